//! `all-edges-invert`: paper 002's shadow volumes for highly concave casters (trees): no
//! silhouette at all, every triangle's full volume, one pass with face culling off and the
//! stencil operations ZFAIL = INVERT, PASS = INCR under write mask 1101b, test NOTEQUAL 1100b
//! under mask 1101b; a sample is shadowed where the stencil ends as 1100b.
//!
//! Paper 002, Section 3 (3.1 the required operations, 3.2 the functions). Why it works, per
//! sample, with the stencil starting at 0: with write mask 1101b the PASS operation INCR
//! toggles 0 <-> 1 (2 = 0010b loses its masked bit 1), the ZFAIL operation INVERT toggles
//! 0 <-> 1101b, and one of each in either order gives 1100b (0001b inverted is 1110b, masked
//! 1100b; 1101b + 1 = 1110b, masked 1100b), where the NOTEQUAL test then fails forever (KEEP):
//! "whenever a polygon casts its shadow, no other polygon can erase it". A sample inside one
//! triangle's (convex) volume sees exactly one of its faces in front (PASS) and one behind
//! (ZFAIL); outside it sees 0 or 2 of the same kind, which cancel. The volumes are drawn one
//! after another, so the stencil returns to 0 after every volume the sample is outside of and
//! locks at 1100b after the first one it is inside of.
//!
//! Overlapping volumes of different triangles are therefore fine as long as each volume is
//! drawn whole before the next (here: 24 consecutive vertices of one draw, and GL applies
//! stencil updates in primitive order). Where it is not exact:
//! * the eye inside a volume (camera in shadow): that volume shows every sample only its exit
//!   face, one ZFAIL (1101b) for a sample inside it, one PASS (0001b) for a sample beyond it,
//!   and any later volume the sample is outside of turns that into 1100b (PASS PASS after
//!   1101b, ZFAIL ZFAIL after 0001b) or back — false shadow and false light;
//! * ties, because each face decides PASS or ZFAIL on its own: at shadow boundaries (like
//!   every method), and on a lit caster right next to an interior edge, where the side cast
//!   from that edge (by both neighbours) passes through the sample: counting methods cancel
//!   the two copies, here each volume is judged alone, and a tie read as "side in front" makes
//!   that neighbour's volume PASS + ZFAIL = 1100b, a speck of false shadow. (Copies of one side
//!   are emitted in one canonical vertex order, volume.vert.glsl, so they at least agree.)
//!   Measured: 1-12 samples outside the band per torture case, 53 and 60 of 921,600 on the
//!   default 1280x720 views of Crytek Sponza and Conference.
//!
//! `umbra_verify::must_be_exact` lists the method as measured only.
//!
//! Once per mesh: the program and an empty vertex array; the triangles are read from the
//! scene's own buffers (`gpu_bytes() == 0`). Per light: uniforms, one non-indexed draw of 24
//! vertices per triangle (21 for a directional light). `frame.zpass` is ignored: the method is
//! neither z-pass nor z-fail, it needs both outcomes of the depth test.
//!
//! Stages reported: "volumes".

use glow::HasContext;

use crate::error::GlError;
use crate::methods::method::{Classification, ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::{GlState, StencilFace};

/// Registry name.
pub const NAME: &str = "all-edges-invert";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const DEPTH: &str = include_str!("../shared/depth.glsl");
const VERT: &str = include_str!("volume.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");

/// Paper 002's stencil value of a shadowed sample, STENCILREF.
pub const SHADOW_VALUE: i32 = 0b1100;
/// Paper 002's STENCILMASK and STENCILWRITEMASK.
pub const MASK: u32 = 0b1101;

/// Shader-storage binding points of the scene's positions and triangles during the draw
/// (unbound afterwards); away from the lighting pass's normals (binding 0).
pub const POSITIONS_BINDING: u32 = 2;
/// Shader-storage binding point of the scene's triangles during the draw.
pub const TRIANGLES_BINDING: u32 = 3;

/// Vertices per scene triangle: 3 side quads, light cap and (point lights) dark cap.
pub fn vertices_per_triangle(directional: bool) -> usize {
    if directional {
        21
    } else {
        24
    }
}

/// The stencil operations of paper 002, one value per stencil update, as GL applies them:
/// `new = op(old)`, stored `(new & write_mask) | (old & !write_mask)`, and no update at all
/// once the NOTEQUAL test fails (stored value 1100b under mask 1101b).
pub fn stencil_after(events: impl IntoIterator<Item = DepthOutcome>) -> u8 {
    let mut s: u8 = 0;
    let mask = MASK as u8;
    for e in events {
        if s & mask == (SHADOW_VALUE as u8) & mask {
            continue; // the stencil test fails: KEEP
        }
        let new = match e {
            DepthOutcome::Pass => s.saturating_add(1), // INCR (clamps at 255)
            DepthOutcome::Fail => !s,                  // INVERT
        };
        s = (new & mask) | (s & !mask);
    }
    s
}

/// The depth test's outcome for one volume fragment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthOutcome {
    /// The volume fragment is nearer than the stored depth.
    Pass,
    /// The volume fragment is behind the stored depth.
    Fail,
}

/// Paper 002's volume-pass state, every field with its reason. `depth_func` is the counting
/// state's for the frame's depth convention (LESS with the standard depth range, GREATER with a
/// reversed one): a volume face strictly in front of the sample passes, one behind it or at the
/// same depth fails, and a light cap at the far plane always fails - what the paper gets from
/// ZFUNC = LESS on the standard range.
pub fn volume_state(depth_func: u32) -> GlState {
    let face = StencilFace {
        // Reason: "no other polygon can erase" a shadow: once a sample holds 1100b (under mask
        // 1101b) the test fails and STENCILFAIL = KEEP freezes it.
        func: glow::NOTEQUAL,
        reference: SHADOW_VALUE,
        value_mask: MASK,
        // Reason: bit 1 is never written, so INCR from 1 gives 2 -> 0 (PASS twice cancels) and
        // INVERT toggles 0 <-> 1101b (ZFAIL twice cancels); PASS + ZFAIL in either order = 1100b.
        write_mask: MASK,
        // Reason: a frozen (shadowed) sample stays as it is.
        stencil_fail: glow::KEEP,
        // Reason: paper 002, STENCILZFAIL = INVERT.
        depth_fail: glow::INVERT,
        // Reason: paper 002, STENCILPASS = INCR.
        depth_pass: glow::INCR,
    };
    GlState {
        // Reason: the method is built on both outcomes of the depth test against the scene.
        depth_test: true,
        depth_func,
        // Reason: volumes are invisible; the scene depth must survive for the lighting pass.
        depth_write: false,
        // Reason: as for counting volumes, no face may be clipped by the near or far plane
        // (w = 0 vertices land at depth 1 and could round beyond it; faces before the near
        // plane are clamped to depth 0 and pass, as they should).
        depth_clamp: true,
        stencil_test: true,
        // Reason: "the method should not differ" back and front sides: the same test and
        // operations for both faces.
        stencil_front: face,
        stencil_back: face,
        // Reason: the volume pass only marks the stencil.
        color_write: [false; 4],
        // Reason: paper 002, CULLMODE = NONE: back and front sides in one pass.
        cull_face: None,
        // Reason: irrelevant with culling off and identical faces; GL's default.
        front_face: glow::CCW,
        // Reason: no colour is written.
        blend: None,
        // Reason: an offset would move the faces relative to the scene depth.
        polygon_offset: None,
    }
}

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    u_vertices_per_triangle: Option<glow::UniformLocation>,
    /// Core profile needs a bound vertex array even with no attributes.
    vao: glow::VertexArray,
}

/// See the module documentation.
#[derive(Default)]
pub struct AllEdgesInvert {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
}

impl AllEdgesInvert {
    /// Unprepared; programs and buffers are made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }
}

impl ShadowMethod for AllEdgesInvert {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["volumes"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        if self.gpu.is_none() {
            let vert = format!("#version 450 core\n{MULTIPLICITY}\n{DEPTH}\n{VERT}");
            let positions = format!("UMBRA_POSITIONS_BINDING {POSITIONS_BINDING}");
            let triangles = format!("UMBRA_TRIANGLES_BINDING {TRIANGLES_BINDING}");
            let program = link_program(
                gl,
                "all-edges-invert volume",
                &[
                    ShaderSource::vertex("all_edges_invert/volume.vert.glsl", &vert),
                    ShaderSource::fragment("all_edges_invert/volume.frag.glsl", FRAG),
                ],
                &[&positions, &triangles],
            )?;
            // SAFETY: DSA creation on the current context; the program is deleted on failure.
            let vao = unsafe {
                gl.create_named_vertex_array().map_err(|detail| {
                    gl.delete_program(program);
                    GlError::Create { what: "all-edges-invert vertex array", detail }
                })?
            };
            self.gpu = Some(Gpu {
                u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                u_light: uniform(gl, program, "u_light"),
                u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
                u_vertices_per_triangle: uniform(gl, program, "u_vertices_per_triangle"),
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
            .ok_or_else(|| GlError::InvalidParams("all-edges-invert: draw_volumes before prepare".into()))?;
        let per_triangle = vertices_per_triangle(frame.light[3] == 0.0);
        let count =
            scene.triangle_count().checked_mul(per_triangle).and_then(|n| i32::try_from(n).ok()).ok_or_else(|| {
                GlError::InvalidParams(format!(
                    "{} triangles x {per_triangle} vertices exceed one draw call",
                    scene.triangle_count()
                ))
            })?;
        frame.mark(gl, "volumes");
        // The depth convention comes from the frame (LESS now, GREATER if reversed); the
        // stencil scheme is paper 002's own, see volume_state. Always the stencil counting
        // state's depth func: this method never uses the wide counter (its classification is
        // not StencilZero).
        volume_state(crate::GlState::shadow_volume_for(frame.zpass, frame.depth_convention()).depth_func).apply(gl);
        if count == 0 {
            return Ok(());
        }
        // SAFETY: our program and VAO; the storage buffers are the scene's, sized for every
        // index the shader computes.
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.bind_vertex_array(Some(gpu.vao));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
            gl.uniform_1_i32(gpu.u_vertices_per_triangle.as_ref(), per_triangle as i32);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS_BINDING, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLES_BINDING, Some(scene.index_buffer()));
            gl.draw_arrays(glow::TRIANGLES, 0, count);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS_BINDING, None);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLES_BINDING, None);
        }
        Ok(())
    }

    /// Lit where the stencil test `NOTEQUAL 1100b` under mask 1101b passes, i.e. where the
    /// stencil is not 1100b (bit 1 is never written, so "under the mask" changes nothing).
    fn classification(&self) -> Classification {
        Classification::StencilTest { func: glow::NOTEQUAL, reference: SHADOW_VALUE, value_mask: MASK }
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
    use super::DepthOutcome::{Fail, Pass};
    use super::*;

    #[test]
    fn pass_and_zfail_in_either_order_give_the_shadow_value() {
        assert_eq!(stencil_after([Pass, Fail]), 0b1100);
        assert_eq!(stencil_after([Fail, Pass]), 0b1100);
    }

    #[test]
    fn two_of_a_kind_cancel() {
        assert_eq!(stencil_after([Pass, Pass]), 0);
        assert_eq!(stencil_after([Fail, Fail]), 0);
        assert_eq!(stencil_after([Pass]), 1);
        assert_eq!(stencil_after([Fail]), 0b1101);
    }

    #[test]
    fn shadow_is_never_erased() {
        assert_eq!(stencil_after([Pass, Fail, Pass, Pass, Fail]), 0b1100);
        assert_eq!(stencil_after([Fail, Pass, Fail]), 0b1100);
    }

    #[test]
    fn volumes_drawn_one_after_another_are_a_union() {
        // Outside volume 1 (both faces behind), inside volume 2, outside volume 3 (in front).
        let v_outside_behind = [Fail, Fail];
        let v_inside = [Pass, Fail];
        let v_outside_front = [Pass, Pass];
        let all: Vec<_> = v_outside_behind.iter().chain(&v_inside).chain(&v_outside_front).copied().collect();
        assert_eq!(stencil_after(all), 0b1100);
        let none: Vec<_> = v_outside_behind.iter().chain(&v_outside_front).copied().collect();
        assert_eq!(stencil_after(none), 0);
    }

    #[test]
    fn interleaved_volumes_can_cancel() {
        // Two volumes containing the sample whose faces interleave: P1 P2 F1 F2 is read as
        // pass, pass (cancel), fail, fail (cancel): no shadow. Drawing volume after volume
        // avoids exactly this.
        assert_eq!(stencil_after([Pass, Pass, Fail, Fail]), 0);
    }

    #[test]
    fn state_is_papers() {
        let s = volume_state(glow::LESS);
        assert_eq!(s.cull_face, None);
        assert_eq!(s.stencil_front, s.stencil_back);
        assert_eq!(
            (s.stencil_front.func, s.stencil_front.reference, s.stencil_front.value_mask),
            (glow::NOTEQUAL, 0b1100, 0b1101)
        );
        assert_eq!(
            (s.stencil_front.depth_fail, s.stencil_front.depth_pass, s.stencil_front.write_mask),
            (glow::INVERT, glow::INCR, 0b1101)
        );
        assert_eq!(volume_state(glow::GREATER).depth_func, glow::GREATER);
    }
}
