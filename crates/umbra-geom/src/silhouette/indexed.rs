//! [`extract_indexed`], the CPU shadow volume the renderer draws: every triangle oriented
//! once, each edge's multiplicity summed from its triangles' orientations through the
//! per-mesh [`TriangleSlots`], and the caps as one index triple per triangle
//! ([`IndexedVolume`]).

use rayon::prelude::*;

use super::clamp::VolumeClamp;
use super::emit::{emit_sides, set_len, with_scratch, Scratch, ITEMS_PER_CHUNK};
use super::kernels::orientation_batches;
use super::slots::TriangleSlots;
use super::volume::{cap_vertices, extrude, has_dark_caps, oriented, VolumeGeometry};
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
    /// Far caps of a volume clamped to its receivers ([`extract_clamped`]): per kept,
    /// light-facing-oriented triangle `P0 P1 P2`, the triangle of its far vertices
    /// `P0' P2' P1'` (facing out of the volume, as a dark cap), three homogeneous vertices
    /// each (a far vertex at infinity has `w = 0`). Drawn in z-pass and z-fail alike: unlike a
    /// dark cap at infinity, a far cap may lie in front of a visible sample. A far cap with
    /// all three far ends at infinity is left out where the unclamped volume has no dark cap
    /// (z-pass, directional lights). Empty for an unclamped volume.
    pub far_caps: Vec<[f32; 4]>,
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
        self.far_caps.clear();
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
        with_scratch(|scratch| extract_indexed_with(mesh, adj, slots, light, caps, None, out, scratch));
    });
}

/// [`extract_indexed`] of the triangles `clamp` keeps, with every side ending at its
/// vertices' far ends instead of infinity and the volume closed there by
/// [`IndexedVolume::far_caps`] ([`VolumeClamp`], the proof in docs/exactness.md). The
/// multiplicities are the sums over the kept triangles' orientations only (a dropped
/// triangle counts as edge-on: no cap, no contribution to its edges), so the sides are the
/// silhouette of the kept triangles. `caps` asks for the light caps (z-fail); the far caps
/// are written either way. `clamp` must have been made for this mesh and `light`.
pub fn extract_clamped(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    clamp: &VolumeClamp,
    out: &mut IndexedVolume,
) {
    rayon::scope(|_| {
        with_scratch(|scratch| extract_indexed_with(mesh, adj, slots, light, caps, Some(clamp), out, scratch));
    });
}

#[allow(clippy::too_many_arguments)]
fn extract_indexed_with(
    mesh: &WeldedMesh,
    adj: &EdgeAdjacency,
    slots: &TriangleSlots,
    light: Light,
    caps: bool,
    clamp: Option<&VolumeClamp>,
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
    let keep = clamp.map(|c| &c.keep[..]);
    let orient = |first: usize, ss: &mut [i8], tris: &[[u32; 3]], mut caps_out: Option<&mut [[u32; 3]]>| {
        let mut at = 0;
        orientation_batches(&mesh.positions, tris, light, |tris, orientations| {
            for (s, &o) in ss[at..at + tris.len()].iter_mut().zip(orientations) {
                *s = o as i8;
            }
            if let Some(keep) = keep {
                // A dropped triangle is treated as edge-on: no cap, no part in any edge.
                for (s, &k) in ss[at..at + tris.len()].iter_mut().zip(&keep[first + at..first + at + tris.len()]) {
                    if !k {
                        *s = 0;
                    }
                }
            }
            let orientations = &ss[at..at + tris.len()];
            if let Some(out) = caps_out.as_deref_mut() {
                for ((cap, &tri), &s) in out[at..at + tris.len()].iter_mut().zip(tris).zip(orientations) {
                    *cap = if s != 0 { oriented(tri, s) } else { [tri[0]; 3] };
                }
            }
            at += tris.len();
        });
    };
    let chunks = orientation.par_chunks_mut(ITEMS_PER_CHUNK).zip(triangles.par_chunks(ITEMS_PER_CHUNK)).enumerate();
    if caps {
        chunks
            .zip(out.caps.par_chunks_mut(ITEMS_PER_CHUNK))
            .for_each(|((k, (ss, tris)), c)| orient(k * ITEMS_PER_CHUNK, ss, tris, Some(c)));
    } else {
        chunks.for_each(|(k, (ss, tris))| orient(k * ITEMS_PER_CHUNK, ss, tris, None));
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
    let positions = &mesh.positions;
    match clamp {
        None => {
            let far = |i: u32| extrude(positions[i as usize], light);
            emit_sides(positions, adj, multiplicity, side_offsets, &mut out.sides, &from_orientations, &far);
            out.far_caps.clear();
        }
        Some(clamp) => {
            let far = |i: u32| clamp.far_vertex(positions, i);
            emit_sides(positions, adj, multiplicity, side_offsets, &mut out.sides, &from_orientations, &far);
            // The far caps: one per kept triangle that is not edge-on, in triangle order. A far
            // cap whose three far ends are at infinity is the dark cap at infinity: drawn only
            // where the unclamped volume draws it (z-fail, point lights); z-pass never counts
            // it and a directional light's has no area.
            out.far_caps.clear();
            let infinite_caps = caps && has_dark_caps(light);
            for (&tri, &s) in triangles.iter().zip(ss.iter()) {
                if s != 0 {
                    let [i0, i1, i2] = oriented(tri, s);
                    let cap = [far(i0), far(i2), far(i1)];
                    if infinite_caps || cap.iter().any(|v| v[3] != 0.0) {
                        out.far_caps.extend_from_slice(&cap);
                    }
                }
            }
        }
    }
}
