//! Fixed-function GL state as one small `Copy` value, applied in full before every draw
//! (the approach of asny/three-d): no draw depends on state another draw left lying around.
//!
//! What [`GlState::apply`] sets (and [`GlState::capture`] reads back, so a caller's state can
//! be restored): DEPTH_TEST, glDepthFunc, glDepthMask, DEPTH_CLAMP, STENCIL_TEST,
//! glStencilFuncSeparate / glStencilMaskSeparate / glStencilOpSeparate for FRONT and BACK,
//! glColorMask (all draw buffers), CULL_FACE, glCullFace, glFrontFace, BLEND,
//! glBlendFuncSeparate, glBlendEquationSeparate (all draw buffers), POLYGON_OFFSET_FILL and
//! glPolygonOffset. Nothing else.

use glow::HasContext;

use crate::camera::{DepthConvention, DepthConventionGl};
use umbra_geom::frame::Receivers;

/// One face's stencil function and operations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StencilFace {
    /// glStencilFuncSeparate: comparison (ALWAYS, EQUAL, ...).
    pub func: u32,
    /// glStencilFuncSeparate: reference value.
    pub reference: i32,
    /// glStencilFuncSeparate: mask ANDed with reference and stored value before comparing.
    pub value_mask: u32,
    /// glStencilMaskSeparate: bits the operations may write.
    pub write_mask: u32,
    /// glStencilOpSeparate: operation when the stencil test fails.
    pub stencil_fail: u32,
    /// glStencilOpSeparate: operation when the stencil test passes and the depth test fails.
    pub depth_fail: u32,
    /// glStencilOpSeparate: operation when both tests pass.
    pub depth_pass: u32,
}

impl StencilFace {
    /// Test always passes, nothing is written (GL's defaults except the write mask).
    pub const KEEP: StencilFace = StencilFace {
        func: glow::ALWAYS,
        reference: 0,
        value_mask: !0,
        write_mask: 0,
        stencil_fail: glow::KEEP,
        depth_fail: glow::KEEP,
        depth_pass: glow::KEEP,
    };
}

/// Blend function and equation (same for every draw buffer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlendState {
    /// glBlendFuncSeparate: source factor of the colour channels.
    pub src_rgb: u32,
    /// glBlendFuncSeparate: destination factor of the colour channels.
    pub dst_rgb: u32,
    /// glBlendFuncSeparate: source factor of alpha.
    pub src_alpha: u32,
    /// glBlendFuncSeparate: destination factor of alpha.
    pub dst_alpha: u32,
    /// glBlendEquationSeparate: equation of the colour channels.
    pub equation_rgb: u32,
    /// glBlendEquationSeparate: equation of alpha.
    pub equation_alpha: u32,
}

impl BlendState {
    /// `dst + src` on all channels.
    pub const ADDITIVE: BlendState = BlendState {
        src_rgb: glow::ONE,
        dst_rgb: glow::ONE,
        src_alpha: glow::ONE,
        dst_alpha: glow::ONE,
        equation_rgb: glow::FUNC_ADD,
        equation_alpha: glow::FUNC_ADD,
    };
}

/// The complete fixed-function state of one draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlState {
    /// GL_DEPTH_TEST.
    pub depth_test: bool,
    /// glDepthFunc.
    pub depth_func: u32,
    /// glDepthMask.
    pub depth_write: bool,
    /// GL_DEPTH_CLAMP: no near/far clipping, depths clamped to the depth range instead.
    pub depth_clamp: bool,
    /// GL_STENCIL_TEST.
    pub stencil_test: bool,
    /// Stencil function and operations of front faces.
    pub stencil_front: StencilFace,
    /// Stencil function and operations of back faces.
    pub stencil_back: StencilFace,
    /// glColorMask (R, G, B, A), all draw buffers.
    pub color_write: [bool; 4],
    /// `Some(face)` enables GL_CULL_FACE with glCullFace(face).
    pub cull_face: Option<u32>,
    /// glFrontFace (CCW or CW).
    pub front_face: u32,
    /// `Some(blend)` enables GL_BLEND with that function and equation.
    pub blend: Option<BlendState>,
    /// `Some((factor, units))` enables POLYGON_OFFSET_FILL.
    pub polygon_offset: Option<(f32, f32)>,
}

impl Default for GlState {
    /// GL's initial state.
    fn default() -> Self {
        Self {
            depth_test: false,
            depth_func: glow::LESS,
            depth_write: true,
            depth_clamp: false,
            stencil_test: false,
            stencil_front: StencilFace { write_mask: !0, ..StencilFace::KEEP },
            stencil_back: StencilFace { write_mask: !0, ..StencilFace::KEEP },
            color_write: [true; 4],
            cull_face: None,
            front_face: glow::CCW,
            blend: None,
            polygon_offset: None,
        }
    }
}

fn set_enabled(gl: &glow::Context, cap: u32, on: bool) {
    // SAFETY: glEnable/glDisable with a valid capability on the current context.
    unsafe {
        if on {
            gl.enable(cap)
        } else {
            gl.disable(cap)
        }
    }
}

impl GlState {
    /// Sets every field on the current context.
    pub fn apply(&self, gl: &glow::Context) {
        set_enabled(gl, glow::DEPTH_TEST, self.depth_test);
        set_enabled(gl, glow::DEPTH_CLAMP, self.depth_clamp);
        set_enabled(gl, glow::STENCIL_TEST, self.stencil_test);
        set_enabled(gl, glow::CULL_FACE, self.cull_face.is_some());
        set_enabled(gl, glow::BLEND, self.blend.is_some());
        set_enabled(gl, glow::POLYGON_OFFSET_FILL, self.polygon_offset.is_some());
        // SAFETY: plain state setters with enums taken from this struct on the current context.
        unsafe {
            gl.depth_func(self.depth_func);
            gl.depth_mask(self.depth_write);
            for (face, s) in [(glow::FRONT, &self.stencil_front), (glow::BACK, &self.stencil_back)] {
                gl.stencil_func_separate(face, s.func, s.reference, s.value_mask);
                gl.stencil_mask_separate(face, s.write_mask);
                gl.stencil_op_separate(face, s.stencil_fail, s.depth_fail, s.depth_pass);
            }
            let [r, g, b, a] = self.color_write;
            gl.color_mask(r, g, b, a);
            if let Some(face) = self.cull_face {
                gl.cull_face(face);
            }
            gl.front_face(self.front_face);
            if let Some(bl) = self.blend {
                gl.blend_func_separate(bl.src_rgb, bl.dst_rgb, bl.src_alpha, bl.dst_alpha);
                gl.blend_equation_separate(bl.equation_rgb, bl.equation_alpha);
            }
            if let Some((factor, units)) = self.polygon_offset {
                gl.polygon_offset(factor, units);
            }
        }
    }

    /// Reads the current values of every field (draw buffer 0 for colour mask and blend).
    /// `capture` followed later by `apply` restores what a caller had.
    ///
    /// GL clamps the queried stencil reference to the stencil bits of the current DRAW
    /// framebuffer: capture with the framebuffer the state is meant for bound.
    ///
    /// Fields whose enable flag is off are still read (`cull_face`, `blend`,
    /// `polygon_offset` become `None` then, and their parameters are not restored).
    pub fn capture(gl: &glow::Context) -> GlState {
        // SAFETY: glGet*/glIsEnabled queries of core state on the current context.
        unsafe {
            let u = |pname: u32| gl.get_parameter_i32(pname) as u32;
            let face = |p: [u32; 7]| StencilFace {
                func: u(p[0]),
                reference: gl.get_parameter_i32(p[1]),
                value_mask: u(p[2]),
                write_mask: u(p[3]),
                stencil_fail: u(p[4]),
                depth_fail: u(p[5]),
                depth_pass: u(p[6]),
            };
            let mask = gl.get_parameter_bool_array::<4>(glow::COLOR_WRITEMASK);
            GlState {
                depth_test: gl.is_enabled(glow::DEPTH_TEST),
                depth_func: u(glow::DEPTH_FUNC),
                depth_write: gl.get_parameter_bool(glow::DEPTH_WRITEMASK),
                depth_clamp: gl.is_enabled(glow::DEPTH_CLAMP),
                stencil_test: gl.is_enabled(glow::STENCIL_TEST),
                stencil_front: face([
                    glow::STENCIL_FUNC,
                    glow::STENCIL_REF,
                    glow::STENCIL_VALUE_MASK,
                    glow::STENCIL_WRITEMASK,
                    glow::STENCIL_FAIL,
                    glow::STENCIL_PASS_DEPTH_FAIL,
                    glow::STENCIL_PASS_DEPTH_PASS,
                ]),
                stencil_back: face([
                    glow::STENCIL_BACK_FUNC,
                    glow::STENCIL_BACK_REF,
                    glow::STENCIL_BACK_VALUE_MASK,
                    glow::STENCIL_BACK_WRITEMASK,
                    glow::STENCIL_BACK_FAIL,
                    glow::STENCIL_BACK_PASS_DEPTH_FAIL,
                    glow::STENCIL_BACK_PASS_DEPTH_PASS,
                ]),
                color_write: mask,
                cull_face: gl.is_enabled(glow::CULL_FACE).then(|| u(glow::CULL_FACE_MODE)),
                front_face: u(glow::FRONT_FACE),
                blend: gl.is_enabled(glow::BLEND).then(|| BlendState {
                    src_rgb: u(glow::BLEND_SRC_RGB),
                    dst_rgb: u(glow::BLEND_DST_RGB),
                    src_alpha: u(glow::BLEND_SRC_ALPHA),
                    dst_alpha: u(glow::BLEND_DST_ALPHA),
                    equation_rgb: u(glow::BLEND_EQUATION_RGB),
                    equation_alpha: u(glow::BLEND_EQUATION_ALPHA),
                }),
                polygon_offset: gl.is_enabled(glow::POLYGON_OFFSET_FILL).then(|| {
                    (
                        gl.get_parameter_f32(glow::POLYGON_OFFSET_FACTOR),
                        gl.get_parameter_f32(glow::POLYGON_OFFSET_UNITS),
                    )
                }),
            }
        }
    }

    /// The standard counting stencil state for shadow volumes (Heidmann 1991 z-pass,
    /// Everitt & Kilgard 2002 z-fail), two-sided in one pass with glStencilOpSeparate, in the
    /// [`DepthConvention::Standard`] depth convention. Same as
    /// `shadow_volume_for(zpass, DepthConvention::Standard)`.
    pub fn shadow_volume(zpass: bool) -> GlState {
        Self::shadow_volume_for(zpass, DepthConvention::Standard)
    }

    /// The counting stencil state for shadow volumes in `convention`; the only
    /// convention-dependent field is `depth_func` ("strictly nearer than the stored depth").
    /// Per-field reasons are written next to each choice.
    pub fn shadow_volume_for(zpass: bool, convention: DepthConvention) -> GlState {
        let counting = |depth_fail: u32, depth_pass: u32| StencilFace {
            // Reason: every volume fragment must reach the stencil op; the count is all we want.
            func: glow::ALWAYS,
            reference: 0,
            value_mask: !0,
            // Reason: all 8 bits count; INCR_WRAP/DECR_WRAP make the count exact modulo 256.
            write_mask: 0xFF,
            // Reason: the stencil test always passes, so this op never runs.
            stencil_fail: glow::KEEP,
            depth_fail,
            depth_pass,
        };
        let (front, back) = if zpass {
            // z-pass: count the volume faces IN FRONT of the visible sample: entering a
            // volume (front face) +1, leaving it (back face) -1. Wrong when the camera is
            // inside a volume (the entry face lies behind the eye).
            (counting(glow::KEEP, glow::INCR_WRAP), counting(glow::KEEP, glow::DECR_WRAP))
        } else {
            // z-fail: count the faces BEHIND the visible sample: a back face behind it means the
            // ray leaves a volume it was inside of (+1), a front face behind it means it enters
            // one after the sample (-1). Correct wherever the camera is, given closed volumes.
            (counting(glow::DECR_WRAP, glow::KEEP), counting(glow::INCR_WRAP, glow::KEEP))
        };
        GlState {
            // Reason: "behind / in front of the visible sample" is exactly the depth test result.
            depth_test: true,
            // Reason: STRICTLY nearer passes (LESS for Standard, GREATER for ReversedZ), not
            // LEQUAL / GEQUAL: a light cap pushed to the far plane (clip z = far_clip_z * w,
            // depth 1 resp. exactly 0) must FAIL at every sample, background included (depth
            // cleared to that same far value: 1 < 1 and 0 > 0 are both false), so z-fail counts
            // it consistently everywhere (see cpu-silhouette's caps). With GEQUAL a reversed-Z
            // cap would pass on the background and fail on geometry.
            depth_func: convention.nearer(),
            // Reason: the volumes are invisible; the scene's depth must stay intact for the
            // lighting pass (depth func EQUAL).
            depth_write: false,
            // Reason: nothing of a volume may be clipped by the near or far plane, or the
            // count misses faces. Far: sides and dark caps have w = 0 vertices that land
            // exactly on the far plane with the infinite projection (depth 1, resp. 0 under
            // ReversedZ); rounding could put them a hair beyond it. Near: parts in front of the
            // near plane are clamped to the near depth and still counted (they pass the depth
            // test, as they should).
            depth_clamp: true,
            stencil_test: true,
            stencil_front: front,
            stencil_back: back,
            // Reason: the volume pass only counts; colour is untouched.
            color_write: [false; 4],
            // Reason: both faces are counted with different ops in ONE pass (two-sided stencil);
            // culling would drop half of them.
            cull_face: None,
            // Reason: VolumeGeometry triangles are CCW seen from outside the volume, so the
            // outward side is the GL front face.
            front_face: glow::CCW,
            // Reason: no colour is written, blending is irrelevant; off for clarity.
            blend: None,
            // Reason: an offset would move volume faces relative to the scene depth and break
            // exactness; the self-shadowing fight is solved by pushing light caps to the far
            // plane.
            polygon_offset: None,
        }
    }
}

/// The depth function that passes exactly where `nearer` fails (LESS -> GEQUAL,
/// GREATER -> LEQUAL, and so on): a stencil op's "depth fail" as a depth test that passes.
pub fn depth_func_complement(nearer: u32) -> u32 {
    match nearer {
        glow::LESS => glow::GEQUAL,
        glow::GEQUAL => glow::LESS,
        glow::GREATER => glow::LEQUAL,
        glow::LEQUAL => glow::GREATER,
        glow::EQUAL => glow::NOTEQUAL,
        glow::NOTEQUAL => glow::EQUAL,
        glow::ALWAYS => glow::NEVER,
        _ => glow::ALWAYS,
    }
}

impl GlState {
    /// The state of a pass that re-draws the scene to record each pixel's visible sample into
    /// a buffer (the hier methods' samples pass, ray-bvh's): only the fragments whose depth
    /// equals the depth pass's run, and nothing of the frame is written.
    pub fn visible_samples(receivers: Receivers) -> GlState {
        GlState {
            // Reason: exactly the visible surface of each pixel: the renderer's invariant
            // vertex shader gives the depth pass's depths bit for bit, EQUAL selects them
            // (either depth convention), and early_fragment_tests applies the test before
            // the shader's buffer write.
            depth_test: true,
            depth_func: glow::EQUAL,
            // Reason: the frame's depth is final; nothing but the samples buffer is written.
            depth_write: false,
            // Reason: the same clipping as the depth pass, or depths could differ.
            depth_clamp: false,
            stencil_test: false,
            stencil_front: StencilFace::KEEP,
            stencil_back: StencilFace::KEEP,
            // Reason: no colour output (the frame's colour stays untouched).
            color_write: [false; 4],
            // Reason: the faces the depth pass showed, culled as it culled them
            // ([`GlState::receivers_cull`]): a culled triangle coplanar with the visible one
            // would pass EQUAL too.
            cull_face: GlState::receivers_cull(receivers),
            front_face: glow::CCW,
            blend: None,
            polygon_offset: None,
        }
    }

    /// The face culling of every pass that draws the scene's surfaces (the depth pass, and the
    /// passes that re-draw them with depth EQUAL): `None` for [`Receivers::Both`] (triangle
    /// soups are two-sided: every triangle is visible from both sides), `Some(GL_BACK)` for
    /// [`Receivers::Front`] (a pixel shows the nearest triangle facing the eye, counter-clockwise
    /// with `glFrontFace(GL_CCW)`, as three.js culls a `FrontSide` material). Never for volumes:
    /// casters cast from both faces.
    pub fn receivers_cull(receivers: Receivers) -> Option<u32> {
        match receivers {
            Receivers::Both => None,
            Receivers::Front => Some(glow::BACK),
        }
    }
}

impl GlState {
    /// The state of a full-screen resolve into the stencil ([`crate::counter`]'s resolve and the
    /// hier methods'): every fragment that survives the resolve shader's discard (a shadowed
    /// sample) writes 1, nothing else is written.
    pub fn stencil_mark_resolve() -> GlState {
        let mark = StencilFace {
            // Reason: every surviving fragment writes; the shader's discard is the decision.
            func: glow::ALWAYS,
            reference: 1,
            value_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: glow::KEEP,
            depth_fail: glow::KEEP,
            // Reason: "shadowed" = stencil not 0, what the StencilZero lighting test reads.
            depth_pass: glow::REPLACE,
        };
        GlState {
            // Reason: a full-screen pass over every pixel, the decision already made per
            // sample; a depth test would drop some.
            depth_test: false,
            depth_func: glow::ALWAYS,
            // Reason: the frame's depth is final.
            depth_write: false,
            // Reason: the triangle's z = 0 lies inside the clip volume; nothing to clamp.
            depth_clamp: false,
            // Reason: the stencil is what the resolve writes.
            stencil_test: true,
            stencil_front: mark,
            stencil_back: mark,
            // Reason: only the stencil changes; the colour is the lighting pass's.
            color_write: [false; 4],
            // Reason: the full-screen triangle must cover every pixel whatever its winding.
            cull_face: None,
            front_face: glow::CCW,
            // Reason: no colour is written.
            blend: None,
            // Reason: no depth test, an offset would change nothing.
            polygon_offset: None,
        }
    }
}

impl GlState {
    /// The counting state of the wide (Float32) counter ([`crate::counter`]): the same count
    /// as [`GlState::shadow_volume_for`], accumulated by additive blending of the volume
    /// fragment shaders' `o_count` (+1 front face, -1 back face) into an R32F colour buffer
    /// instead of INCR_WRAP / DECR_WRAP into 8 stencil bits. Exact for |count| < 2^24.
    /// Per-field reasons are written next to each choice.
    pub fn shadow_volume_float_for(zpass: bool, convention: DepthConvention) -> GlState {
        let stencil = Self::shadow_volume_for(zpass, convention);
        GlState {
            // Reason: the stencil ops ran on "depth pass" (z-pass) or "depth fail" (z-fail); a
            // blend only runs where the depth test passes, so z-fail tests the complement.
            depth_test: true,
            // Reason: z-pass counts faces strictly nearer than the sample (the convention's
            // nearer: LESS / GREATER), z-fail the others (GEQUAL / LEQUAL). A light cap pushed
            // to the far plane (depth 1, resp. 0) fails LESS everywhere, background included,
            // so z-fail counted it everywhere; with the complement GEQUAL (1 >= anything, resp.
            // 0 <= anything) it passes everywhere: the same, consistent, count.
            depth_func: if zpass { convention.nearer() } else { depth_func_complement(convention.nearer()) },
            // Reason: the volumes are invisible; the copied scene depth stays intact.
            depth_write: false,
            // Reason: the stencil test is not used: the blend does the counting, every
            // fragment counts (the counter's framebuffer may have no stencil at all).
            stencil_test: false,
            stencil_front: StencilFace::KEEP,
            stencil_back: StencilFace::KEEP,
            // Reason: the count lives in the red channel of the R32F buffer only.
            color_write: [true, false, false, false],
            // Reason: dst + src (z-pass: front +1, back -1) or dst - src (z-fail, reverse
            // subtract: back +1, front -1), factors ONE: an exact integer sum in f32.
            blend: Some(BlendState {
                equation_rgb: if zpass { glow::FUNC_ADD } else { glow::FUNC_REVERSE_SUBTRACT },
                equation_alpha: if zpass { glow::FUNC_ADD } else { glow::FUNC_REVERSE_SUBTRACT },
                ..BlendState::ADDITIVE
            }),
            // Reason (depth clamp on, no culling, CCW front, no polygon offset): as in the
            // stencil state, see shadow_volume_for.
            ..stencil
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shadow_volume_depth_func_follows_the_convention() {
        for zpass in [false, true] {
            let standard = GlState::shadow_volume(zpass);
            assert_eq!(standard, GlState::shadow_volume_for(zpass, DepthConvention::Standard));
            assert_eq!(standard.depth_func, glow::LESS);
            let reversed = GlState::shadow_volume_for(zpass, DepthConvention::ReversedZ);
            assert_eq!(reversed.depth_func, glow::GREATER);
            // Nothing else differs.
            assert_eq!(GlState { depth_func: glow::LESS, ..reversed }, standard);
        }
    }

    #[test]
    fn float_count_state_tests_where_the_stencil_op_ran() {
        use glow::{FUNC_ADD, FUNC_REVERSE_SUBTRACT, GEQUAL, GREATER, LEQUAL, LESS};
        for (zpass, convention, func, equation) in [
            (true, DepthConvention::Standard, LESS, FUNC_ADD),
            (true, DepthConvention::ReversedZ, GREATER, FUNC_ADD),
            (false, DepthConvention::Standard, GEQUAL, FUNC_REVERSE_SUBTRACT),
            (false, DepthConvention::ReversedZ, LEQUAL, FUNC_REVERSE_SUBTRACT),
        ] {
            let f = GlState::shadow_volume_float_for(zpass, convention);
            let s = GlState::shadow_volume_for(zpass, convention);
            assert_eq!(f.depth_func, func, "zpass {zpass} {convention:?}");
            let blend = f.blend.expect("blending counts");
            assert_eq!((blend.equation_rgb, blend.src_rgb, blend.dst_rgb), (equation, glow::ONE, glow::ONE));
            assert!(!f.stencil_test && !f.depth_write && f.depth_clamp && f.depth_test);
            assert_eq!(f.color_write, [true, false, false, false]);
            assert_eq!((f.cull_face, f.front_face, f.polygon_offset), (s.cull_face, s.front_face, s.polygon_offset));
        }
        for func in [glow::LESS, glow::LEQUAL, glow::GREATER, glow::GEQUAL, glow::EQUAL, glow::NOTEQUAL] {
            assert_eq!(depth_func_complement(depth_func_complement(func)), func);
        }
    }
}
