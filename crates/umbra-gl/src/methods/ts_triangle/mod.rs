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
//! evaluated in double at the fragment (shared/side_plane.glsl, side_depth.frag.glsl): both copies
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

use crate::error::GlError;
use crate::methods::face_depth::SIDE_PLANE_GLSL;
use crate::scene::SceneGpu;

pub mod one_pass;
pub mod two_pass;

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const PATCH_VERT: &str = include_str!("patch.vert.glsl");
const VOLUME_FRAG: &str = include_str!("volume.frag.glsl");
const SIDE_DEPTH_FRAG: &str = include_str!("side_depth.frag.glsl");

/// `#version` + the shared GLSL (multiplicity, far-plane push, canonical side planes) + a
/// stage body without `#version`.
fn with_shared(body: &str) -> String {
    format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE_GLSL}\n{body}")
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
