//! `ts-triangle`: the two-pass per-triangle tessellation method, paper 001 Section 2.1,
//! Algorithm 1 and Fig. 2.
//!
//! Pass 1 ("volumes"): every triangle is a patch of its 3 points; the control shader orients it
//! towards the light through its reference edge (Alg. 2-4) and sets inner level 3, outer 1
//! (or discards an edge-on triangle); the evaluation shader (Alg. 1, equal spacing, reversed
//! winding) keeps the 3 corners and pushes the 3 inner points to infinity (Eq. 2): the sides and
//! the dark (back) cap. Side fragments get the depth of their canonical plane
//! ([`SideDepth::Canonical`], see the parent module) so that the two copies of a side shared by
//! neighbours cancel exactly. Pass 2 ("light caps"): the same patches at level 1, one triangle
//! each, wound to face the light and pushed to the far plane in the evaluation shader (paper
//! 003, Eq. 6), no fragment depth. Both passes counted with
//! [`VolumeFrame::shadow_volume_state`]. In z-pass mode the light-cap pass is skipped; the dark
//! caps of pass 1 lie at depth 1 and never pass the LESS depth test, so they change nothing.
//!
//! Preprocessing: none (the paper's point); the method owns no buffers (`gpu_bytes() == 0`).

use glow::HasContext;

use super::{draw_triangle_patches, require_tess_level, with_shared, PATCH_VERT, SIDE_DEPTH_FRAG, VOLUME_FRAG};
use crate::error::GlError;
use crate::methods::face_depth::DepthUniforms;
use crate::methods::method::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "ts-triangle";

const TESC: &str = include_str!("two_pass.tesc.glsl");
const TESE: &str = include_str!("two_pass.tese.glsl");
const CAPS_TESE: &str = include_str!("light_caps.tese.glsl");

/// Depth of the side fragments of pass 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SideDepth {
    /// The depth of the side's canonical plane, written as gl_FragDepth. Exact.
    #[default]
    Canonical,
    /// The rasterized depth (the paper's method as written, early depth test kept). Shared
    /// sides may fail to cancel by one at samples at their depth; for measurements only.
    Rasterized,
}

struct Program {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    depth: DepthUniforms,
}

impl Program {
    fn link(
        gl: &glow::Context,
        name: &str,
        tese: (&str, &str),
        frag: (&str, &str),
        defines: &[&str],
    ) -> Result<Self, GlError> {
        let tesc = with_shared(TESC);
        let tese_source = with_shared(tese.1);
        let program = link_program(
            gl,
            name,
            &[
                ShaderSource::vertex("ts_triangle/patch.vert.glsl", PATCH_VERT),
                ShaderSource {
                    stage: glow::TESS_CONTROL_SHADER,
                    name: "ts_triangle/two_pass.tesc.glsl",
                    source: &tesc,
                },
                ShaderSource { stage: glow::TESS_EVALUATION_SHADER, name: tese.0, source: &tese_source },
                ShaderSource::fragment(frag.0, frag.1),
            ],
            defines,
        )?;
        Ok(Self {
            u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
            u_light: uniform(gl, program, "u_light"),
            u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
            depth: DepthUniforms::locate(gl, program),
            program,
        })
    }

    /// Makes the program current with this frame's uniforms.
    fn bind(&self, gl: &glow::Context, frame: &VolumeFrame<'_>) {
        // SAFETY: our linked program; uniform types match the shader declarations.
        unsafe {
            gl.use_program(Some(self.program));
            gl.uniform_matrix_4_f32_slice(self.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(self.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(self.u_far_clip_z.as_ref(), frame.far_clip_z());
        }
        self.depth.set(gl, frame);
    }
}

struct Gpu {
    volumes: Program,
    light_caps: Program,
}

/// See the module documentation.
#[derive(Default)]
pub struct TsTriangle {
    side_depth: SideDepth,
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
}

impl TsTriangle {
    /// The registered, exact method ([`SideDepth::Canonical`]).
    pub fn new() -> Self {
        Self::default()
    }

    /// A variant with the side depths of pass 1 as `side_depth` says.
    pub fn with_side_depth(side_depth: SideDepth) -> Self {
        Self { side_depth, ..Self::default() }
    }
}

impl ShadowMethod for TsTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["volumes", "light caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            require_tess_level(gl, NAME, 3)?;
            let defines: &[&str] = match self.side_depth {
                SideDepth::Canonical => &["UMBRA_CANONICAL_SIDES"],
                SideDepth::Rasterized => &[],
            };
            let volumes = Program::link(
                gl,
                "ts-triangle volumes",
                ("ts_triangle/two_pass.tese.glsl", TESE),
                ("ts_triangle/side_depth.frag.glsl", SIDE_DEPTH_FRAG),
                defines,
            )?;
            let light_caps = match Program::link(
                gl,
                "ts-triangle light caps",
                ("ts_triangle/light_caps.tese.glsl", CAPS_TESE),
                ("ts_triangle/volume.frag.glsl", VOLUME_FRAG),
                &["UMBRA_LIGHT_CAPS"],
            ) {
                Ok(p) => p,
                Err(e) => {
                    // SAFETY: our own program, not used afterwards.
                    unsafe { gl.delete_program(volumes.program) };
                    return Err(e);
                }
            };
            self.gpu = Some(Gpu { volumes, light_caps });
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
            .ok_or_else(|| GlError::InvalidParams("ts-triangle: draw_volumes before prepare".into()))?;
        // Counting state (z-fail or z-pass, two-sided stencil, depth clamp, no colour or depth
        // writes: gl_FragDepth only feeds the depth test); the reason for every field is in
        // GlState::shadow_volume. Same for both passes.
        frame.shadow_volume_state().apply(gl);
        frame.mark(gl, "volumes");
        gpu.volumes.bind(gl, frame);
        draw_triangle_patches(gl, scene);
        frame.mark(gl, "light caps");
        if !frame.zpass {
            gpu.light_caps.bind(gl, frame);
            draw_triangle_patches(gl, scene);
        }
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        0
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own programs, not used afterwards.
            unsafe {
                gl.delete_program(g.volumes.program);
                gl.delete_program(g.light_caps.program);
            }
        }
        self.prepared = None;
    }
}
