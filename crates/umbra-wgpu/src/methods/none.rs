//! `none`: no shadows (every sample lit by every light whose side it sees); the baseline the
//! verifier compares against and the frame the depth pass's captures come from.

use crate::common::{Common, LightPlan};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "none";

/// See the module documentation.
#[derive(Default)]
pub struct NoShadows {
    prepared: Option<SceneId>,
}

impl Method for NoShadows {
    fn name(&self) -> &'static str {
        NAME
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Counting { silhouette_sides: true }
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn prepare_scene(&mut self, _device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepare_light(
        &mut self,
        _device: &wgpu::Device,
        _queue: &wgpu::Queue,
        _encoder: &mut wgpu::CommandEncoder,
        _scene: &SceneGpu,
        _common: &Common,
        _frame: &LightFrame,
    ) -> Result<(), WgpuError> {
        Ok(())
    }

    fn draw(&self, _pass: &mut wgpu::RenderPass<'_>, _common: &Common, _slot: usize, _plan: LightPlan) {}

    fn gpu_bytes(&self) -> u64 {
        0
    }
}
