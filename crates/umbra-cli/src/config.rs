//! Raw flags → checked configuration, in one place (the ripgrep pattern): every number is
//! parsed and range-checked here, defaults derived from the scene's bounds here, and the
//! commands receive values they can trust.

use std::path::Path;

use umbra_geom::load::{load_path_with, LoadOptions};
use umbra_geom::scene::{self, SceneSpec};
use umbra_geom::{Aabb, Light, Mesh};

use crate::args::ViewArgs;

/// Every error the CLI reports. Displayed as `umbra: error: …` with a non-zero exit status.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error("{flag}: {message}")]
    BadFlag { flag: &'static str, message: String },
    #[error("{0}")]
    Scene(#[from] scene::SceneError),
    #[error("{0}")]
    Load(#[from] umbra_geom::load::LoadError),
    #[error("{0}")]
    Gl(String),
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{0}")]
    Other(String),
}

fn bad(flag: &'static str, message: impl Into<String>) -> CliError {
    CliError::BadFlag { flag, message: message.into() }
}

/// Parses `N` comma-separated finite numbers.
fn parse_numbers(flag: &'static str, text: &str, counts: &[usize]) -> Result<Vec<f64>, CliError> {
    let values: Vec<f64> = text
        .split(',')
        .map(|s| {
            let v: f64 = s.trim().parse().map_err(|_| bad(flag, format!("{s:?} in {text:?} is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(bad(flag, format!("{s:?} in {text:?} is not finite")))
            }
        })
        .collect::<Result<_, _>>()?;
    if !counts.contains(&values.len()) {
        let want = counts.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(" or ");
        return Err(bad(flag, format!("expected {want} comma-separated numbers, got {text:?}")));
    }
    Ok(values)
}

pub fn parse_vec3(flag: &'static str, text: &str) -> Result<[f64; 3], CliError> {
    let v = parse_numbers(flag, text, &[3])?;
    Ok([v[0], v[1], v[2]])
}

/// `X,Y,Z` (point light, w = 1) or `X,Y,Z,W`. A point light with `W != 0` is normalised to
/// `w = 1`; `W = 0` is a directional light coming from `(X, Y, Z)`, which must not be zero.
pub fn parse_light(text: &str) -> Result<Light, CliError> {
    let v = parse_numbers("--light", text, &[3, 4])?;
    let w = if v.len() == 4 { v[3] } else { 1.0 };
    if w == 0.0 {
        if v[..3].iter().all(|&c| c == 0.0) {
            return Err(bad("--light", "a directional light (w = 0) needs a non-zero direction"));
        }
        return Ok([v[0] as f32, v[1] as f32, v[2] as f32, 0.0]);
    }
    Ok([(v[0] / w) as f32, (v[1] / w) as f32, (v[2] / w) as f32, 1.0])
}

pub fn parse_size(text: &str) -> Result<(u32, u32), CliError> {
    let err = || bad("--size", format!("expected WxH with 1 <= W, H <= 16384, got {text:?}"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(err)?;
    let w: u32 = w.trim().parse().map_err(|_| err())?;
    let h: u32 = h.trim().parse().map_err(|_| err())?;
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(err());
    }
    Ok((w, h))
}

/// Loads a scene spec (procedural or file), adding the ground plane when asked.
pub fn load_scene(spec: &str, ground: bool, max_input_bytes: Option<u64>) -> Result<Mesh, CliError> {
    let parsed = scene::parse(spec)?;
    let mut mesh = match &parsed {
        SceneSpec::File(path) => {
            let mut options = LoadOptions::default();
            if let Some(limit) = max_input_bytes {
                options.max_input_bytes = limit;
            }
            load_path_with(Path::new(path), &options)?
        }
        other => scene::build(other)?,
    };
    if ground {
        scene::add_ground(&mut mesh);
    }
    Ok(mesh)
}

/// A camera: where it is, what it looks at, which way is up, vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraConfig {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub fov_y_degrees: f64,
}

/// Everything `render` and `verify` need to draw a view, checked.
#[derive(Clone, Debug)]
pub struct ViewConfig {
    pub scene_spec: String,
    pub mesh: Mesh,
    pub camera: CameraConfig,
    pub lights: Vec<Light>,
    pub width: u32,
    pub height: u32,
    /// z-pass for every light (`--zpass`, `--zmode zpass`).
    pub zpass: bool,
    /// z-pass where provably exact (`--zmode auto`, the default).
    pub auto_zpass: bool,
}

/// `--zmode` (and `--zpass`, its older spelling of `zpass`) as (force z-pass, auto z-pass).
pub fn parse_zmode(zmode: &str, zpass: bool) -> Result<(bool, bool), CliError> {
    match (zmode.trim(), zpass) {
        ("auto", false) => Ok((false, true)),
        ("zfail", false) => Ok((false, false)),
        ("zpass", _) | ("auto", true) => Ok((true, false)),
        ("zfail", true) => Err(bad("--zmode", "zfail contradicts --zpass")),
        (other, _) => Err(bad("--zmode", format!("expected zfail, zpass or auto, got {other:?}"))),
    }
}

/// How a scene is framed by default: interiors (the papers' scenes, any file) are seen and
/// lit from inside; procedural scenes (objects over a ground plane) from above and outside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Framing {
    Interior,
    Exterior,
}

impl Framing {
    pub fn of(spec: &SceneSpec) -> Framing {
        match spec {
            SceneSpec::File(_) => Framing::Interior,
            _ => Framing::Exterior,
        }
    }
}

/// The default light. Interiors: inside the bounds at about 70 % of their height, slightly
/// off-centre (the scenes' README). Exteriors: above the objects, off-centre, so shadows
/// fall on the ground beside them.
pub fn default_light(b: &Aabb, framing: Framing) -> Light {
    let c = b.center();
    let e = b.extent();
    let horizontal = e[0].max(e[2]);
    match framing {
        Framing::Interior => [c[0] + 0.11 * e[0], b.min[1] + 0.7 * e[1], c[2] + 0.07 * e[2], 1.0],
        Framing::Exterior => {
            [c[0] + 0.15 * e[0], b.min[1] + (2.0 * e[1]).max(0.35 * horizontal), c[2] + 0.1 * e[2], 1.0]
        }
    }
}

/// The default camera. Interiors: at 45 % of the height, 30 % of the way in from one end of
/// the longer horizontal axis, looking along it slightly downwards (for Crytek Sponza: down
/// the atrium from the first gallery; for Conference: over the table). Exteriors: from above the front-left, at the centre.
pub fn default_camera(b: &Aabb, framing: Framing) -> CameraConfig {
    let c = b.center().map(f64::from);
    let e = b.extent().map(f64::from);
    let min_y = f64::from(b.min[1]);
    let horizontal = e[0].max(e[2]);
    let (eye, target) = match framing {
        Framing::Interior if e[0] >= e[2] => {
            ([c[0] - 0.2 * e[0], min_y + 0.45 * e[1], c[2]], [c[0] + 0.2 * e[0], min_y + 0.3 * e[1], c[2]])
        }
        Framing::Interior => {
            ([c[0], min_y + 0.45 * e[1], c[2] - 0.2 * e[2]], [c[0], min_y + 0.3 * e[1], c[2] + 0.2 * e[2]])
        }
        Framing::Exterior => ([c[0] - 0.3 * e[0], c[1] + 0.25 * horizontal + 0.5 * e[1], c[2] + 0.4 * e[2]], c),
    };
    CameraConfig { eye, target, up: [0.0, 1.0, 0.0], fov_y_degrees: 60.0 }
}

impl ViewConfig {
    pub fn from_args(a: &ViewArgs) -> Result<Self, CliError> {
        let (width, height) = parse_size(&a.size)?;
        if !(a.fov > 0.0 && a.fov < 180.0) {
            return Err(bad("--fov", format!("must be in (0, 180) degrees, got {}", a.fov)));
        }
        let up = parse_vec3("--up", &a.up)?;
        if up.iter().all(|&c| c == 0.0) {
            return Err(bad("--up", "must not be zero"));
        }
        // `default` names the light derived from the scene's bounds, resolved below.
        let explicit_lights = a
            .light
            .iter()
            .map(|l| if l.trim() == "default" { Ok(None) } else { parse_light(l).map(Some) })
            .collect::<Result<Vec<_>, _>>()?;
        let eye = a.eye.as_deref().map(|s| parse_vec3("--eye", s)).transpose()?;
        let target = a.target.as_deref().map(|s| parse_vec3("--target", s)).transpose()?;
        let framing = Framing::of(&scene::parse(&a.scene)?);
        let mut mesh = load_scene(&a.scene, false, a.max_input_bytes)?;
        // Camera and light follow the scene itself, not the (ten times wider) ground plane.
        let bounds = mesh.bounds().unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
        if a.ground {
            scene::add_ground(&mut mesh);
        }
        let mut camera = default_camera(&bounds, framing);
        camera.up = up;
        camera.fov_y_degrees = a.fov;
        if let Some(e) = eye {
            camera.eye = e;
        }
        if let Some(t) = target {
            camera.target = t;
        }
        if camera.eye == camera.target {
            return Err(bad("--eye", "the eye and the target must differ"));
        }
        let derived = default_light(&bounds, framing);
        let lights = if explicit_lights.is_empty() {
            vec![derived]
        } else {
            explicit_lights.into_iter().map(|l| l.unwrap_or(derived)).collect()
        };
        let (zpass, auto_zpass) = parse_zmode(&a.zmode, a.zpass)?;
        Ok(ViewConfig { scene_spec: a.scene.clone(), mesh, camera, lights, width, height, zpass, auto_zpass })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_three_numbers_is_point() {
        assert_eq!(parse_light("1,2,3").unwrap(), [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(parse_light("2,4,6,2").unwrap(), [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(parse_light("0,-1,0,0").unwrap(), [0.0, -1.0, 0.0, 0.0]);
        assert!(parse_light("0,0,0,0").is_err());
        assert!(parse_light("1,2").is_err());
        assert!(parse_light("1,nan,2").is_err());
    }

    #[test]
    fn size_is_checked() {
        assert_eq!(parse_size("1280x720").unwrap(), (1280, 720));
        assert!(parse_size("0x720").is_err());
        assert!(parse_size("1280").is_err());
        assert!(parse_size("99999x1").is_err());
    }
}
