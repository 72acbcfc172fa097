//! [`InfoConfig`]: the flags of `umbra info`, checked.

use umbra_geom::Light;

use super::parse::{parse_backend, parse_light};
use crate::args::InfoArgs;
use crate::backend::Backend;
use crate::error::{bad, CliError};

/// `umbra info`: a scene's statistics, the backend's device, or both.
pub struct InfoConfig {
    /// The scene spec; `None` only with a backend (the device alone).
    pub scene: Option<String>,
    /// `--backend`: print the device it draws on.
    pub backend: Option<Backend>,
    /// `--light`: also count its silhouette edges.
    pub light: Option<Light>,
    pub ground: bool,
    pub json: bool,
    pub max_input_bytes: Option<u64>,
}

impl InfoConfig {
    pub fn from_args(a: &InfoArgs) -> Result<Self, CliError> {
        let backend = a.backend.as_deref().map(parse_backend).transpose()?;
        let scene = match (&a.scene, &a.scene_flag) {
            (Some(p), Some(f)) if p != f => {
                return Err(bad("--scene", format!("two scenes: {p:?} (positional) and {f:?} (--scene)")));
            }
            (p, f) => p.clone().or_else(|| f.clone()),
        };
        if scene.is_none() && backend.is_none() {
            return Err(CliError::Other("info needs a SCENE, or --backend gl|wgpu to print the device".into()));
        }
        let light = a.light.as_deref().map(parse_light).transpose()?;
        Ok(Self { scene, backend, light, ground: a.ground, json: a.json, max_input_bytes: a.max_input_bytes })
    }
}
