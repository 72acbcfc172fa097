//! Shadow methods on wgpu, behind one trait, and their registry: the same `--method` names as
//! umbra-gl (`cs-silhouette`, `cpu-silhouette`, `vs-silhouette`, `shadow-map-cube:RES`, `none`).
//! Geometry- and tessellation-shader methods have no wgpu counterpart (wgpu has neither stage).
//!
//! Per frame protocol ([`crate::ShadowVolumes`]): once per scene `prepare_scene`;
//! per light, before the caller's passes, `prepare_light` (uniform slot, compute
//! passes, uploads, own render passes into the encoder); then, in the caller's pass with the
//! stencil cleared to the light's [`LightPlan::stencil_clear`], `draw`.

use crate::error::WgpuError;
use crate::scene::{SceneGpu, SceneId};
use crate::volumes::{Common, LightPlan, LightSlot};

pub mod cpu_silhouette;
pub mod cs_silhouette;
pub mod none;
pub mod shadow_map;
mod transform;
pub mod vs_silhouette;

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
pub(crate) struct LightFrame {
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
        frame: &LightFrame,
    ) -> Result<(), WgpuError>;
    /// Draws light `slot`'s volumes (or resolve) into the caller's pass.
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan);
    /// Bytes of GPU memory the method holds.
    fn gpu_bytes(&self) -> u64;
    /// Records a copy of light `slot`'s side and cap vertex counts, as the GPU decided them,
    /// into `readback` (32 bytes, two draw-indirect commands); false for methods whose counts
    /// the CPU knows.
    fn copy_counts(&self, _encoder: &mut wgpu::CommandEncoder, _slot: usize, _readback: &wgpu::Buffer) -> bool {
        false
    }
}

/// Every method of the wgpu backend, in a stable order (umbra-gl's names).
pub fn method_names() -> &'static [&'static str] {
    &[
        none::NAME,
        cpu_silhouette::NAME,
        vs_silhouette::NAME,
        cs_silhouette::NAME,
        shadow_map::NAME_1024,
        shadow_map::NAME_2048,
    ]
}

/// Builds a method by registry name for the pass formats of `common` (any
/// `shadow-map-cube:RES[+pcf]`, listed or not, with the default bias; see
/// [`create_shadow_map`] for other options).
pub(crate) fn create_method(device: &wgpu::Device, common: &Common, name: &str) -> Result<Box<dyn Method>, WgpuError> {
    match name {
        none::NAME => Ok(Box::new(none::NoShadows::default())),
        cpu_silhouette::NAME => Ok(Box::new(cpu_silhouette::CpuSilhouette::new(device, common))),
        vs_silhouette::NAME => Ok(Box::new(vs_silhouette::VsSilhouette::new(device, common))),
        cs_silhouette::NAME => Ok(Box::new(cs_silhouette::CsSilhouette::new(device, common))),
        n => match shadow_map::ShadowMapConfig::from_name(n) {
            Some(config) => Ok(Box::new(shadow_map::ShadowMapCube::new(device, common, config)?)),
            None => Err(WgpuError::UnknownMethod { name: name.to_string(), known: method_names().join(", ") }),
        },
    }
}

/// A shadow map with explicit options (bias) for the pass formats of `common`.
pub(crate) fn create_shadow_map(
    device: &wgpu::Device,
    common: &Common,
    config: shadow_map::ShadowMapConfig,
) -> Result<Box<dyn Method>, WgpuError> {
    Ok(Box::new(shadow_map::ShadowMapCube::new(device, common, config)?))
}
