//! The precision envelope of a rasterized sample, and the band it defines.
//!
//! A stencil shadow method decides a sample by rasterizing shadow-volume faces and
//! depth-testing them against the sample's depth; the lighting pass decides its facing. In
//! exact arithmetic that decision is the reference's (the count of volumes containing the
//! sample). The machinery is not exact, and this module bounds by how much:
//!
//! * **Depth** (GL 4.5 core, Section 14.6.5, "Depth Offset"): `r`, the minimum resolvable
//!   difference, is "the smallest difference in window coordinate z values that is guaranteed
//!   to remain distinct throughout polygon rasterization and in the depth buffer": `2^-n` for
//!   an n-bit fixed-point buffer, `2^(e - 23)` for a floating-point one, `e` the exponent of
//!   the primitive's largest `|z|`. A volume face may reach depth 1 (the near plane of
//!   reversed-Z, where depth clamp puts what lies in front of it; the far plane of the
//!   standard convention), so for faces `r = 2^-23` with a float buffer, `2^-24` with
//!   DEPTH24. Two primitives are compared at a sample (the face and the sample's own
//!   triangle), each within `r` of its exact depth: [`DEPTH_STEPS`] = 2 steps. Converted to a
//!   distance along the view ray through the slope of window depth there
//!   ([`RasterView::depth_slope`]).
//! * **Lateral** (where on the screen a primitive lies): the rasterizer snaps vertices to
//!   `GL_SUBPIXEL_BITS` bits (GL 4.5 core, Chapter 23 state tables, minimum 4; 8 on llvmpipe, `FIXED_ORDER` in
//!   lp_rast.h; at least 4 by the spec): a vertex moves by up to `2^-(b+1)` per axis, an edge
//!   by up to `sqrt 2 * 2^-(b+1)` pixel, for the face and for the sample's triangle alike.
//!   llvmpipe then interpolates every attribute, depth included, with plane equations taken
//!   at the framebuffer's origin (lp_state_setup.c, `calc_coef4`, and its FIXME: "if some
//!   (small) tri is far away from the origin and gradients are large, this can lead to HUGE
//!   errors"): `a0 = z0 - dzdx x0 - dzdy y0`, then `z = a0 + dzdx x + dzdy y`, in f32. Every
//!   rounding there has the magnitude of `|grad z| (W + H)` (llvmpipe clips x and y at the
//!   viewport, `draw_set_driver_clipping(.., guard_band_xy = false, ..)` in lp_context.c, so
//!   no vertex lies outside it): [`PLANE_ROUNDINGS`] of them per primitive, two primitives.
//!   A depth error of `|grad z| e` is the face moved by `e` pixels across the screen, so both
//!   bounds add up to one lateral distance in pixels, [`RasterView::lateral_pixels`],
//!   converted to world units through the pixel's footprint at the sample.
//! * **Position**: the sample's world position is interpolated in f32 from f32 vertices:
//!   [`POSITION_RELATIVE`] of its distance and coordinates.
//!
//! The **envelope** of a sample `S` is the ball around `S` of radius `R` = position plus
//! lateral plus depth (world units). The depth test of a face against `S`, at the pixel, can go either
//! way exactly when the face passes within the envelope: a plane at perpendicular distance
//! `h` from `S`, with unit normal `n`, is met by the view ray `v` at distance `h / |n.v|`, and
//! the machinery moves that hit by at most `depth / |n.v| + lateral |n_perp| / |n.v|` along the
//! ray (`n_perp` the part of `n` across the ray), so it can cross `S` only if
//! `h <= depth |n.v| + lateral |n_perp| <= depth + lateral`. Faces seen edge-on (`n.v ~ 0`)
//! are covered by the lateral term, faces parallel to the screen by the depth term. Half of
//! the lateral bound belongs to the sample's own triangle `T`: moving `T` across the screen
//! moves `S` along `T`'s plane, by that much divided by `|cos|` of the angle `T` is seen at
//! (a wall seen at 6 degrees: ten times as far), so that half is stretched by `1 / |cos|`; a
//! `T` seen so obliquely that this exceeds a pixel is FACING band (its sample's position is
//! the rasterizer's choice). Found on Crytek Sponza (torture pose 2, 240 x 180): a sample on a
//! wall seen at a grazing angle, 0.0007 pixel from the wall's corner edge on the screen but
//! 4.7e-4 units from it along the wall, beyond the corner, in the shadow of the other wall.
//!
//! A sample is **band** when some part of its decision lies within the machinery's precision,
//! each a flag of [`BandParts`] computed per sample by the reference:
//! * [`BandParts::FACING`]: the lighting pass's facing (`n.l > 0` in f32 from the stored unit
//!   normal and the interpolated position, `gl_FrontFacing` from the snapped vertices) or the
//!   f32 orientation of the sample's own triangle towards the light (001 Alg. 4, which
//!   orients its volume) could differ from the reference's f64 plane test.
//! * [`BandParts::SIDE_FACE`]: a side face passes within the envelope. Side faces are swept
//!   from edges that cast one ([`casting_edges`]: silhouettes, or next to a triangle whose
//!   f32 orientation is uncertain); a point `X` lies on the face of edge `e` iff the segment
//!   from `X` to the light meets `e`, so the face passes within `R` of `S` only if the
//!   segment from `S` to the light passes within `R` of `e` (for a point light the segments
//!   from the ball's points converge on the light, so `R` at every `t` is conservative). Also
//!   where the face passes far from `S` but is seen edge-on: its projection passes within the
//!   lateral bound of the pixel centre and its plane within `R` of `S` (llvmpipe covers the
//!   pixel with the snapped face and gives it its plane's depth there, [`crate::edge_on`]).
//! * [`BandParts::CANCELLING`]: the same for an edge that casts nothing, where a per-triangle
//!   method draws two opposite faces that cancel exactly only if both are ordered alike.
//!   Silhouette methods draw nothing there and are judged without this part. The same
//!   edge-on faces as for [`BandParts::SIDE_FACE`] ([`crate::edge_on`]).
//! * [`BandParts::ORIENTATION`]: the segment to the light passes within the envelope of a
//!   triangle whose f32 orientation is uncertain: its volume may be the other way round.
//! * [`BandParts::SURFACE`]: another triangle, not coplanar with the sample's own, passes
//!   within the envelope (a crease, an object resting on the surface): the depth pass may
//!   have picked either, and the light caps pushed to the far plane (paper 003 Eq. 6) assume
//!   the caster hides what lies behind it. Also where the projected edge of another surface in
//!   front of the sample passes within the lateral bound of the pixel centre: its volume's
//!   snapped cap or side may cover the pixel the exact ray passes by
//!   ([`crate::nearer_contour`]).
//! * [`BandParts::REFERENCE_EPS`]: lit only because the reference's segment test skips what
//!   lies within `eps` of the sample ([`crate::segment_epsilon`]): a method has no eps.
//! * [`BandParts::NEAR_CUT`]: the pixel lies within the lateral bound of the image of a
//!   triangle's cut by the camera's near plane, where the depth pass's clip and the light
//!   cap's `gl_ClipDistance` decide which samples are seen through the cut caster.
//! * [`BandParts::SEEN_SURFACE`]: only for decisions made on another depth pass than the one
//!   that produced the samples (an external mask, [`RasterView::other_depth_pass`]): that pass
//!   may show another surface at the pixel, whose decision differs ([`crate::seen_surface`]).
//!   A native method decides the samples themselves and is judged without it.
//!
//! Which parts come from depth-testing rasterized volume faces: [`BandParts::SIDE_FACE`],
//! [`BandParts::CANCELLING`] and [`BandParts::SURFACE`]. A method that decides samples
//! without depth-testing faces (testing world positions against volume planes in a compute
//! pass) is judged with `BandParts::ALL & !BandParts::DEPTH_TESTED` plus its own part (the
//! same proximity tests with its own evaluation's margin, e.g. [`RasterView::position_margin`]
//! alone): pass that mask to [`crate::compare_masked`].

use std::collections::HashSet;

use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::frame::Receivers;
use umbra_geom::vec3::{cross, dot, norm, sub};
use umbra_geom::{Light, WeldedMesh};

/// Depth-buffer steps `r` that separate a face and a sample for sure: one for each of the two
/// primitives compared (GL 4.5 Section 14.6.5; see the module doc).
pub const DEPTH_STEPS: f64 = 2.0;
/// f32 roundings, each of magnitude `|grad z| (W + H)`, in one plane-equation evaluation of
/// llvmpipe's setup and interpolation (module doc): `a0`'s two products and two sums, the
/// evaluation's two products and two sums.
pub const PLANE_ROUNDINGS: f64 = 8.0;
/// Relative error of an interpolated f32 world position: 16 units in the last place (2^-20)
/// of its distance from the eye plus its largest coordinate (the vertices' coordinates, the
/// barycentrics and the perspective division each round a few times).
pub const POSITION_RELATIVE: f64 = 1.0 / 1_048_576.0;
/// f32 roundings in 001 Alg. 4's determinant `((C - A) x (L - A l_w)) . (B - A)` (precise,
/// no FMA): three differences, the light term, the cross product's products and difference,
/// the dot product's products and sums: each term of the final sum carries at most 8
/// relative roundings, three terms, and the inputs' own rounding. 32 bounds it with room.
pub const ORIENTATION_ROUNDINGS: f64 = 32.0;
/// Error of the lighting pass's `dot(n, l)` in f32 with unit `n` (an f64 normal rounded to
/// f32) and `l = normalize(L - p)`: a few units in the last place of 1 (2^-20), plus the
/// angle the position's own error subtends at the light (added per sample).
pub const LIGHTING_DOT: f64 = 1.0 / 1_048_576.0;
/// The smallest `GL_SUBPIXEL_BITS` GL 4.5 allows (Chapter 23 state tables): the default when the
/// rasterizer's own is not known.
pub const MIN_SUBPIXEL_BITS: u32 = 4;

/// Which parts of a sample's decision lie within the machinery's precision (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BandParts(pub u8);

impl BandParts {
    pub const NONE: BandParts = BandParts(0);
    pub const FACING: BandParts = BandParts(1);
    pub const SIDE_FACE: BandParts = BandParts(2);
    pub const CANCELLING: BandParts = BandParts(4);
    pub const ORIENTATION: BandParts = BandParts(8);
    pub const SURFACE: BandParts = BandParts(16);
    pub const REFERENCE_EPS: BandParts = BandParts(32);
    pub const NEAR_CUT: BandParts = BandParts(64);
    /// Computed only for [`RasterView::other_depth_pass`] (module doc).
    pub const SEEN_SURFACE: BandParts = BandParts(128);
    /// Every part.
    pub const ALL: BandParts = BandParts(255);
    /// What a method that decides the reference's own samples is judged with: every part but
    /// [`BandParts::SEEN_SURFACE`].
    pub const SAME_SAMPLES: BandParts = BandParts(127);
    /// The parts that come from depth-testing rasterized volume faces against the sample.
    pub const DEPTH_TESTED: BandParts = BandParts(2 | 4 | 16);
    /// What a silhouette method is judged with: it draws no cancelling faces (and decides the
    /// reference's own samples: no [`BandParts::SEEN_SURFACE`]).
    pub const SILHOUETTE: BandParts = BandParts(127 & !4);

    /// Whether any part of `mask` is set.
    pub fn intersects(self, mask: BandParts) -> bool {
        self.0 & mask.0 != 0
    }

    /// Whether every part of `other` is set.
    pub fn contains(self, other: BandParts) -> bool {
        self.0 & other.0 == other.0
    }

    /// The parts' names, for diagnosis.
    pub fn names(self) -> Vec<&'static str> {
        const NAMES: [&str; 8] = [
            "facing",
            "side-face",
            "cancelling",
            "orientation",
            "surface",
            "reference-eps",
            "near-cut",
            "seen-surface",
        ];
        (0..8).filter(|k| self.0 & (1 << k) != 0).map(|k| NAMES[k]).collect()
    }
}

impl std::ops::BitOr for BandParts {
    type Output = BandParts;
    fn bitor(self, o: BandParts) -> BandParts {
        BandParts(self.0 | o.0)
    }
}

impl std::ops::BitOrAssign for BandParts {
    fn bitor_assign(&mut self, o: BandParts) {
        self.0 |= o.0;
    }
}

impl std::ops::BitAnd for BandParts {
    type Output = BandParts;
    fn bitand(self, o: BandParts) -> BandParts {
        BandParts(self.0 & o.0)
    }
}

impl std::ops::Not for BandParts {
    type Output = BandParts;
    fn not(self) -> BandParts {
        BandParts(!self.0 & BandParts::ALL.0)
    }
}

/// The depth buffer the samples and the volumes were depth-tested in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthFormat {
    /// Fixed point with this many bits (DEPTH24_STENCIL8: 24).
    Fixed(u32),
    /// 32-bit float (DEPTH32F_STENCIL8).
    Float32,
}

/// The view the samples were rasterized with, and what is known of the rasterizer's
/// precision ([`RasterView::new`] assumes the least the GL spec allows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterView {
    /// Clip space from world space, column-major (OpenGL's convention), in the depth
    /// convention the samples were rendered with: the standard one (window depth
    /// `(z/w + 1) / 2`) or reversed-Z with glClipControl ZERO_TO_ONE (window depth `z/w`,
    /// recognised by a depth row without x, y and z terms).
    pub clip_from_world: [f64; 16],
    /// `GL_SUBPIXEL_BITS` of the rasterizer.
    pub subpixel_bits: u32,
    /// The depth buffer.
    pub depth: DepthFormat,
    /// Whether the judged decisions were made on another depth pass than the one that
    /// produced the samples, with this precision (an external mask drawn by another renderer):
    /// then the band has [`BandParts::SEEN_SURFACE`] ([`crate::seen_surface`]).
    pub other_depth_pass: bool,
    /// Which faces the depth passes can show ([`Receivers`]): with [`Receivers::Front`] both
    /// the samples' pass and another depth pass cull back faces, so a triangle that faces away
    /// from the eye beyond the rasterizer's precision is never the surface a pixel shows
    /// ([`crate::seen_surface`]).
    pub receivers: Receivers,
    /// The unit view direction when the view is orthographic (`clip_from_world`'s last row
    /// is (0, 0, 0, 1): parallel rays, the eye at infinity behind the camera), `None` for a
    /// perspective view. The pixel's ray through a sample `s` then runs along it, and the
    /// depth convention is told by whether clip z falls along it (reversed-Z).
    pub orthographic_forward: Option<[f64; 3]>,
}

/// `2^(e - 23)` for the exponent `e` of `z` (the f32 spacing just above `|z|`, i.e. GL's `r`
/// for a floating-point depth buffer), `2^-149` at least.
fn float_step(z: f64) -> f64 {
    let z = (z.abs() as f32).max(f32::MIN_POSITIVE);
    let exponent_bits = z.to_bits() & 0x7f80_0000;
    f64::from(f32::from_bits(exponent_bits)) * f64::from(f32::EPSILON)
}

impl RasterView {
    /// A view with the least precision GL 4.5 allows: 4 subpixel bits, a float depth buffer
    /// (whose `r` for faces reaching depth 1 is the larger).
    pub fn new(clip_from_world: [f64; 16]) -> RasterView {
        RasterView {
            clip_from_world,
            subpixel_bits: MIN_SUBPIXEL_BITS,
            depth: DepthFormat::Float32,
            other_depth_pass: false,
            receivers: Receivers::Both,
            orthographic_forward: None,
        }
    }

    fn row(&self, r: usize, p: [f64; 3], w: f64) -> f64 {
        let m = &self.clip_from_world;
        m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * w
    }

    /// Homogeneous 2D clip coordinates `(x, y, w)` of a world point.
    pub(crate) fn clip(&self, p: [f64; 3]) -> [f64; 3] {
        [self.row(0, p, 1.0), self.row(1, p, 1.0), self.row(3, p, 1.0)]
    }

    /// Whether the depth is reversed-Z (window depth `z/w`) rather than standard.
    pub(crate) fn reversed(&self) -> bool {
        if let Some(f) = self.orthographic_forward {
            // Orthographic: reversed-Z depth falls with distance, the standard one grows.
            return self.row(2, f, 0.0) < 0.0;
        }
        let m = &self.clip_from_world;
        m[2] == 0.0 && m[6] == 0.0 && m[10] == 0.0
    }

    /// Window depth of a world point in front of the eye (`None` behind it).
    // `!(w > 0.0)` is meant: NaN gives no depth the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn window_depth(&self, p: [f64; 3]) -> Option<f64> {
        let (z, w) = (self.row(2, p, 1.0), self.row(3, p, 1.0));
        if !(w > 0.0) {
            return None;
        }
        Some(if self.reversed() { z / w } else { 0.5 * (z / w + 1.0) })
    }

    /// The depth buffer's `r` for a primitive whose largest window depth is `max_depth`
    /// (GL 4.5 Section 14.6.5).
    pub fn depth_step(&self, max_depth: f64) -> f64 {
        match self.depth {
            DepthFormat::Fixed(bits) => 2f64.powi(-(bits as i32)),
            DepthFormat::Float32 => float_step(max_depth),
        }
    }

    /// `r` for a volume face: it may reach depth 1 (module doc).
    pub fn face_depth_step(&self) -> f64 {
        self.depth_step(1.0)
    }

    /// `r` for a scene triangle: from its largest window depth, or a face's when a vertex
    /// lies behind the eye (then the near plane cuts it, at depth 0 or 1).
    pub fn triangle_depth_step(&self, tri: [[f64; 3]; 3]) -> f64 {
        let mut max_depth = 0f64;
        for p in tri {
            match self.window_depth(p) {
                Some(z) => max_depth = max_depth.max(z.abs()),
                None => return self.face_depth_step(),
            }
        }
        self.depth_step(max_depth)
    }

    /// Window depth per world unit along the view ray through `s` seen from `eye` (`0` when
    /// the depth does not change there, or `s` is behind the eye).
    // `!(x > 0.0)` is meant: it is also true for NaN, which must give no slope the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn depth_slope(&self, s: [f64; 3], eye: [f64; 3]) -> f64 {
        let scale = if self.reversed() { 1.0 } else { 0.5 };
        let d = sub(s, eye);
        let len = dot(d, d).sqrt();
        if !(len > 0.0) {
            return 0.0;
        }
        let v = d.map(|c| c / len);
        let (z, w) = (self.row(2, s, 1.0), self.row(3, s, 1.0));
        let (dz, dw) = (self.row(2, v, 0.0), self.row(3, v, 0.0));
        if !(w > 0.0) {
            return 0.0;
        }
        // d(z/w)/dt along the unit view direction, then to window depth.
        let slope = scale * ((dz * w - z * dw) / (w * w)).abs();
        if slope.is_finite() {
            slope
        } else {
            0.0
        }
    }

    /// The world distance along the view ray at `s` that [`DEPTH_STEPS`] steps `r` of window
    /// depth span (`0` where the depth does not change along the ray).
    pub fn depth_margin_for(&self, s: [f64; 3], eye: [f64; 3], r: f64) -> f64 {
        let slope = self.depth_slope(s, eye);
        if slope > 0.0 {
            DEPTH_STEPS * r / slope
        } else {
            0.0
        }
    }

    /// [`RasterView::depth_margin_for`] a volume face.
    pub fn depth_margin(&self, s: [f64; 3], eye: [f64; 3]) -> f64 {
        self.depth_margin_for(s, eye, self.face_depth_step())
    }

    /// How far one vertex moves when snapped: `sqrt 2 * 2^-(b+1)` pixel.
    pub fn snap_pixels(&self) -> f64 {
        std::f64::consts::SQRT_2 * 2f64.powi(-(self.subpixel_bits as i32 + 1))
    }

    /// The lateral bound, in pixels, of a `width x height` image (module doc): the snapping
    /// of the face's and of the sample's triangle's vertices, and [`PLANE_ROUNDINGS`] f32
    /// roundings of `|grad z| (W + H)` in each one's plane equations.
    pub fn lateral_pixels(&self, width: u32, height: u32) -> f64 {
        2.0 * self.snap_pixels() + 2.0 * PLANE_ROUNDINGS * f64::from(f32::EPSILON) / 2.0 * f64::from(width + height)
    }

    /// World size of one pixel at `s` (the larger of its width and height; `0` behind the eye).
    // `!(w > 0.0)` is meant: NaN gives no footprint the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn footprint(&self, s: [f64; 3], width: u32, height: u32) -> f64 {
        let m = &self.clip_from_world;
        let w = self.row(3, s, 1.0);
        if !(w > 0.0) {
            return 0.0;
        }
        // |row 0| and |row 1| (their xyz parts): clip units per world unit across the screen.
        let fx = (m[0] * m[0] + m[4] * m[4] + m[8] * m[8]).sqrt();
        let fy = (m[1] * m[1] + m[5] * m[5] + m[9] * m[9]).sqrt();
        let px = if fx > 0.0 { 2.0 * w / (f64::from(width) * fx) } else { 0.0 };
        let py = if fy > 0.0 { 2.0 * w / (f64::from(height) * fy) } else { 0.0 };
        px.max(py)
    }

    /// [`POSITION_RELATIVE`] of the sample's distance from the eye and its largest coordinate.
    pub fn position_margin(s: [f64; 3], eye: [f64; 3]) -> f64 {
        POSITION_RELATIVE * (norm(sub(s, eye)) + s.iter().fold(0f64, |m, c| m.max(c.abs())))
    }

    /// Distance in pixels from the centre of pixel `(x, y)` (top row first) of a `width` x
    /// `height` image to the nearest line of the triangle's three edges, in homogeneous 2D
    /// clip coordinates (right for vertices behind the eye too: the line through two
    /// homogeneous points is their cross product). `None` when every line is degenerate.
    pub fn edge_distance_px(&self, tri: [[f64; 3]; 3], x: u32, y: u32, width: u32, height: u32) -> Option<f64> {
        let (w, h) = (width as f64, height as f64);
        let p = [(x as f64 + 0.5) / w * 2.0 - 1.0, 1.0 - (y as f64 + 0.5) / h * 2.0, 1.0];
        let v = tri.map(|q| self.clip(q));
        let mut best: Option<f64> = None;
        for k in 0..3 {
            let l = cross(v[k], v[(k + 1) % 3]);
            let g = (2.0 * l[0] / w).hypot(2.0 * l[1] / h);
            if g > 0.0 && g.is_finite() {
                let d = dot(l, p).abs() / g;
                best = Some(best.map_or(d, |b: f64| b.min(d)));
            }
        }
        best
    }

    /// Window coordinates in pixels (x right, y down) of a world point in front of the eye.
    // `!(w > 0.0)` is meant: NaN gives no position the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub(crate) fn window_xy(&self, p: [f64; 3], width: u32, height: u32) -> Option<[f64; 2]> {
        let [x, y, w] = self.clip(p);
        if !(w > 0.0) {
            return None;
        }
        Some([(x / w + 1.0) * 0.5 * f64::from(width), (1.0 - y / w) * 0.5 * f64::from(height)])
    }

    /// Whether the rasterizer's `gl_FrontFacing` for the triangle could differ from the exact
    /// side the eye sees: its snapped screen area could change sign (each vertex moves by up
    /// to [`RasterView::snap_pixels`], which changes twice the area by at most that times
    /// twice the perimeter). Triangles cut by the near plane: `false` (their area is not small).
    pub fn facing_uncertain(&self, tri: [[f64; 3]; 3], width: u32, height: u32) -> bool {
        let Some(p) = tri.iter().map(|&q| self.window_xy(q, width, height)).collect::<Option<Vec<_>>>() else {
            return false;
        };
        let e = |i: usize, j: usize| [p[j][0] - p[i][0], p[j][1] - p[i][1]];
        let (a, b) = (e(0, 1), e(0, 2));
        let area2 = (a[0] * b[1] - a[1] * b[0]).abs();
        let perimeter = (0..3).map(|k| e(k, (k + 1) % 3)).map(|v| v[0].hypot(v[1])).sum::<f64>();
        area2 <= 2.0 * self.snap_pixels() * perimeter
    }
}

/// Whether a method's f32 orientation of triangle `tri` towards `light` (001 Alg. 4, or any
/// evaluation of the same determinant with as many roundings) could differ from the exact
/// one: `|det| <=` [`ORIENTATION_ROUNDINGS`] `* 2^-24 * |B - A| |C - A| |L - A l_w|`,
/// bounded over every vertex order by the two longest edges and the farthest vertex from
/// the light. A zero-area triangle always is.
pub fn orientation_uncertain(tri: [[f64; 3]; 3], light: Light) -> bool {
    let [a, b, c] = tri;
    let l = light.map(f64::from);
    let towards = |p: [f64; 3]| [l[0] - p[0] * l[3], l[1] - p[1] * l[3], l[2] - p[2] * l[3]];
    let n = cross(sub(b, a), sub(c, a));
    let det = dot(n, towards(a));
    let mut edges = [norm(sub(b, a)), norm(sub(c, b)), norm(sub(a, c))];
    edges.sort_by(|x, y| y.total_cmp(x));
    let light_len = tri.iter().map(|&p| norm(towards(p))).fold(0f64, f64::max);
    let bound = ORIENTATION_ROUNDINGS * f64::from(f32::EPSILON) / 2.0 * edges[0] * edges[1] * light_len;
    // `!(x > y)` is meant: NaN is uncertain too.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let uncertain = !(det.abs() > bound);
    uncertain
}

/// Per light: which triangles' f32 orientation is uncertain ([`orientation_uncertain`]) and
/// which edges cast a side face in some exact method (vertex pairs, smaller index first): a
/// nonzero sum of the opposite vertices' sides of the plane through the light and the edge
/// (001 Alg. 3, in f64), a zero term, or an adjacent triangle of uncertain orientation.
pub struct Casting {
    pub uncertain: Vec<bool>,
    pub edges: HashSet<[u32; 2]>,
}

/// [`Casting`] of `mesh` for `light`.
pub fn casting_edges(mesh: &WeldedMesh, light: Light) -> Casting {
    use rayon::prelude::*;
    let pos = |k: u32| mesh.positions[k as usize].map(f64::from);
    let uncertain: Vec<bool> = mesh.triangles.par_iter().map(|t| orientation_uncertain(t.map(pos), light)).collect();
    // Vertex pairs of the triangles of uncertain orientation: every edge they touch casts.
    let shaky: HashSet<[u32; 2]> = mesh
        .triangles
        .iter()
        .zip(&uncertain)
        .filter(|(_, &u)| u)
        .flat_map(|(t, _)| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    let adjacency = EdgeAdjacency::build(mesh);
    let edges = (0..adjacency.len())
        .into_par_iter()
        .filter_map(|e| {
            let [a, b] = adjacency.edges[e];
            let key = [a.min(b), a.max(b)];
            (shaky.contains(&key) || casts_side(mesh, &adjacency, e, light)).then_some(key)
        })
        .collect();
    Casting { uncertain, edges }
}

/// Whether edge `e` of `adjacency` casts a side face for `light`: a nonzero sum of its
/// opposite vertices' sides of the plane (light, a, b) (001 Alg. 3, here in f64), or a zero
/// term (undecided). The per-triangle methods draw faces on every edge, but on an edge that
/// casts nothing two opposite faces cancel ([`BandParts::CANCELLING`]).
pub fn casts_side(mesh: &WeldedMesh, adjacency: &EdgeAdjacency, e: usize, light: Light) -> bool {
    let pos = |k: u32| mesh.positions[k as usize].map(f64::from);
    let [ia, ib] = adjacency.edges[e];
    let (a, b) = (pos(ia), pos(ib));
    let towards = if light[3] != 0.0 {
        sub([0, 1, 2].map(|k| f64::from(light[k]) / f64::from(light[3])), a)
    } else {
        [0, 1, 2].map(|k| f64::from(light[k]))
    };
    let edge_normal = cross(sub(b, a), towards);
    let (mut m, mut undecided) = (0i64, false);
    for &o in adjacency.opposites(e) {
        let side = dot(edge_normal, sub(pos(o), a));
        undecided |= side == 0.0;
        m += if side > 0.0 {
            1
        } else if side < 0.0 {
            -1
        } else {
            0
        };
    }
    m != 0 || undecided
}

/// Distance between the segments `p0 p1` and `q0 q1` (Ericson, Real-Time Collision Detection,
/// Section 5.1.9), in f64.
pub fn segment_segment_distance(p0: [f64; 3], p1: [f64; 3], q0: [f64; 3], q1: [f64; 3]) -> f64 {
    let d1 = sub(p1, p0);
    let d2 = sub(q1, q0);
    let r = sub(p0, q0);
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let (s, t) = if a <= 0.0 && e <= 0.0 {
        (0.0, 0.0)
    } else if a <= 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = dot(d1, r);
        if e <= 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = dot(d1, d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    let cp = [p0[0] + d1[0] * s, p0[1] + d1[1] * s, p0[2] + d1[2] * s];
    let cq = [q0[0] + d2[0] * t, q0[1] + d2[1] * t, q0[2] + d2[2] * t];
    norm(sub(cp, cq))
}

/// Distance from `p` to the triangle `a b c` (Ericson, Section 5.1.5), in f64. A degenerate
/// triangle: the distance to its edges.
pub fn point_triangle_distance(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let n = cross(ab, ac);
    let nn = dot(n, n);
    if nn > 0.0 {
        // Barycentrics of p's projection on the plane.
        let v = dot(cross(ap, ac), n) / nn;
        let w = dot(cross(ab, ap), n) / nn;
        if v >= 0.0 && w >= 0.0 && v + w <= 1.0 {
            return dot(ap, n).abs() / nn.sqrt();
        }
    }
    segment_segment_distance(p, p, a, b)
        .min(segment_segment_distance(p, p, b, c))
        .min(segment_segment_distance(p, p, c, a))
}

/// Distance from the segment `p0 p1` to the triangle `tri`: 0 when it crosses it, else the
/// least of its endpoints' distances to the triangle and its distances to the edges.
pub fn segment_triangle_distance(p0: [f64; 3], p1: [f64; 3], tri: [[f64; 3]; 3]) -> f64 {
    let [a, b, c] = tri;
    let n = cross(sub(b, a), sub(c, a));
    let (s0, s1) = (dot(n, sub(p0, a)), dot(n, sub(p1, a)));
    if (s0 <= 0.0 && s1 >= 0.0) || (s0 >= 0.0 && s1 <= 0.0) {
        let t = if s0 == s1 { 0.0 } else { s0 / (s0 - s1) };
        let x = [0, 1, 2].map(|k| p0[k] + t * (p1[k] - p0[k]));
        if point_triangle_distance(x, tri) == 0.0 {
            return 0.0;
        }
    }
    let edges =
        (0..3).map(|k| segment_segment_distance(p0, p1, tri[k], tri[(k + 1) % 3])).fold(f64::INFINITY, f64::min);
    edges.min(point_triangle_distance(p0, tri)).min(point_triangle_distance(p1, tri))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_step_is_the_spacing_at_the_exponent() {
        assert_eq!(float_step(1.0), f64::from(f32::EPSILON));
        assert_eq!(float_step(0.75), f64::from(f32::EPSILON) / 2.0);
        assert_eq!(float_step(1e-3), 2f64.powi(-10 - 23));
    }

    #[test]
    fn segment_distances() {
        let d = segment_segment_distance([0.0; 3], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.5, 1.0, 1.0]);
        assert!((d - 1.0).abs() < 1e-15);
        // Crossing segments.
        assert_eq!(segment_segment_distance([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0]), 0.0);
        // Parallel, offset.
        let d = segment_segment_distance([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0], [1.0, 0.0, 2.0]);
        assert!((d - 2.0).abs() < 1e-15);
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!((point_triangle_distance([0.2, 0.2, 0.5], tri) - 0.5).abs() < 1e-15);
        assert!((point_triangle_distance([2.0, 0.0, 0.0], tri) - 1.0).abs() < 1e-15);
        assert_eq!(segment_triangle_distance([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], tri), 0.0);
        assert!((segment_triangle_distance([2.0, 0.0, -1.0], [2.0, 0.0, 1.0], tri) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn orientation_uncertainty_follows_the_angle_to_the_light() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        // Light high above: certain. Light 1e-9 above the plane, 10 away: uncertain.
        assert!(!orientation_uncertain(tri, [0.3, 5.0, 0.3, 1.0]));
        assert!(orientation_uncertain(tri, [10.0, 1e-9, 0.3, 1.0]));
        // In the plane: uncertain; a directional light along the plane too.
        assert!(orientation_uncertain(tri, [10.0, 0.0, 0.3, 1.0]));
        assert!(orientation_uncertain(tri, [1.0, 0.0, 0.0, 0.0]));
        assert!(!orientation_uncertain(tri, [1.0, 1.0, 0.0, 0.0]));
        // Zero area.
        assert!(orientation_uncertain([[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [0.0, 5.0, 0.0, 1.0]));
    }

    #[test]
    fn band_parts_combine() {
        let p = BandParts::SIDE_FACE | BandParts::FACING;
        assert!(p.intersects(BandParts::DEPTH_TESTED));
        assert!(!(p & !BandParts::DEPTH_TESTED).contains(BandParts::SIDE_FACE));
        assert!(p.contains(BandParts::FACING));
        assert_eq!(p.names(), vec!["facing", "side-face"]);
        assert!(!BandParts::SILHOUETTE.intersects(BandParts::CANCELLING));
    }
}
