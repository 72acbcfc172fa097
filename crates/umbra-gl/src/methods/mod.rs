//! Shadow methods behind one trait, and their registry.
//!
//! A method turns (scene, light, camera) into a per-pixel "shadowed" classification that the
//! lighting pass reads. Counting methods (stencil shadow volumes, z-fail or z-pass) draw
//! volumes into a stencil cleared to 0 and use [`Classification::StencilZero`]; a method with
//! its own stencil scheme (paper 002: INVERT / INCR with masks) describes its test with
//! [`Classification::StencilTest`]; a method that does not use the stencil at all (shadow
//! maps) supplies a GLSL function with [`Classification::Shader`].
//!
//! Frame protocol, per light, as run by [`crate::Renderer`]:
//! 1. the stencil is cleared to 0 (write mask 0xFF);
//! 2. [`ShadowMethod::draw_volumes`] — the method applies its own [`crate::GlState`] for every
//!    draw (for counting methods [`VolumeFrame::shadow_volume_state`]), may bind its own
//!    programs, vertex arrays, buffers, and even other framebuffers/viewports (shadow maps);
//!    the renderer re-binds its target, program and vertex array afterwards. With the wide
//!    counter ([`crate::counter::Counter::Float32`], `StencilZero` methods only) the bound
//!    target is the counter's framebuffer, the state blends the fragment shader's
//!    `o_count` (+1 front face, -1 back face, location 0) instead of counting in the stencil,
//!    and the renderer resolves the count into the stencil afterwards: every counting
//!    method's volume fragment shader writes `o_count`;
//! 3. the lighting pass, restricted by [`ShadowMethod::classification`] and by the facing of
//!    the seen side towards the light (see [`Classification`]).
//!
//! Stage boundaries are reported through [`VolumeFrame::mark`] so a benchmark can time them
//! ([`crate::TimestampHook`]).

pub(crate) mod method;

pub mod all_edges_invert;
pub mod cpu_silhouette;
pub mod cs_silhouette;
pub mod face_depth;
mod gpu_cull;
pub mod gs_silhouette;
pub mod gs_triangle;
pub mod hier;
pub mod hier_silhouette;
pub mod hier_triangle;
pub mod none;
pub mod ray_bvh;
pub(crate) mod receivers;
pub mod shadow_map;
pub mod silhouette_caps;
pub mod ts_silhouette;
pub mod ts_triangle;
pub mod vs_silhouette;
pub mod vs_triangle;
pub mod work_counts;

pub use method::{Classification, DrawnVolume, ShadowMethod, StageHook, StageMark, VolumeFrame};

/// A method name the registry does not know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown shadow method {name:?}; known methods: {}", method_names().join(", "))]
pub struct UnknownMethod {
    /// The name asked for.
    pub name: String,
}

/// Every registered method, in a stable order.
pub fn method_names() -> &'static [&'static str] {
    &[
        none::NAME,
        cpu_silhouette::NAME,
        vs_silhouette::NAME,
        cs_silhouette::NAME,
        ts_silhouette::NAME,
        ts_silhouette::NAME_3EDGE,
        gs_silhouette::NAME,
        gs_silhouette::NAME_3EDGE,
        shadow_map::NAME_1024,
        shadow_map::NAME_2048,
        ts_triangle::two_pass::NAME,
        ts_triangle::one_pass::NAME,
        gs_triangle::NAME,
        vs_triangle::NAME,
        all_edges_invert::NAME,
        hier_triangle::NAME,
        hier_silhouette::NAME,
        ray_bvh::NAME,
    ]
}

/// Builds a method by registry name (no GL calls; see [`ShadowMethod::prepare`]).
pub fn create_method(name: &str) -> Result<Box<dyn ShadowMethod>, UnknownMethod> {
    match name {
        none::NAME => Ok(Box::new(none::NoShadows::new())),
        cpu_silhouette::NAME => Ok(Box::new(cpu_silhouette::CpuSilhouette::new())),
        vs_silhouette::NAME => Ok(Box::new(vs_silhouette::VsSilhouette::new())),
        cs_silhouette::NAME => Ok(Box::new(cs_silhouette::CsSilhouette::new())),
        ts_silhouette::NAME => Ok(Box::new(ts_silhouette::TsSilhouette::new())),
        ts_silhouette::NAME_3EDGE => Ok(Box::new(ts_silhouette::TsSilhouette::new_three_edge())),
        gs_silhouette::NAME => Ok(Box::new(gs_silhouette::GsSilhouette::new())),
        gs_silhouette::NAME_3EDGE => Ok(Box::new(gs_silhouette::GsSilhouette::new_three_edge())),
        ts_triangle::two_pass::NAME => Ok(Box::new(ts_triangle::two_pass::TsTriangle::new())),
        ts_triangle::one_pass::NAME => Ok(Box::new(ts_triangle::one_pass::TsTriangle1Pass::new())),
        gs_triangle::NAME => Ok(Box::new(gs_triangle::GsTriangle::new())),
        vs_triangle::NAME => Ok(Box::new(vs_triangle::VsTriangle::new())),
        all_edges_invert::NAME => Ok(Box::new(all_edges_invert::AllEdgesInvert::new())),
        hier_triangle::NAME => Ok(Box::new(hier_triangle::HierTriangle::new())),
        hier_silhouette::NAME => Ok(Box::new(hier_silhouette::HierSilhouette::new())),
        ray_bvh::NAME => Ok(Box::new(ray_bvh::RayBvhMethod::new())),
        n if n.starts_with(shadow_map::PREFIX) => shadow_map::ShadowMapCube::from_name(n)
            .map(|m| Box::new(m) as Box<dyn ShadowMethod>)
            .ok_or_else(|| UnknownMethod { name: n.to_string() }),
        _ => Err(UnknownMethod { name: name.to_string() }),
    }
}
