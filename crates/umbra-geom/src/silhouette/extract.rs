//! [`extract`], the reference output of the CPU shadow volume: sides and caps as vertex
//! copies ([`VolumeGeometry`]), from the vectorised multiplicities of every edge.

use super::emit::{
    cap_orientations, emit_sides, for_each_cap, set_len, with_scratch, write_chunks, CapsOut, Scratch, ITEMS_PER_CHUNK,
};
use super::kernels::multiplicities_batched;
use super::volume::{cap_vertices, extrude, has_dark_caps, VolumeGeometry};
use crate::adjacency::EdgeAdjacency;
use crate::weld::WeldedMesh;
use crate::Light;

/// Computes every edge's multiplicity (in parallel) and emits the volume into `out`
/// (its previous contents replaced, its capacity reused). `caps` adds the light and dark
/// caps z-fail needs, as vertex copies (96 bytes per cap and frame for a point light; the
/// renderer uses [`extract_indexed`], which writes 12).
///
/// Output order is deterministic (edge order, then triangle order). Two parallel passes per
/// output: multiplicities (or cap orientations) with a count per chunk, then, after prefix
/// sums over the chunks, every chunk writes its vertices straight into its own part of
/// `out`. Once warmed up (same thread, output not larger than before) a frame allocates
/// nothing.
///
/// [`extract_indexed`]: super::extract_indexed
pub fn extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool, out: &mut VolumeGeometry) {
    with_scratch(|scratch| {
        let positions = &mesh.positions;
        let Scratch { multiplicity, orientation, side_offsets, cap_offsets } = scratch;
        let from_positions = |first: usize, ms: &mut [i32]| multiplicities_batched(positions, adj, first, ms, light);
        let far = |i: u32| extrude(positions[i as usize], light);
        emit_sides(positions, adj, multiplicity, side_offsets, &mut out.sides, &from_positions, &far);
        if !caps {
            out.light_caps.clear();
            out.dark_caps.clear();
            return;
        }
        let tri_chunks = cap_orientations(mesh, light, orientation, cap_offsets);
        let cap_count = cap_offsets[tri_chunks];
        set_len(&mut out.light_caps, 3 * cap_count, [0.0; 4]);
        set_len(&mut out.dark_caps, if has_dark_caps(light) { 3 * cap_count } else { 0 }, [0.0; 4]);
        let (ss, triangles): (&[i8], _) = (orientation, &mesh.triangles);
        let caps_out: CapsOut<'_> = (out.light_caps.as_chunks_mut().0, out.dark_caps.as_chunks_mut().0);
        write_chunks(0..tri_chunks, cap_offsets, caps_out, &|chunk, (light_caps, dark_caps): CapsOut<'_>| {
            let range = chunk * ITEMS_PER_CHUNK..((chunk + 1) * ITEMS_PER_CHUNK).min(triangles.len());
            let mut at = 0;
            for_each_cap(&triangles[range.clone()], &ss[range], |cap| {
                let (lit, dark) = cap_vertices(positions, cap, light);
                light_caps[at] = lit;
                if let Some(d) = dark_caps.get_mut(at) {
                    *d = dark;
                }
                at += 1;
            });
        });
    })
}
