//! [`extract_indexed`], the CPU shadow volume the renderer draws: every triangle oriented
//! once, each edge's multiplicity summed from its triangles' orientations through the
//! per-mesh [`TriangleSlots`], and the caps as one index triple per triangle
//! ([`IndexedVolume`]).

use rayon::prelude::*;

use super::emit::{emit_sides, set_len, with_scratch, Scratch, ITEMS_PER_CHUNK};
use super::kernels::orientation_batches;
use super::slots::TriangleSlots;
use super::volume::{cap_vertices, has_dark_caps, oriented, VolumeGeometry};
use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;
use crate::Light;

/// The shadow volume of [`extract`] with the caps as indices into the welded positions
/// instead of vertex copies: 12 bytes per triangle and frame instead of 96. The renderer
/// draws the caps from the mesh's static position buffer; [`IndexedVolume::expand_into`]
/// gives the vertices it draws, so tests can check the very volume drawn.
///
/// [`extract`]: super::extract
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedVolume {
    /// Silhouette sides, exactly as [`VolumeGeometry::sides`].
    pub sides: Vec<[f32; 4]>,
    /// One cap per triangle of the mesh, in mesh order (empty without caps): the triangle
    /// wound so that it faces the light, by its [`triangle_orientation`] (through the
    /// reference edge, as the sides), or, when it is edge-on (orientation 0, no cap), the
    /// degenerate cap `[i0, i0, i0]`, which has zero area and draws nothing. Light cap: the
    /// triangle at `w = 1`, pushed to the far plane by the renderer. Dark cap (only if
    /// [`has_dark_caps`]): the same three vertices extruded to infinity with 001 Eq. 2 and
    /// the opposite winding. Keeping edge-on triangles as degenerate caps gives every
    /// triangle a fixed slot, so each chunk of triangles writes its caps in the same pass
    /// that orients them, without counting first.
    ///
    /// [`triangle_orientation`]: crate::multiplicity::triangle_orientation
    pub caps: Vec<[u32; 3]>,
}

/// Whether an [`IndexedVolume`] cap is the degenerate stand-in of an edge-on triangle.
#[inline]
pub fn is_degenerate_cap(cap: [u32; 3]) -> bool {
    cap[0] == cap[1] && cap[1] == cap[2]
}

impl IndexedVolume {
    /// Empties sides and caps, keeping the allocations.
    pub fn clear(&mut self) {
        self.sides.clear();
        self.caps.clear();
    }

    /// The vertices the renderer draws for this volume, into `out` (its contents replaced):
    /// the sides as they are, then per cap the light cap and, for point lights, the dark cap,
    /// degenerate caps included (as zero-area triangles). Without the degenerate caps this
    /// is, bit for bit, what [`extract`] writes for the same mesh and light. `positions`
    /// must be those of the mesh the volume was extracted from; an index out of their range
    /// is a programming error and panics.
    ///
    /// [`extract`]: super::extract
    pub fn expand_into(&self, positions: &[[f32; 3]], light: Light, out: &mut VolumeGeometry) {
        out.clear();
        out.sides.extend_from_slice(&self.sides);
        for &cap in &self.caps {
            let (lit, dark) = cap_vertices(positions, cap, light);
            out.light_caps.extend_from_slice(&lit);
            if has_dark_caps(light) {
                out.dark_caps.extend_from_slice(&dark);
            }
        }
    }

    /// [`IndexedVolume::expand_into`] into a new [`VolumeGeometry`].
    pub fn expand(&self, positions: &[[f32; 3]], light: Light) -> VolumeGeometry {
        let mut out = VolumeGeometry::default();
        self.expand_into(positions, light, &mut out);
        out
    }
}

/// The volume of [`extract`] with indexed caps ([`IndexedVolume`]), from one orientation per
/// triangle: pass 1 orients every triangle (the vectorised kernel of [`extract`]'s caps)
/// into the scratch and, with `caps`, writes its cap in the same go; pass 2 sums the
/// orientations per edge through `slots` ([`TriangleSlots`]) into the multiplicities; pass 3
/// writes the side quads exactly as [`extract`] does. The same multiplicities, sides and
/// caps as [`extract`] (bit for bit, checked by the unit tests) whenever the vertex order is
/// strict, i.e. without NaN coordinates; with NaN the sides follow the caps' orientations,
/// so the volume stays closed. Deterministic, parallel, and allocation-free once warmed up
/// (rayon's global queue allocates a block per 63 calls from outside its pool).
///
/// `slots` must be [`TriangleSlots::build`] of this mesh and adjacency; slots of another
/// mesh give a wrong volume or panic on an index out of range.
///
/// [`extract`]: super::extract
pub fn extract_indexed(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    out: &mut IndexedVolume,
) {
    // One job for the whole frame: the passes below fork and join on the pool's workers
    // instead of each queueing from outside.
    rayon::scope(|_| {
        with_scratch(|scratch| extract_indexed_with(mesh, adj, slots, light, caps, out, scratch));
    });
}

fn extract_indexed_with(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    out: &mut IndexedVolume,
    scratch: &mut Scratch,
) {
    let Scratch { multiplicity, orientation, side_offsets, .. } = scratch;
    let triangles = &mesh.triangles;
    // Pass 1: orientations, and the caps.
    set_len(orientation, triangles.len(), 0);
    if caps {
        set_len(&mut out.caps, triangles.len(), [0; 3]);
    } else {
        out.caps.clear();
    }
    let orient = |ss: &mut [i8], tris: &[[u32; 3]], mut caps_out: Option<&mut [[u32; 3]]>| {
        let mut at = 0;
        orientation_batches(&mesh.positions, tris, light, |tris, orientations| {
            for (s, &o) in ss[at..at + tris.len()].iter_mut().zip(orientations) {
                *s = o as i8;
            }
            if let Some(out) = caps_out.as_deref_mut() {
                for ((cap, &tri), &s) in out[at..at + tris.len()].iter_mut().zip(tris).zip(orientations) {
                    *cap = if s != 0 { oriented(tri, s as i8) } else { [tri[0]; 3] };
                }
            }
            at += tris.len();
        });
    };
    let chunks = orientation.par_chunks_mut(ITEMS_PER_CHUNK).zip(triangles.par_chunks(ITEMS_PER_CHUNK));
    if caps {
        chunks.zip(out.caps.par_chunks_mut(ITEMS_PER_CHUNK)).for_each(|((ss, tris), c)| orient(ss, tris, Some(c)));
    } else {
        chunks.for_each(|(ss, tris)| orient(ss, tris, None));
    }

    // Pass 2 and 3: multiplicities as sums of ± orientations, then the sides.
    let (ss, slots, start): (&[i8], &[u32], &[u32]) = (orientation, &slots.slots, &adj.opposite_start);
    let from_orientations = |first: usize, ms: &mut [i32]| {
        for (e, m) in (first..first + ms.len()).zip(ms.iter_mut()) {
            *m = slots[start[e] as usize..start[e + 1] as usize]
                .iter()
                .map(|&slot| ss[(slot >> 1) as usize] as i32 * (1 - 2 * (slot & 1) as i32))
                .sum();
        }
    };
    emit_sides(&mesh.positions, adj, light, multiplicity, side_offsets, &mut out.sides, &from_orientations);
}
