//! `vs-triangle`: the naive per-triangle shadow volume of every triangle, extruded in the
//! vertex shader; no silhouette. The baseline every silhouette method is measured against.
//!
//! Paper 001, Section 2.1 (per-triangle volumes: no preprocessing, any triangle soup),
//! oriented through the reference edge (Section 2.2-2.3, Alg. 2-4, `umbra_triangle_orientation`)
//! so sides and caps agree with every other method; sides extruded with Eq. 2; light caps
//! pushed to the far plane (paper 003, Eq. 6). Vertex-shader extrusion in the manner of
//! McGuire 2004 and paper 002, but with no extra vertex data at all: one non-indexed
//! `glDrawArrays` of 24 vertices (8 triangles: 3 side quads, light cap, dark cap) per scene
//! triangle, whose vertex shader fetches its triangle from the scene's own position and index
//! buffers (bound as shader storage) by `gl_VertexID / 24`. See volume.vert.glsl for the vertex
//! table.
//!
//! Two draws per light, because the sides two light-facing neighbours cast on their shared
//! edge (+1 and -1) must cancel at every sample, including samples at the side's own depth: all
//! sides are emitted in one canonical vertex order (that of a +1 side), so both copies are
//! clipped, triangulated and depth-interpolated identically, and the -1 sides are drawn in a
//! second draw ("negative sides", 18 vertices per triangle) with `glFrontFace(GL_CW)`, which
//! counts the same primitives as the opposite face.
//!
//! Face depths: every primitive carries its face's window depth function, flat,
//! computed in the vertex shader at the provoking vertex ([`crate::methods::face_depth`]),
//! which the fragment shader writes as every fragment's `gl_FragDepth`
//! (`shared/face_depth.frag.glsl`: llvmpipe's interpolated depth is NaN or wrong on some faces).
//!
//! Preprocessing (once): the program and an empty vertex array; the method owns no buffers
//! (`gpu_bytes() == 0`). Per light: uniforms and one draw, counted with
//! [`VolumeFrame::shadow_volume_state`] (z-fail; z-pass draws only the 18 side vertices per
//! triangle).
//!
//! Stages reported: "volumes" (+1 sides and caps), "negative sides".

use glow::HasContext;

use crate::error::GlError;
use crate::methods::face_depth::{face_depth_fragment, DepthUniforms, SIDE_PLANE_GLSL};
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::GlState;

/// Registry name.
pub const NAME: &str = "vs-triangle";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const VERT: &str = include_str!("volume.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Shader-storage binding points of the scene's positions and triangles while the volumes are
/// drawn (unbound again afterwards). Away from [`crate::scene::NORMALS_BINDING`] (0), which
/// the lighting pass uses.
pub const POSITIONS_BINDING: u32 = 2;
/// Shader-storage binding point of the scene's triangles while the volumes are drawn.
pub const TRIANGLES_BINDING: u32 = 3;

/// Vertices per scene triangle: 3 side quads (18), light cap (3), dark cap (3).
pub const VERTICES_PER_TRIANGLE: usize = 24;

/// Vertices per scene triangle of the second draw (the -1 sides).
pub const NEGATIVE_SIDE_VERTICES: usize = 18;

/// Vertices drawn per scene triangle for a light in the first draw: sides only in z-pass; no dark cap for a
/// directional light (every vertex extrudes to the same point, the cap has zero area).
pub fn vertices_per_triangle(zpass: bool, directional: bool) -> usize {
    match (zpass, directional) {
        (true, _) => 18,
        (false, true) => 21,
        (false, false) => VERTICES_PER_TRIANGLE,
    }
}

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    u_vertices_per_triangle: Option<glow::UniformLocation>,
    u_pass: Option<glow::UniformLocation>,
    depth: DepthUniforms,
    /// Core profile needs a bound vertex array even with no attributes.
    vao: glow::VertexArray,
}

/// See the module documentation.
#[derive(Default)]
pub struct VsTriangle {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
}

impl VsTriangle {
    /// Unprepared; the program is made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }
}

fn vertex_source() -> String {
    format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE_GLSL}\n{VERT}")
}

impl ShadowMethod for VsTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["volumes", "negative sides"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            let vert = vertex_source();
            let frag = face_depth_fragment(FRAG);
            let positions = format!("UMBRA_POSITIONS_BINDING {POSITIONS_BINDING}");
            let triangles = format!("UMBRA_TRIANGLES_BINDING {TRIANGLES_BINDING}");
            let program = link_program(
                gl,
                "vs-triangle volume",
                &[
                    ShaderSource::vertex("vs_triangle/volume.vert.glsl", &vert),
                    ShaderSource::fragment("vs_triangle/volume.frag.glsl", &frag),
                ],
                &[&positions, &triangles],
            )?;
            // SAFETY: DSA creation on the current context; the program is deleted on failure.
            let vao = unsafe {
                gl.create_named_vertex_array().map_err(|detail| {
                    gl.delete_program(program);
                    GlError::Create { what: "vs-triangle vertex array", detail }
                })?
            };
            self.gpu = Some(Gpu {
                u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                u_light: uniform(gl, program, "u_light"),
                u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
                u_vertices_per_triangle: uniform(gl, program, "u_vertices_per_triangle"),
                u_pass: uniform(gl, program, "u_pass"),
                depth: DepthUniforms::locate(gl, program),
                program,
                vao,
            });
        }
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        let gpu = self
            .gpu
            .as_ref()
            .ok_or_else(|| GlError::InvalidParams("vs-triangle: draw_volumes before prepare".into()))?;
        let draw_count = |per_triangle: usize| {
            scene.triangle_count().checked_mul(per_triangle).and_then(|n| i32::try_from(n).ok()).ok_or_else(|| {
                GlError::InvalidParams(format!(
                    "{} triangles x {per_triangle} vertices exceed one draw call",
                    scene.triangle_count()
                ))
            })
        };
        let per_triangle = vertices_per_triangle(frame.zpass, frame.light[3] == 0.0);
        let count = draw_count(per_triangle)?;
        let negative_count = draw_count(NEGATIVE_SIDE_VERTICES)?;
        frame.mark(gl, "volumes");
        // Counting state (z-fail or z-pass, two-sided stencil, depth clamp, no colour or depth
        // writes); the reason for every field is in GlState::shadow_volume.
        let state = frame.shadow_volume_state();
        state.apply(gl);
        // SAFETY: our program and VAO; the storage buffers are the scene's, sized for every
        // index the shader computes (3 per triangle, each < positions.len(), checked at upload).
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.bind_vertex_array(Some(gpu.vao));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        gpu.depth.set(gl, frame);
        // SAFETY: as above.
        unsafe {
            // The triangles are read from the scene's buffers, not from vertex attributes.
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS_BINDING, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLES_BINDING, Some(scene.index_buffer()));
            gl.uniform_1_i32(gpu.u_vertices_per_triangle.as_ref(), per_triangle as i32);
            gl.uniform_1_i32(gpu.u_pass.as_ref(), 0);
            if count > 0 {
                gl.draw_arrays(glow::TRIANGLES, 0, count);
            }
        }
        frame.mark(gl, "negative sides");
        GlState {
            // Reason: the -1 sides come in the vertex order of +1 sides (so that both copies of a
            // shared side rasterize identically); calling clockwise the front face counts them
            // with the opposite sign. Everything else is the counting state.
            front_face: glow::CW,
            ..state
        }
        .apply(gl);
        // SAFETY: as above, same program, VAO and buffers.
        unsafe {
            gl.uniform_1_i32(gpu.u_vertices_per_triangle.as_ref(), NEGATIVE_SIDE_VERTICES as i32);
            gl.uniform_1_i32(gpu.u_pass.as_ref(), 1);
            if negative_count > 0 {
                gl.draw_arrays(glow::TRIANGLES, 0, negative_count);
            }
            // Leave no binding of ours behind for the caller.
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS_BINDING, None);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLES_BINDING, None);
        }
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        0
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_program(g.program);
                gl.delete_vertex_array(g.vao);
            }
        }
        self.prepared = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_per_triangle_by_mode() {
        assert_eq!(vertices_per_triangle(false, false), 24);
        assert_eq!(vertices_per_triangle(false, true), 21);
        assert_eq!(vertices_per_triangle(true, false), 18);
        assert_eq!(vertices_per_triangle(true, true), 18);
    }
}
