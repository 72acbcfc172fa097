//! Shadow methods on wgpu and their registry: the same `--method` names as umbra-gl
//! (`cs-silhouette`, `cpu-silhouette`, `vs-silhouette`, `shadow-map-cube:RES`, `ray-bvh`, `none`), each
//! behind the one trait of `method.rs`. Geometry- and tessellation-shader methods have no wgpu
//! counterpart (wgpu has neither stage).

use crate::common::Common;
use crate::error::WgpuError;

pub mod cpu_silhouette;
pub mod cs_silhouette;
mod gpu_cull;
mod method;
pub mod none;
pub mod ray_bvh;
pub mod shadow_map;
mod transform;
pub mod vs_silhouette;

pub use method::{DrawnVolume, MethodKind};
pub(crate) use method::{LightFrame, Method};

/// Every method of the wgpu backend, in a stable order (umbra-gl's names).
pub fn method_names() -> &'static [&'static str] {
    &[
        none::NAME,
        cpu_silhouette::NAME,
        vs_silhouette::NAME,
        cs_silhouette::NAME,
        shadow_map::NAME_1024,
        shadow_map::NAME_2048,
        ray_bvh::NAME,
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
        ray_bvh::NAME => Ok(Box::new(ray_bvh::RayBvhMethod::new(device, common)?)),
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
