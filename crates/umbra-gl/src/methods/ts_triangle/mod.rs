//! The per-triangle tessellation methods of paper 001, Section 2.1: every triangle of the
//! soup casts its own closed volume, built by the tessellator from a patch of the triangle's
//! points; no preprocessing, no adjacency, no silhouette.
//!
//! * [`two_pass`] — `ts-triangle`: Alg. 1 / Fig. 2, sides + dark cap in one pass, light caps in
//!   a second pass pushed to the far plane in the evaluation shader.
//! * [`one_pass`] — `ts-triangle-1pass`: Fig. 3, the whole volume from one quad patch; the light
//!   cap shares tessellated vertices with the sides, so (as in the paper, Section 2.3) it is
//!   pushed to the far plane per fragment.
//!
//! Exactness needs one addition to the paper: the side two light-facing neighbours cast on
//! their shared edge comes out of two different patches with different triangulations and
//! vertex orders, so the two copies (+1 and -1) can rasterize to depths differing in the last
//! bit and fail to cancel where a receiver lies at the side's depth (measured: tens of samples
//! per frame on a 100k-triangle scene, tens more on the real scenes). The fragment shader
//! therefore gives every side fragment the depth of the side's plane, computed once per patch
//! from the edge's endpoints in canonical order as a clip-space plane in double precision and
//! evaluated in double at the fragment (side_plane.glsl, side_depth.frag.glsl): both copies
//! get the same depth, and with reversed-Z the tiny depths of distant samples keep their
//! precision. A side seen exactly edge-on gets a depth that never counts. This costs the early
//! depth test of the volume pass; the rasterized variant stays available for measurements (not
//! registered, not exact).
//!
//! Both draw the scene's own vertex array and index buffer as `GL_PATCHES` of 3 vertices, in
//! triangle order, and orient each triangle towards the light through its reference edge
//! (Sections 2.2-2.3, Alg. 2-4) in the control shader, so their volumes agree with every other
//! method's.

use glow::HasContext;

use crate::camera::DepthConvention;
use crate::error::GlError;
use crate::methods::VolumeFrame;
use crate::scene::SceneGpu;

pub mod one_pass;
pub mod two_pass;

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const SIDE_PLANE: &str = include_str!("side_plane.glsl");
const PATCH_VERT: &str = include_str!("patch.vert.glsl");
const VOLUME_FRAG: &str = include_str!("volume.frag.glsl");
const SIDE_DEPTH_FRAG: &str = include_str!("side_depth.frag.glsl");

/// `#version` + the shared GLSL (multiplicity, far-plane push, canonical side planes) + a
/// stage body without `#version`.
fn with_shared(body: &str) -> String {
    format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE}\n{body}")
}

/// `z_window = a * z_ndc + b` for the frame's depth convention, as `[a, b]`: (0.5, 0.5) for
/// [`DepthConvention::Standard`] (clip z in -w..w, glDepthRange(0, 1)), (1, 0) for
/// [`DepthConvention::ReversedZ`] (glClipControl ZERO_TO_ONE: the window depth is z_ndc).
pub fn depth_from_ndc(convention: DepthConvention) -> [f32; 2] {
    match convention {
        DepthConvention::Standard => [0.5, 0.5],
        DepthConvention::ReversedZ => [1.0, 0.0],
    }
}

/// Window depth that makes a volume fragment never count: it passes the depth test in z-fail
/// (the near plane) and fails it in z-pass (the far plane). Given to side fragments seen
/// exactly edge-on (side_depth.frag.glsl). The far plane's window depth is `far_clip_z` (1
/// Standard, 0 reversed-Z), the near plane's the other end of the 0..1 range.
pub fn edge_on_depth(far_clip_z: f32, zpass: bool) -> f32 {
    if zpass {
        far_clip_z
    } else {
        1.0 - far_clip_z
    }
}

/// Uniforms of the fragment-depth path (side_plane.glsl, side_depth.frag.glsl).
struct DepthUniforms {
    u_viewport_size: Option<glow::UniformLocation>,
    u_depth_from_ndc: Option<glow::UniformLocation>,
    u_edge_on_depth: Option<glow::UniformLocation>,
}

impl DepthUniforms {
    fn locate(gl: &glow::Context, program: glow::Program) -> Self {
        Self {
            u_viewport_size: crate::program::uniform(gl, program, "u_viewport_size"),
            u_depth_from_ndc: crate::program::uniform(gl, program, "u_depth_from_ndc"),
            u_edge_on_depth: crate::program::uniform(gl, program, "u_edge_on_depth"),
        }
    }

    /// Sets them for `frame` on the current program.
    fn set(&self, gl: &glow::Context, frame: &VolumeFrame<'_>) {
        // SAFETY: uniform setters on the current program with matching types.
        unsafe {
            gl.uniform_2_f32(self.u_viewport_size.as_ref(), frame.width as f32, frame.height as f32);
            let [a, b] = depth_from_ndc(frame.depth_convention());
            gl.uniform_2_f32(self.u_depth_from_ndc.as_ref(), a, b);
            gl.uniform_1_f32(self.u_edge_on_depth.as_ref(), edge_on_depth(frame.far_clip_z(), frame.zpass));
        }
    }
}

/// Fails unless the context can tessellate to `level` (MAX_TESS_GEN_LEVEL).
fn require_tess_level(gl: &glow::Context, method: &'static str, level: i32) -> Result<(), GlError> {
    // SAFETY: plain limit query on the current context.
    let max = unsafe { gl.get_parameter_i32(glow::MAX_TESS_GEN_LEVEL) };
    if max < level {
        return Err(GlError::Unsupported {
            method,
            reason: format!("needs tessellation level {level}, MAX_TESS_GEN_LEVEL is {max}"),
        });
    }
    Ok(())
}

/// Draws every scene triangle as one patch of its 3 points (scene VAO, index buffer, triangle
/// order). The program must be current.
fn draw_triangle_patches(gl: &glow::Context, scene: &SceneGpu) {
    let indices = scene.triangle_count() * 3;
    // SAFETY: the scene's vertex array with its element buffer of exactly 3 * triangle_count
    // u32 indices (checked < positions.len() and to fit i32 at upload).
    unsafe {
        // Reason: GL_PATCH_VERTICES is not part of GlState; every patch is one triangle's
        // three points, so it is set right before each patch draw.
        gl.patch_parameter_i32(glow::PATCH_VERTICES, 3);
        gl.bind_vertex_array(Some(scene.vertex_array()));
        if indices > 0 {
            gl.draw_elements(glow::PATCHES, indices as i32, glow::UNSIGNED_INT, 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_depth_of_the_planes_per_convention() {
        for convention in [DepthConvention::Standard, DepthConvention::ReversedZ] {
            let [a, b] = depth_from_ndc(convention);
            let far = convention.far_clip_z(); // z_ndc of the far plane
                                               // The far plane's window depth is the depth buffer's far value.
            assert_eq!(a * far + b, convention.far_depth());
            // Edge-on sides: never counted - nearer than anything in z-fail, the far plane in z-pass.
            assert_eq!(edge_on_depth(far, true), convention.far_depth());
            assert_eq!(edge_on_depth(far, false), 1.0 - convention.far_depth());
        }
    }
}
