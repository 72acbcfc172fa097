//! The shadow-method trait of the wgpu backend ([`Method`]), what a method sees of one light
//! ([`LightFrame`]) and what its draw leaves in the stencil ([`MethodKind`]).
//!
//! Per frame protocol ([`crate::ShadowVolumes`]): once per scene `prepare_scene`;
//! per light, before the caller's passes, `prepare_light` (uniform slot, compute
//! passes, uploads, own render passes into the encoder); then, in the caller's pass with the
//! stencil cleared to the light's [`LightPlan::stencil_clear`], `draw`.

use crate::common::{Common, LightPlan, LightSlot};
use crate::error::WgpuError;
use crate::scene::{SceneGpu, SceneId};
use crate::view::View;

pub use umbra_geom::silhouette::DrawnVolume;

/// What a method's draw leaves in the stencil.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodKind {
    /// Shadow volumes counted into a stencil cleared to 0 (or W0 for z-pass from inside):
    /// lit where it ends at 0. `silhouette_sides`: sides only on edges of nonzero multiplicity
    /// (the auto z-pass test may then let edges of multiplicity 0 cross the near pyramid).
    Counting {
        /// Side faces only on silhouette edges.
        silhouette_sides: bool,
    },
    /// The draw resolves the method's own decision into a stencil cleared to 1: 0 where lit
    /// (shadow maps).
    Resolve,
}

/// One light of one frame, as a method sees it.
pub(crate) struct LightFrame<'a> {
    /// The frame's camera.
    pub view: &'a View,
    /// The caller's submitted depth, where the volumes are to be culled against it
    /// ([`crate::VolumeFrame::receivers`]).
    pub receivers: Option<&'a wgpu::Texture>,
    /// Index of the light (its uniform slot and output buffers).
    pub slot: usize,
    /// How it counts.
    pub plan: LightPlan,
    /// Its uniform slot, to complete (records, max_mult) and write.
    pub data: LightSlot,
}

/// A shadow method on wgpu.
pub(crate) trait Method {
    /// Registry name.
    fn name(&self) -> &'static str;
    /// What its draw leaves in the stencil.
    fn kind(&self) -> MethodKind;
    /// The scene the last `prepare_scene` was for.
    fn prepared_scene(&self) -> Option<SceneId>;
    /// Once per scene: per-mesh buffers and bind groups.
    fn prepare_scene(&mut self, device: &wgpu::Device, scene: &SceneGpu, common: &Common) -> Result<(), WgpuError>;
    /// Per light and frame: writes the light's uniform slot and records the method's work
    /// into `encoder` (before the caller's passes).
    fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame<'_>,
    ) -> Result<(), WgpuError>;
    /// Draws light `slot`'s volumes (or resolve) into the caller's pass.
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan);
    /// Bytes of GPU memory the method holds.
    fn gpu_bytes(&self) -> u64;
    /// Records a copy of light `slot`'s side and cap vertex counts, as the GPU decided them,
    /// into `readback` (two draw-indirect commands, then one word: the triangles its cull
    /// kept; 36 bytes); false for methods whose counts the CPU knows.
    fn copy_counts(&self, _encoder: &mut wgpu::CommandEncoder, _slot: usize, _readback: &wgpu::Buffer) -> bool {
        false
    }
    /// What light `slot`'s volume drew, from the words [`Method::copy_counts`] copied; `None`
    /// by default.
    fn drawn_from_counts(&self, _slot: usize, _words: &[u32]) -> Option<DrawnVolume> {
        None
    }
    /// Whether the method culls and clamps its volumes against the receivers when the frame
    /// gives it the caller's depth ([`crate::VolumeFrame::receivers`]); false by default.
    fn culls_volumes(&self) -> bool {
        false
    }
    /// Count the fragments of the method's own passes from the next frame on
    /// ([`Method::own_fragments`]); nothing to count by default.
    fn set_count_fragments(&mut self, _on: bool) {}
    /// The fragments light `slot`'s own passes shaded in the last counted frame (the receiver
    /// map's scatter); `None` when not counted or nothing was drawn.
    fn own_fragments(&self, _slot: usize) -> Option<u64> {
        None
    }
    /// What light `slot`'s volume of the last frame drew (culled or not); `None` for methods
    /// that do not know it on the CPU.
    fn drawn_volume(&self, _slot: usize) -> Option<DrawnVolume> {
        None
    }
    /// Figures of the per-scene preprocessing, `(key, value)`, for `bench --json` (ray-bvh's
    /// BVH); none by default.
    fn scene_figures(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
