//! CPU shadow volumes from deterministic multiplicities: silhouette sides and caps.
//!
//! Paper 001, Section 2.2: an edge with multiplicity `m` casts `|m|` side quads, extruded to
//! infinity with Eq. 2 (`C = (A·l_w - L.xyz, 0)`, `D = (B·l_w - L.xyz, 0)`; the paper writes
//! it for `l_w = 1`); Section 2.3: caps oriented by the same reference-edge test, so sides and
//! caps never disagree. Kim, Kim & Turk 2008 for the multiplicity itself.
//!
//! Orientation convention (what makes the stencil counts right): every triangle's own volume
//! is oriented so that the triangle, as a light cap, faces the light, and all faces are
//! counter-clockwise seen from *outside* the volume. For a triangle `A → B → C` facing the
//! light the volume is bounded by the light cap `A B C`, the dark cap `A∞ C∞ B∞` and, for
//! each edge `A → B`, the side `B A A∞ B∞` (the side must traverse the shared edge opposite
//! to the cap). Edge `A → B` with multiplicity `m > 0` thus emits `m` copies of the quad
//! `B A A∞ B∞`; `m < 0` emits `|m|` copies of `A B B∞ A∞`. The union of all triangles'
//! volumes then has winding number = the number of triangles between a point and the light,
//! never negative; the interior sides of adjacent lit triangles cancel, which is exactly
//! what `m = 0` means.
//!
//! Directional lights (`l_w = 0`): every vertex extrudes to the same point at infinity
//! `-L.xyz`, so dark caps have zero area and are not emitted.
//!
//! Two outputs of the same volume:
//! * [`extract`] (the reference): per frame, the multiplicities are evaluated 256 (edge,
//!   opposite vertex) pairs at a time in a loop the compiler vectorises, calling the very
//!   [`comp_multiplicity`] of [`crate::multiplicity`] on the very arguments Alg. 3 gives it
//!   (so the result is the same bit for bit); per-chunk sums of `|m|` and their prefix sums
//!   place every chunk's quads, which it then writes straight into `out`. Caps the same way,
//!   as vertex copies ([`VolumeGeometry`], 96 bytes per cap for a point light).
//! * [`extract_indexed`] (what the renderer draws): every triangle's orientation once (the
//!   same vectorised kernel as [`extract`]'s caps), each edge's multiplicity as the sum of
//!   its triangles' ± orientations through the per-mesh [`TriangleSlots`] (bit for bit the
//!   contributions of Alg. 3), the same side quads, and the caps as one oriented index triple
//!   per triangle into the welded positions ([`IndexedVolume`], 12 bytes), drawn from the
//!   mesh's static position buffer (light caps as they are, dark caps extruded in the vertex
//!   shader). [`IndexedVolume::expand_into`] turns the indices into the very vertices drawn.
//!
//! Both in parallel and, once warmed up, without allocating. Figures in
//! `docs/benchmarks.md`.
//!
//! One part per file: `clamp.rs` ([`VolumeClamp`]: the triangles kept and the far ends of a
//! volume clamped to its receivers, [`extract_clamped`]), `volume.rs` (the vertices, Eq. 2's extrusion, the caps' geometry),
//! `kernels.rs` (the vectorised Alg. 3-4 kernels), `emit.rs` (the parallel two-pass emission
//! and its per-thread scratch), `extract.rs` ([`extract`]), `indexed.rs` ([`extract_indexed`],
//! [`IndexedVolume`]), `slots.rs` ([`TriangleSlots`]), `fill.rs` ([`estimate_fill`]: a clamped volume's screen area against the unclamped one's),
//! `regions.rs` ([`keep_whole_regions`]: the cull widened to whole
//! regions of one orientation), `components.rs` ([`caster_pieces`]: the light-independent
//! pieces the GPU methods cull whole), `tests.rs` (both outputs against the
//! serial emission).
//!
//! [`comp_multiplicity`]: crate::multiplicity::comp_multiplicity

use rayon::prelude::*;

use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::edge_multiplicity;
use crate::weld::WeldedMesh;
use crate::Light;

mod clamp;
mod components;
mod emit;
mod extract;
mod fill;
mod indexed;
mod kept;
mod kernels;
mod regions;
mod slots;
mod volume;

pub use clamp::{travel, VolumeClamp, CLAMP_LIMIT, CLAMP_MARGIN};
pub use components::{caster_pieces, edge_pieces};
pub use extract::extract;
pub use fill::{estimate_fill, FillEstimate, ScreenClip};
pub use indexed::{extract_clamped, extract_indexed, is_degenerate_cap, IndexedVolume};
pub use kept::{extract_kept, DrawnVolume};
pub use regions::keep_whole_regions;
pub use slots::{TriangleSlots, TriangleSlotsError};
pub use volume::{extrude, has_dark_caps, VolumeGeometry};

/// Per-edge multiplicities in edge order (for statistics and tests).
pub fn multiplicities(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light) -> Vec<i32> {
    (0..adj.len())
        .into_par_iter()
        .map(|e| edge_multiplicity(&mesh.positions, adj.edges[e], adj.opposites(e), light))
        .collect()
}

/// Silhouette statistics for `umbra info`: edges with `m != 0` and the sum of `|m|`.
pub fn silhouette_stats(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light) -> (usize, u64) {
    let m = multiplicities(mesh, adj, light);
    (m.iter().filter(|&&x| x != 0).count(), m.iter().map(|&x| x.unsigned_abs() as u64).sum())
}

#[cfg(test)]
mod tests;
