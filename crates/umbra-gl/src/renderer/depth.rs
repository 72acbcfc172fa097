//! Pass 1 of the frame, once per frame: the clears, then the scene's depth + ambient (+ world
//! position and triangle id when captured), with normal near clipping.

use glow::HasContext;

use umbra_geom::FrameParams;

use super::view::{mark, PassView};
use super::Renderer;
use crate::camera::DepthConventionGl;
use crate::error::GlError;
use crate::methods::StageHook;
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SCENE_VERT};
use crate::state::{GlState, StencilFace};
use crate::target::{RenderTarget, TargetPass};

const DEPTH_FRAG: &str = include_str!("../shaders/depth_ambient.frag.glsl");

/// The depth + ambient program and its uniforms.
pub(super) struct DepthProgram {
    pub(super) program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_ambient_color: Option<glow::UniformLocation>,
}

impl DepthProgram {
    pub(super) fn new(gl: &glow::Context) -> Result<DepthProgram, GlError> {
        let program = link_program(
            gl,
            "depth+ambient",
            &[
                ShaderSource::vertex("shaders/scene.vert.glsl", SCENE_VERT),
                ShaderSource::fragment("shaders/depth_ambient.frag.glsl", DEPTH_FRAG),
            ],
            &[],
        )?;
        Ok(DepthProgram {
            u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
            u_ambient_color: uniform(gl, program, "u_ambient_color"),
            program,
        })
    }
}

impl Renderer {
    /// Pass 1, once per frame: clears colour (to `params.background`), depth (to the
    /// convention's far value) and stencil (to 0) of `view`'s framebuffer, then draws the
    /// scene's depth + ambient (+ world position and triangle id into `own`'s attachments).
    pub(super) fn depth_pass(
        &self,
        gl: &glow::Context,
        scene: &SceneGpu,
        params: &FrameParams,
        view: &PassView,
        own: Option<&RenderTarget>,
        hook: &mut Option<&mut dyn StageHook>,
    ) {
        let convention = view.convention;
        mark(hook, gl, "depth", None);
        // Reason: glClear* obeys the colour/depth/stencil write masks; GL's default state has
        // all of them on (and blending/tests do not affect clears).
        GlState::default().apply(gl);
        view.bind_target(gl);
        // SAFETY: disabling enables that would restrict clears and draws (restored by the
        // caller's SavedState), then clearing the bound framebuffer.
        unsafe {
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::RASTERIZER_DISCARD);
            // Reason: depth cleared to the far plane's depth (1 Standard, 0 reversed-Z), which is
            // also where light caps are pushed (so they fail the strict test there too).
            let far = convention.far_depth();
            match own {
                Some(t) => t.clear(gl, params.background, far),
                None => {
                    gl.clear_buffer_f32_slice(glow::COLOR, 0, &params.background);
                    gl.clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, far, 0);
                }
            }
        }

        // ---- Pass 1: depth + ambient (+ world position, triangle id).
        if let Some(t) = own {
            t.set_draw_buffers(gl, TargetPass::Depth);
        }
        GlState {
            // Reason: nearest surface wins: strictly nearer (LESS Standard, GREATER reversed-Z,
            // where depth = near / distance grows towards the eye); ties keep the first triangle
            // drawn (strict, not LEQUAL / GEQUAL), the same one the lighting pass selects.
            depth_test: true,
            depth_func: convention.nearer(),
            depth_write: true,
            // Reason: the scene uses normal near clipping; only volumes need clamping.
            depth_clamp: false,
            // Reason: the stencil belongs to the per-light volume passes.
            stencil_test: false,
            stencil_front: StencilFace::KEEP,
            stencil_back: StencilFace::KEEP,
            color_write: [true; 4],
            // Reason: which faces a pixel can show (`params.receivers`): none culled for
            // triangle soups, which are two-sided; back faces culled for `Receivers::Front`,
            // so the nearest front-facing triangle wins, as three.js draws a FrontSide
            // material ([`GlState::receivers_cull`]).
            cull_face: GlState::receivers_cull(params.receivers),
            // Reason: counter-clockwise on the screen is the front face (GL's default).
            front_face: glow::CCW,
            // Reason: opaque ambient base colour.
            blend: None,
            // Reason: depths must match the lighting pass and the volumes exactly.
            polygon_offset: None,
        }
        .apply(gl);
        let ambient = params.albedo.map(|a| a * params.ambient);
        // SAFETY: our program and the scene's VAO; uniforms match the shader declarations.
        unsafe {
            gl.use_program(Some(self.depth.program));
            gl.uniform_matrix_4_f32_slice(self.depth.u_clip_from_world.as_ref(), false, &view.clip_f32);
            gl.uniform_3_f32_slice(self.depth.u_ambient_color.as_ref(), &ambient);
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);
    }
}
