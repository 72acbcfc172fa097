//! Scenes by spec (procedural or a mesh file), and how a scene is framed by default: the
//! camera and the light `render`, `verify`, `view`, `export` and `bench` derive from its bounds.

use std::path::Path;

use umbra_geom::load::{load_path_with, LoadOptions};
use umbra_geom::scene::{self, SceneSpec};
use umbra_geom::{Aabb, Light, Mesh};

use crate::error::CliError;

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
    /// `Some(height)`: orthographic, `height` world units tall (`--ortho`).
    pub ortho: Option<f64>,
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
    CameraConfig { eye, target, up: [0.0, 1.0, 0.0], fov_y_degrees: 60.0, ortho: None }
}
