//! `ts-triangle-1pass`: the single-pass per-triangle tessellation method, paper 001 Section
//! 2.1 and Fig. 3, with the fragment-depth push of Section 2.3.
//!
//! Every triangle is a patch of its 3 points; the control shader (4 invocations: the triangle
//! plus the added quad corner) orients it through its reference edge (Alg. 2-4) and sets outer
//! levels (1, 5, 1, 5), inner (5, 1), fractional odd spacing; the evaluation shader maps the
//! 5-cell strip onto the 5 faces of the triangle's volume (table in one_pass.tese.glsl):
//! 3 sides, dark cap, light cap — one draw.
//!
//! The light cap must lie at the far plane (or it z-fights with the caster, Section 2.3). Its
//! tessellated vertices are shared with two of the sides in every column assignment that
//! yields the volume (exhaustive search, see one_pass.tese.glsl), so it cannot be moved in the
//! evaluation stage the way every other umbra method moves caps; the fragment shader moves its
//! fragments instead, as the paper did, and gives the side fragments their canonical plane's
//! depth (see the parent module): [`FragmentDepth::Exact`], the registered method. The depth
//! write disables early depth testing for the volume draw. [`FragmentDepth::CapsOnly`] is the
//! paper's variant as published (sides keep their rasterized depth), [`FragmentDepth::None`]
//! writes no depth at all (cap z-fights with the caster); both exist to measure costs and are
//! neither registered nor exact.
//!
//! Preprocessing: none; the method owns no buffers (`gpu_bytes() == 0`). Counted with
//! [`VolumeFrame::shadow_volume_state`]; the same draw serves z-pass (the cap fragments at the
//! far plane and the dark cap at infinity never pass the depth test).

use glow::HasContext;

use super::{draw_triangle_patches, require_tess_level, with_shared, PATCH_VERT, SIDE_DEPTH_FRAG};
use crate::error::GlError;
use crate::methods::face_depth::DepthUniforms;
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "ts-triangle-1pass";

const TESC: &str = include_str!("one_pass.tesc.glsl");
const TESE: &str = include_str!("one_pass.tese.glsl");
/// Which fragment depths the volume draw writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FragmentDepth {
    /// Light-cap fragments at the far plane, side fragments at their canonical plane. Exact.
    #[default]
    Exact,
    /// Light-cap fragments at the far plane only: paper 001 Section 2.3 as published. Shared
    /// sides may fail to cancel at samples at their depth. Measurements only.
    CapsOnly,
    /// No depth write, early depth test kept: the cap z-fights with the caster. Measurements
    /// only.
    None,
}

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

/// See the module documentation.
#[derive(Default)]
pub struct TsTriangle1Pass {
    fragment_depth: FragmentDepth,
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
}

impl TsTriangle1Pass {
    /// The registered, exact method ([`FragmentDepth::Exact`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// A variant writing the fragment depths `fragment_depth` says.
    pub fn with_fragment_depth(fragment_depth: FragmentDepth) -> Self {
        Self { fragment_depth, ..Self::default() }
    }

    /// Which fragment depths this instance writes.
    pub fn fragment_depth(&self) -> FragmentDepth {
        self.fragment_depth
    }
}

impl ShadowMethod for TsTriangle1Pass {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["volumes"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            require_tess_level(gl, NAME, 5)?;
            let tesc = with_shared(TESC);
            let tese = with_shared(TESE);
            let defines: &[&str] = match self.fragment_depth {
                FragmentDepth::Exact => &["UMBRA_CAPS_TO_FAR", "UMBRA_CANONICAL_SIDES"],
                FragmentDepth::CapsOnly => &["UMBRA_CAPS_TO_FAR"],
                FragmentDepth::None => &[],
            };
            let program = link_program(
                gl,
                "ts-triangle-1pass volumes",
                &[
                    ShaderSource::vertex("ts_triangle/patch.vert.glsl", PATCH_VERT),
                    ShaderSource {
                        stage: glow::TESS_CONTROL_SHADER,
                        name: "ts_triangle/one_pass.tesc.glsl",
                        source: &tesc,
                    },
                    ShaderSource {
                        stage: glow::TESS_EVALUATION_SHADER,
                        name: "ts_triangle/one_pass.tese.glsl",
                        source: &tese,
                    },
                    ShaderSource::fragment("ts_triangle/side_depth.frag.glsl", SIDE_DEPTH_FRAG),
                ],
                defines,
            )?;
            self.gpu = Some(Gpu {
                u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                u_light: uniform(gl, program, "u_light"),
                u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
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
            .ok_or_else(|| GlError::InvalidParams("ts-triangle-1pass: draw_volumes before prepare".into()))?;
        frame.mark(gl, "volumes");
        // Counting state (z-fail or z-pass, two-sided stencil, depth clamp, no colour or depth
        // writes: gl_FragDepth only feeds the depth test); the reason for every field is in
        // GlState::shadow_volume.
        frame.shadow_volume_state().apply(gl);
        // SAFETY: our linked program; uniform types match the shader declarations.
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
        }
        gpu.depth.set(gl, frame);
        draw_triangle_patches(gl, scene);
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
