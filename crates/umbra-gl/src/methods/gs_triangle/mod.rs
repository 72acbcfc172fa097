//! `gs-triangle`: the closed shadow volume of every triangle, built in a geometry shader.
//!
//! Paper 001, Section 2.1 (per-triangle volumes) and Section 3 (the geometry-shader
//! counterpart the two-pass tessellation method is measured against); orientation through the
//! reference edge (Sections 2.2-2.3, Alg. 2-4) so caps and sides agree with every other method;
//! Eq. 2 extrusion; light caps pushed to the far plane in the geometry shader (paper 003,
//! Eq. 6). Details and the canonical side form in volume.geom.glsl.
//!
//! Face depths: every primitive carries its face's window depth function, flat,
//! computed in the geometry shader ([`crate::methods::face_depth`]), which the fragment shader
//! writes as every fragment's `gl_FragDepth` (`shared/face_depth.frag.glsl`: llvmpipe's
//! interpolated depth is NaN or wrong on some faces).
//!
//! Preprocessing: none beyond the program (it draws the scene's own vertex array and index
//! buffer with `GL_TRIANGLES`); the method owns no buffers (`gpu_bytes() == 0`). Per light:
//! uniforms and two indexed draws with [`VolumeFrame::shadow_volume_state`]: the +1 sides and
//! the caps, then the -1 sides in the vertex order of +1 sides with `glFrontFace(GL_CW)`, so
//! that the two copies of a side shared by light-facing neighbours rasterize identically and
//! cancel exactly (as in vs-triangle).
//!
//! Stages reported: "volumes" (+1 sides and caps), "negative sides".

use glow::HasContext;

use crate::error::GlError;
use crate::methods::face_depth::{face_depth_fragment, DepthUniforms, FACE_DEPTH_COMPONENTS, SIDE_PLANE_GLSL};
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::GlState;

/// Registry name.
pub const NAME: &str = "gs-triangle";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const VERT: &str = include_str!("volume.vert.glsl");
const GEOM: &str = include_str!("volume.geom.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Vertices the geometry shader emits at most per triangle (8 triangles of 3).
pub const MAX_OUTPUT_VERTICES: i32 = 24;

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    u_caps: Option<glow::UniformLocation>,
    u_pass: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

/// See the module documentation.
#[derive(Default)]
pub struct GsTriangle {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
}

impl GsTriangle {
    /// Unprepared; the program is made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }
}

impl ShadowMethod for GsTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["volumes", "negative sides"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            // SAFETY: plain limit queries on the current context.
            let (max_vertices, max_components) = unsafe {
                (
                    gl.get_parameter_i32(glow::MAX_GEOMETRY_OUTPUT_VERTICES),
                    gl.get_parameter_i32(glow::MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS),
                )
            };
            // gl_Position and the flat face depth (a dvec3) per vertex.
            let components = (4 + FACE_DEPTH_COMPONENTS) * MAX_OUTPUT_VERTICES;
            if max_vertices < MAX_OUTPUT_VERTICES || max_components < components {
                return Err(GlError::Unsupported {
                    method: NAME,
                    reason: format!(
                        "needs {MAX_OUTPUT_VERTICES} geometry-shader output vertices ({components} components); the context offers {max_vertices} ({max_components})"
                    ),
                });
            }
            let geom = format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{SIDE_PLANE_GLSL}\n{GEOM}");
            let frag = face_depth_fragment(FRAG);
            let program = link_program(
                gl,
                "gs-triangle volume",
                &[
                    ShaderSource::vertex("gs_triangle/volume.vert.glsl", VERT),
                    ShaderSource { stage: glow::GEOMETRY_SHADER, name: "gs_triangle/volume.geom.glsl", source: &geom },
                    ShaderSource::fragment("gs_triangle/volume.frag.glsl", &frag),
                ],
                &[],
            )?;
            self.gpu = Some(Gpu {
                u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                u_light: uniform(gl, program, "u_light"),
                u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
                u_caps: uniform(gl, program, "u_caps"),
                u_pass: uniform(gl, program, "u_pass"),
                depth: DepthUniforms::locate(gl, program),
                program,
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
            .ok_or_else(|| GlError::InvalidParams("gs-triangle: draw_volumes before prepare".into()))?;
        frame.mark(gl, "volumes");
        // Counting state (z-fail or z-pass, two-sided stencil, depth clamp, no colour or depth
        // writes); the reason for every field is in GlState::shadow_volume.
        let state = frame.shadow_volume_state();
        state.apply(gl);
        // SAFETY: our program and the scene's vertex array (indices checked at upload).
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
            gl.uniform_1_i32(gpu.u_caps.as_ref(), i32::from(!frame.zpass));
            gl.uniform_1_i32(gpu.u_pass.as_ref(), 0);
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        gpu.depth.set(gl, frame);
        // SAFETY: the scene's vertex array (indices checked at upload).
        unsafe {
            // The scene's triangles, in order, one geometry-shader invocation each.
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);
        frame.mark(gl, "negative sides");
        GlState {
            // Reason: the -1 sides come in the vertex order of +1 sides (so that both copies of a
            // shared side rasterize identically); calling clockwise the front face counts them
            // with the opposite sign. Everything else is the counting state.
            front_face: glow::CW,
            ..state
        }
        .apply(gl);
        // SAFETY: same program and vertex array as above.
        unsafe { gl.uniform_1_i32(gpu.u_pass.as_ref(), 1) };
        scene.draw_triangles(gl);
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        0
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own program, not used afterwards.
            unsafe { gl.delete_program(g.program) };
        }
        self.prepared = None;
    }
}
