//! The renderer's lighting (pass 3) and the resolve of a shader-classified method's decision
//! into the stencil (for [`Renderer::count_shadows`]): the lighting programs and the passes
//! that draw with them.

use glow::HasContext;
use umbra_geom::Light;

use umbra_geom::FrameParams;

use super::view::{mark, PassView};
use super::Renderer;
use crate::error::GlError;
use crate::image::LitMaskImage;
use crate::methods::{Classification, ShadowMethod, StageHook};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, NORMALS_BINDING, SCENE_VERT};
use crate::state::{BlendState, GlState, StencilFace};
use crate::target::{RenderTarget, TargetPass};

const LIGHTING_FRAG: &str = include_str!("../shaders/lighting.frag.glsl");

/// What a lighting program of a [`Classification::Shader`] method is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum LitPass {
    /// Umbra's lighting pass: the light's term is multiplied by `umbra_lit`'s 0/1 (no
    /// `discard`, so early depth and stencil tests stay on: measured on llvmpipe, the
    /// discarding pass cost 4x `none`'s, see docs/benchmarks.md).
    Shade,
    /// The resolve into the stencil ([`Renderer::count_shadows`]): fragments where
    /// `umbra_lit` is false are discarded, the survivors write stencil 0
    /// (`UMBRA_DISCARD_UNLIT`).
    Resolve,
}

pub(super) struct LightingProgram {
    pub(super) program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_light_color: Option<glow::UniformLocation>,
    u_eye: Option<glow::UniformLocation>,
    u_albedo: Option<glow::UniformLocation>,
    u_specular: Option<glow::UniformLocation>,
    u_shininess: Option<glow::UniformLocation>,
}

impl LightingProgram {
    /// The stencil-classified program (`custom` None), or the one of a shader-classified
    /// method (`custom` = its name and `umbra_lit` GLSL) for `pass`.
    pub(super) fn new(gl: &glow::Context, custom: Option<(&str, &str)>, pass: LitPass) -> Result<Self, GlError> {
        let (frag, mut defines, name) = match custom {
            Some((method, glsl)) => {
                (format!("{LIGHTING_FRAG}\n{glsl}\n"), vec!["UMBRA_CUSTOM_LIT"], format!("lighting+{method}"))
            }
            None => (LIGHTING_FRAG.to_string(), vec![], "lighting".to_string()),
        };
        if pass == LitPass::Resolve {
            defines.push("UMBRA_DISCARD_UNLIT");
        }
        let program = link_program(
            gl,
            &name,
            &[
                ShaderSource::vertex("shaders/scene.vert.glsl", SCENE_VERT),
                ShaderSource::fragment("shaders/lighting.frag.glsl", &frag),
            ],
            &defines,
        )?;
        let u = |n| uniform(gl, program, n);
        Ok(Self {
            u_clip_from_world: u("u_clip_from_world"),
            u_light: u("u_light"),
            u_light_color: u("u_light_color"),
            u_eye: u("u_eye"),
            u_albedo: u("u_albedo"),
            u_specular: u("u_specular"),
            u_shininess: u("u_shininess"),
            program,
        })
    }
}

impl Renderer {
    /// For a shader-classified method after its volume pass (its map of this light drawn):
    /// the stencil becomes 0 where `umbra_lit` holds on the visible surface, 1 elsewhere.
    /// Draws the scene with the method's [`LitPass::Resolve`] lighting program (which
    /// discards where `umbra_lit` is false) and writes nothing but the stencil.
    pub(super) fn shader_lit_to_stencil(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        view: &PassView,
        light: Light,
    ) -> Result<(), GlError> {
        // Reason: the stencil clear obeys the stencil write mask; default = all bits.
        GlState::default().apply(gl);
        view.bind_target(gl);
        // SAFETY: clears the stencil of the bound draw framebuffer to 1 = "not lit".
        unsafe { gl.clear_buffer_i32_slice(glow::STENCIL, 0, &[1]) };
        let write_zero = StencilFace {
            // Reason: every fragment that survives the shader's umbra_lit test marks its
            // pixel lit (0); the depth test below keeps only the visible surface.
            func: glow::ALWAYS,
            reference: 0,
            value_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: glow::KEEP,
            depth_fail: glow::KEEP,
            depth_pass: glow::REPLACE,
        };
        GlState {
            // Reason: only the surface the caller's depth holds (bit-identical depths, see
            // count_shadows' invariance requirement).
            depth_test: true,
            depth_func: glow::EQUAL,
            // Reason: the caller's depth is final and must stay untouched.
            depth_write: false,
            // Reason: same clipping as the caller's scene pass.
            depth_clamp: false,
            stencil_test: true,
            stencil_front: write_zero,
            stencil_back: write_zero,
            // Reason: no colour output at all (the caller's colour stays untouched).
            color_write: [false; 4],
            // Reason: the faces pass 1 showed, culled as it culled them: a culled triangle
            // coplanar with the visible one would pass EQUAL too ([`GlState::receivers_cull`]).
            cull_face: GlState::receivers_cull(params.receivers),
            front_face: glow::CCW,
            blend: None,
            polygon_offset: None,
        }
        .apply(gl);
        let p = self.lighting_program(gl, method, LitPass::Resolve)?;
        let program = p.program;
        // SAFETY: our program, the scene's VAO and normal SSBO; uniforms match the shader
        // (only the ones umbra_lit and the vertex stage read matter: no colour is written).
        unsafe {
            gl.use_program(Some(program));
            gl.uniform_matrix_4_f32_slice(p.u_clip_from_world.as_ref(), false, &view.clip_f32);
            gl.uniform_4_f32_slice(p.u_light.as_ref(), &light);
            gl.uniform_4_f32_slice(p.u_eye.as_ref(), &view.shading_eye);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NORMALS_BINDING, Some(scene.normal_buffer()));
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        let frame = view.volume_frame(params, light, 0, method.name());
        method.bind_lighting(gl, program, &frame)?;
        scene.draw_triangles(gl);
        Ok(())
    }

    /// The lighting program for `method` and `pass` (compiled on first use): the stencil
    /// program (key `("", Shade)`) for stencil classifications, else the method's own.
    fn lighting_program(
        &mut self,
        gl: &glow::Context,
        method: &dyn ShadowMethod,
        pass: LitPass,
    ) -> Result<&LightingProgram, GlError> {
        let key = match method.classification() {
            Classification::Shader => (method.name(), pass),
            _ => ("", LitPass::Shade),
        };
        if let std::collections::hash_map::Entry::Vacant(slot) = self.lighting.entry(key) {
            let glsl = method.lighting_glsl().ok_or_else(|| GlError::Unsupported {
                method: method.name(),
                reason: "Classification::Shader without lighting_glsl()".into(),
            })?;
            slot.insert(LightingProgram::new(gl, Some((method.name(), glsl)), pass)?);
        }
        self.lighting.get(&key).ok_or_else(|| GlError::InvalidParams("lighting program missing".into()))
    }

    /// Pass 3, one light: adds its diffuse + specular where `method`'s classification says
    /// "lit" (the stencil after [`Renderer::volume_pass`], or the method's shader) on the
    /// surfaces whose depth is in the framebuffer (depth EQUAL, no depth writes, additive
    /// blending). With `lit_mask` (a target with a lit-mask attachment) clears that mask
    /// first, writes this light's decision into it and returns it read back.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn lighting_pass(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        view: &PassView,
        own: Option<&RenderTarget>,
        lit_mask: Option<&RenderTarget>,
        light: Light,
        light_index: usize,
        hook: &mut Option<&mut dyn StageHook>,
    ) -> Result<Option<LitMaskImage>, GlError> {
        if let Some(t) = lit_mask {
            // Reason: the clear obeys the colour write mask, which the method may have
            // turned off; GL's default state has it on.
            GlState::default().apply(gl);
            t.clear_lit_mask(gl);
        }

        // ---- Pass 3: lighting where lit.
        mark(hook, gl, "lighting", Some(light_index));
        let classification = method.classification();
        let one_per_pixel = StencilFace {
            // Reason: lit where the count is 0 (or, for Shader classification, where no
            // fragment of this light has been shaded yet: the method leaves the cleared 0).
            func: glow::EQUAL,
            reference: 0,
            value_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: glow::KEEP,
            depth_fail: glow::KEEP,
            // Reason: the first fragment shaded at a pixel bumps the stencil to 1, so a
            // coplanar duplicate triangle at the same depth (common in soups) cannot add
            // this light a second time. The stencil is cleared before the next light.
            depth_pass: glow::INCR_WRAP,
        };
        let stencil_face = match classification {
            Classification::StencilZero | Classification::Shader => one_per_pixel,
            Classification::StencilTest { func, reference, value_mask } => StencilFace {
                // Reason: the method's own "lit" test; its stencil encoding is unknown to
                // us, so nothing is written (coplanar duplicates may add light twice).
                func,
                reference,
                value_mask,
                write_mask: 0,
                stencil_fail: glow::KEEP,
                depth_fail: glow::KEEP,
                depth_pass: glow::KEEP,
            },
        };
        if let Some(t) = own {
            // Colour (and the lit mask when captured): pass 3 must not touch world
            // position / triangle id.
            t.set_draw_buffers(gl, TargetPass::Lighting { lit_mask: lit_mask.is_some() });
        }
        GlState {
            // Reason: shade exactly the surface pass 1 left visible: the same invariant
            // vertex shader gives bit-identical depths, EQUAL selects them (in either depth
            // convention).
            depth_test: true,
            depth_func: glow::EQUAL,
            // Reason: depth is final after pass 1.
            depth_write: false,
            // Reason: same clipping as pass 1, or depths could differ near the near plane.
            depth_clamp: false,
            stencil_test: true,
            stencil_front: stencil_face,
            stencil_back: stencil_face,
            // Reason: alpha keeps pass 1's coverage value 1.
            color_write: [true, true, true, false],
            // Reason: the faces pass 1 showed, culled as it culled them: a culled triangle
            // coplanar with the visible one would pass EQUAL and add this light where the
            // surface shown is not lit ([`GlState::receivers_cull`]).
            cull_face: GlState::receivers_cull(params.receivers),
            front_face: glow::CCW,
            // Reason: each light adds its diffuse + specular onto ambient + earlier lights.
            // On the R8 lit mask (draw buffer 3) the same blend is min(1, dst + src) with
            // src in {0, 1}: an OR, so a second fragment of a pixel cannot clear the bit.
            blend: Some(BlendState::ADDITIVE),
            polygon_offset: None,
        }
        .apply(gl);
        let p = self.lighting_program(gl, method, LitPass::Shade)?;
        // SAFETY: our program, the scene's VAO and normal SSBO; uniforms match the shader.
        unsafe {
            gl.use_program(Some(p.program));
            gl.uniform_matrix_4_f32_slice(p.u_clip_from_world.as_ref(), false, &view.clip_f32);
            gl.uniform_4_f32_slice(p.u_light.as_ref(), &light);
            gl.uniform_3_f32_slice(p.u_light_color.as_ref(), &params.light_color);
            gl.uniform_4_f32_slice(p.u_eye.as_ref(), &view.shading_eye);
            gl.uniform_3_f32_slice(p.u_albedo.as_ref(), &params.albedo);
            gl.uniform_1_f32(p.u_specular.as_ref(), params.specular);
            gl.uniform_1_f32(p.u_shininess.as_ref(), params.shininess);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NORMALS_BINDING, Some(scene.normal_buffer()));
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        if classification == Classification::Shader {
            let program = p.program;
            let frame = view.volume_frame(params, light, light_index, method.name());
            method.bind_lighting(gl, program, &frame)?;
        }
        scene.draw_triangles(gl);
        Ok(lit_mask.and_then(|t| t.read_lit_mask(gl)))
    }
}
