//! Is the eye outside every shadow volume? The test that lets z-pass count.
//!
//! Papers: Heidmann 1991 (z-pass stencil shadow volumes); Everitt & Kilgard 2002, "Practical and
//! Robust Stenciled Shadow Volumes for Hardware-Accelerated Rendering", Section 2 (z-pass fails
//! when the near plane cuts a volume; z-fail with caps at infinity fixes it) and Section 6
//! ("use z-pass when the near-plane light pyramid is clear"); paper 001, Section 2.1 (the count
//! `W(p)`: the number of triangles the segment from `p` to the light crosses, `p` lit iff 0).
//!
//! z-pass counts the volume faces between the eye and a visible sample `p` (depth-clamped
//! fragments in front of the near plane included). That count is `W(p) - W(e)` for the point
//! `e` where the eye ray enters the counted region, so z-pass equals z-fail exactly when every
//! such entry point — the eye itself and every point of the near-plane rectangle — has `W = 0`
//! and no volume face crosses the pyramid between the eye and that rectangle. A triangle `T`
//! puts a point `x` inside its volume iff the segment from `x` to the light meets `T`; so all of
//! this holds when no triangle meets the convex hull `H` of the eye, the near-plane rectangle
//! and the light (for a directional light: the same points swept towards the light beyond the
//! scene's bounds). [`ClearanceIndex::is_clear`] proves that, conservatively:
//!
//! * separating-axis test, triangle against the convex polytope `H`, in f64: candidate axes are
//!   the face planes of `H` (every triple of its points whose plane has all points on one
//!   side), the triangle's normal, and the cross products of every edge of `H` (every pair of
//!   its points, a superset of its true edges) with the triangle's edges. A superset of the
//!   true SAT axes is still a proof of separation;
//! * a gap must exceed a margin of `1e-6` of the scene's scale, so a triangle that merely
//!   touches `H`, or lies within rounding of it, counts as blocking;
//! * triangles are grouped in clusters of [`CLUSTER`] consecutive triangles with an
//!   axis-aligned box each (built once per mesh); a box separated from `H` along the box axes or
//!   a face plane of `H` skips its whole cluster;
//! * a triangle with a non-finite vertex blocks (its volume is unknown).
//!
//! [`ClearanceIndex::near_winding`] extends this to an eye in shadow. `W(x)`, as the point `x`
//! moves through the pyramid, changes only where the segment from `x` to the light passes an
//! edge with a nonzero multiplicity (paper 001, Alg. 3: across an edge of multiplicity 0 the
//! segment leaves one triangle and enters another) or where `x` itself passes a triangle. So
//! `W` is one constant `W0` over the whole pyramid when no triangle meets the pyramid itself
//! and every triangle meeting `H` is either crossed strictly — barycentric and segment margins
//! of [`CROSSING_MARGIN`] — by the segments from EACH point to the light (then none of its edges
//! meets the cone), or has no edge of nonzero multiplicity meeting `H` (the latter only for
//! volumes without faces on edges of multiplicity 0: the caller passes the adjacency). `W0` is then the number
//! of triangles the eye's segment crosses, counted where every crossing is unambiguous (strictly
//! in or strictly out), and z-pass with the count starting at `W0` (the stencil cleared to `W0`)
//! equals z-fail. Anything else is "unknown" (None): z-fail.
//!
//! Answering "not clear" wrongly only costs speed (the renderer falls back to z-fail); answering
//! "clear" wrongly would cost exactness, which is why every approximation errs the first way.
//!
//! One part per file: `crossing.rs` (the strict segment-triangle crossing), `clip_box.rs`
//! (the scene clip box of the z-pass volumes), `hull.rs` (the separating-axis test against
//! `H`), `index.rs` ([`ClearanceIndex`]: the cluster boxes and both questions).

// `!(x > 0.0)` on purpose: true for NaN, which must answer "unknown", never "clear".
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod clip_box;
mod crossing;
mod hull;
mod index;

pub use clip_box::scene_clip_box;
pub use crossing::{crossing, CROSSING_MARGIN};
pub use index::{ClearanceIndex, CLUSTER, MARGIN};

#[cfg(test)]
mod tests;
