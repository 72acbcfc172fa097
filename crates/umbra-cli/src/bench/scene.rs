//! The scene a measurement draws, and the camera path it moves along.

use std::path::Path;

use umbra_geom::scene;
use umbra_geom::{Aabb, Light};

use super::flythrough::{self, Keyframe};
use crate::error::CliError;
use crate::scenes::{default_light, load_scene, Framing};

/// A loaded scene ready to bench: mesh (with ground if asked), the bounds of the scene itself,
/// framing, lights.
pub struct BenchScene {
    pub spec: String,
    pub mesh: umbra_geom::Mesh,
    pub bounds: Aabb,
    pub framing: Framing,
    pub lights: Vec<Light>,
}

impl BenchScene {
    /// Loads `spec`; the lights are `lights`, or when there are none the default light of the
    /// scene's bounds.
    pub fn load(spec: &str, ground: bool, max_input_bytes: Option<u64>, lights: &[Light]) -> Result<Self, CliError> {
        let framing = Framing::of(&scene::parse(spec)?);
        let mut mesh = load_scene(spec, false, max_input_bytes)?;
        let bounds = mesh.bounds().unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
        if ground {
            scene::add_ground(&mut mesh);
        }
        let lights = if lights.is_empty() { vec![default_light(&bounds, framing)] } else { lights.to_vec() };
        Ok(Self { spec: spec.to_string(), mesh, bounds, framing, lights })
    }
}

/// `orbit`, or a fly-through file, as `frames` cameras.
pub fn camera_path(which: &str, scene: &BenchScene, frames: usize) -> Result<Vec<Keyframe>, CliError> {
    let n = frames.max(1);
    if which == "orbit" {
        return Ok(flythrough::orbit(&scene.bounds, scene.framing, n));
    }
    let keys = flythrough::load(Path::new(which))?;
    Ok(flythrough::interpolate(&keys, n))
}
