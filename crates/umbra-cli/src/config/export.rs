//! [`ExportConfig`]: the flags of `umbra export`, checked.

use std::time::Instant;

use super::view::ViewConfig;
use crate::args::{ExportArgs, ViewArgs};
use crate::error::{bad, CliError};

/// `umbra export`: write a scene's buffers and manifest, or check an export.
pub enum ExportConfig {
    /// `--check DIR`: read DIR's manifest back and check it and its buffer files.
    Check { dir: String },
    /// `SCENE --out DIR`.
    Write(Box<ExportJob>),
}

/// What `umbra export SCENE --out DIR` writes.
pub struct ExportJob {
    /// The scene spec as given.
    pub scene: String,
    pub out: String,
    pub ground: bool,
    /// The scene, its suggested light and camera (derived as for `render`, 1280x720, 60°).
    pub view: ViewConfig,
    /// When the export began (the scene's loading included).
    pub started: Instant,
}

impl ExportConfig {
    pub fn from_args(a: &ExportArgs) -> Result<Self, CliError> {
        if let Some(dir) = &a.check {
            return Ok(ExportConfig::Check { dir: dir.clone() });
        }
        let (Some(scene), Some(out)) = (&a.scene, &a.out) else {
            return Err(bad("--out", "usage: umbra export SCENE --out DIR [--ground], or umbra export --check DIR"));
        };
        let started = Instant::now();
        let view = ViewConfig::from_args(&export_view_args(scene, a))?;
        Ok(ExportConfig::Write(Box::new(ExportJob {
            scene: scene.clone(),
            out: out.clone(),
            ground: a.ground,
            view,
            started,
        })))
    }
}

/// The `render` flags an export's view is derived with.
fn export_view_args(scene: &str, a: &ExportArgs) -> ViewArgs {
    ViewArgs {
        scene: scene.to_string(),
        light: a.light.iter().cloned().collect(),
        eye: a.eye.clone(),
        target: a.target.clone(),
        up: "0,1,0".into(),
        fov: 60.0,
        ortho: a.ortho.clone(),
        ortho_far: None,
        size: "1280x720".into(),
        ground: a.ground,
        zpass: false,
        zmode: "auto".into(),
        volume_cull: "on".into(),
        receivers: "both".into(),
        max_input_bytes: a.max_input_bytes,
    }
}
