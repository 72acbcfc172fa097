//! A sound, cheap upper bound of the shadow-volume count of a mesh and one light.
//!
//! Stencil shadow volumes (Heidmann 1991 z-pass, Everitt & Kilgard 2002 z-fail) count, at a
//! visible sample `p`, the volume faces between `p` and the eye (or behind `p`); with volumes
//! oriented consistently the count equals `W(p)`, the number of triangles the segment from `p`
//! to the light crosses, and `p` is lit iff `W(p) = 0`. An 8-bit stencil with INCR_WRAP /
//! DECR_WRAP holds `W mod 256`: a sample with `W = 256, 512, ...` comes out LIT, silently
//! wrong. This module decides, before rendering, whether that can happen:
//!
//! `W(p)` is at most the number of triangles whose footprint *as seen from the light* (their
//! central projection for a point light, their parallel projection along the light direction
//! for a directional light) contains the direction of `p`. The footprints are binned:
//! * point light: the six faces of a cube map around the light. Each triangle is clipped
//!   (Sutherland-Hodgman, f64) to the pyramid of every face (`s d_k >= |d_j|`, boundaries
//!   included, so a direction on an edge of two faces is in both) and the bounding rectangle
//!   of the clipped polygon's projection `(d_j / s d_k)` is added, with a margin, to every
//!   cell it touches. A triangle passing (nearly) through the light covers the whole face.
//! * directional light: one square domain over the projection onto the plane orthogonal to the
//!   light direction.
//!
//! The count of a cell bounds `W` for every direction in it. Cells counting at least
//! [`BoundOptions::threshold`] (256) are refined adaptively (a sub-grid per hot cell with the
//! triangles that touch it), down to [`BoundOptions::max_depth`] levels or until the work
//! budget [`BoundOptions::budget`] (triangle-cell entries) runs out; then the cell's own count
//! stays — still an upper bound. The result, the largest cell count, is therefore sound; it is
//! tight only up to the cell size (triangles that merely touch a cell count).
//!
//! Triangles with a non-finite vertex are counted in every cell (unknown footprint).
//!
//! One part per file: `options.rs` (the options, the result, the errors), `footprint.rs` (a
//! triangle's footprint as seen from the light), `grid.rs` (the counting grid and its adaptive
//! refinement), `bound.rs` ([`winding_bound`]: the footprints of every domain, bounded in
//! parallel).

mod bound;
mod footprint;
mod grid;
mod options;

pub use bound::winding_bound;
pub use options::{BoundError, BoundOptions, WindingBound, STENCIL8_LIMIT};

#[cfg(test)]
mod tests;
