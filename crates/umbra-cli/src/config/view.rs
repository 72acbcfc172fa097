//! [`ViewConfig`]: the scene, camera, lights, size and z-mode flags (`ViewArgs`) checked, as
//! `render`, `verify`, `view` and `export` draw them.

use umbra_geom::scene;
use umbra_geom::{Aabb, Light, Mesh, Receivers};

use super::parse::{
    check_fov, parse_light, parse_ortho, parse_ortho_far, parse_receivers, parse_size, parse_vec3, parse_volume_cull,
    parse_zmode,
};
use crate::args::ViewArgs;
use crate::backend::Backend;
use crate::error::{bad, CliError};
use crate::scenes::{default_camera, default_light, load_scene, CameraConfig, Framing};

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
    /// Volumes culled and clamped against the receivers (`--volume-cull on`, the default).
    pub volume_cull: bool,
    /// Which faces a pixel can show (`--receivers`, default both).
    pub receivers: Receivers,
    /// `--ortho-far`: the orthographic far plane's view distance, in place of the fitted one.
    pub ortho_far: Option<f64>,
}

impl ViewConfig {
    /// Checks the flags, loads the scene and derives the camera and light defaults from its
    /// bounds.
    pub fn from_args(a: &ViewArgs) -> Result<Self, CliError> {
        let (width, height) = parse_size(&a.size)?;
        check_fov(a.fov)?;
        let ortho = a.ortho.as_deref().map(parse_ortho).transpose()?;
        let ortho_far = a.ortho_far.as_deref().map(parse_ortho_far).transpose()?;
        if ortho_far.is_some() && ortho.is_none() {
            return Err(bad("--ortho-far", "applies to an orthographic view (--ortho HEIGHT)"));
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
        camera.ortho = ortho;
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
        let volume_cull = parse_volume_cull(&a.volume_cull)?;
        let receivers = parse_receivers(&a.receivers)?;
        Ok(ViewConfig {
            scene_spec: a.scene.clone(),
            mesh,
            camera,
            lights,
            width,
            height,
            zpass,
            auto_zpass,
            volume_cull,
            receivers,
            ortho_far,
        })
    }
}

/// `--ortho` is drawn by the GL backend only (the wgpu backend's volumes run to infinity).
pub fn check_ortho(backend: Backend, view: &ViewConfig) -> Result<(), CliError> {
    if backend == Backend::Wgpu && view.camera.ortho.is_some() {
        return Err(bad("--ortho", "applies to --backend gl (the wgpu backend's volumes run to infinity)"));
    }
    Ok(())
}

/// `--receivers front` culls back faces in the GL renderer's depth pass; the wgpu backend draws
/// both faces only.
pub fn check_receivers(backend: Backend, view: &ViewConfig) -> Result<(), CliError> {
    if backend == Backend::Wgpu && view.receivers != Receivers::Both {
        return Err(bad("--receivers", "front applies to --backend gl (the wgpu backend draws both faces)"));
    }
    Ok(())
}
