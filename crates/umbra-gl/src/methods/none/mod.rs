//! `none`: no shadows. Draws no volumes, so the stencil stays 0 and every visible surface whose
//! seen side faces a light is lit by it (the renderer's two-sided lighting still leaves the
//! dark side of a surface unlit, and the lit mask says so). The floor for benchmarks (depth +
//! ambient + lighting passes only) and the reference for "what does lighting alone look like".

use crate::error::GlError;
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "none";

/// The `none` method: no volumes, everything lit.
#[derive(Debug, Default)]
pub struct NoShadows {
    prepared: Option<SceneId>,
}

impl NoShadows {
    /// A fresh instance.
    pub fn new() -> Self {
        Self::default()
    }
}

impl ShadowMethod for NoShadows {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &[]
    }

    fn orthographic(&self) -> bool {
        // No volumes: nothing depends on the projection.
        true
    }

    fn prepare(&mut self, _gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(
        &mut self,
        _gl: &glow::Context,
        _scene: &SceneGpu,
        _frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        0
    }

    fn destroy(&mut self, _gl: &glow::Context) {
        self.prepared = None;
    }
}
