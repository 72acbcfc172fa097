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

use rayon::prelude::*;

use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::{edge_multiplicity, triangle_orientation};
use crate::weld::WeldedMesh;
use crate::Light;

/// Shadow-volume triangles in world space, homogeneous; every 3 vertices form a triangle,
/// counter-clockwise seen from outside the volume.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VolumeGeometry {
    /// Silhouette sides: two vertices at `w = 1` on the edge, two at infinity (`w = 0`).
    pub sides: Vec<[f32; 4]>,
    /// Light caps: the light-facing-oriented triangles themselves (`w = 1`). The renderer
    /// pushes them to the far plane (paper 003, Eq. 6).
    pub light_caps: Vec<[f32; 4]>,
    /// Dark caps at infinity (`w = 0`), point lights only.
    pub dark_caps: Vec<[f32; 4]>,
}

impl VolumeGeometry {
    pub fn clear(&mut self) {
        self.sides.clear();
        self.light_caps.clear();
        self.dark_caps.clear();
    }
}

/// `P` extruded away from the light to infinity: `(P·l_w - L.xyz, 0)` (001 Eq. 2).
#[inline(always)]
pub fn extrude(p: [f32; 3], light: Light) -> [f32; 4] {
    [p[0] * light[3] - light[0], p[1] * light[3] - light[1], p[2] * light[3] - light[2], 0.0]
}

#[inline(always)]
fn point(p: [f32; 3]) -> [f32; 4] {
    [p[0], p[1], p[2], 1.0]
}

/// Edges per parallel work item: large enough to amortise the per-chunk vector, small enough
/// to balance two to many cores.
const EDGES_PER_CHUNK: usize = 8192;

/// Appends the side quads of edge `[a, b]` (`a < b`) with multiplicity `m` to `out`.
#[inline]
fn emit_sides(out: &mut Vec<[f32; 4]>, a: [f32; 3], b: [f32; 3], m: i32, light: Light) {
    let (a_inf, b_inf) = (extrude(a, light), extrude(b, light));
    let (a, b) = (point(a), point(b));
    // m > 0: quad B A A∞ B∞; m < 0: the reverse, A B B∞ A∞.
    let quad = if m > 0 { [b, a, a_inf, b, a_inf, b_inf] } else { [a, b, b_inf, a, b_inf, a_inf] };
    for _ in 0..m.unsigned_abs() {
        out.extend_from_slice(&quad);
    }
}

/// Computes every edge's multiplicity (in parallel) and emits the volume into `out`
/// (cleared first). `caps` adds the light and dark caps z-fail needs.
///
/// Output order is deterministic (edge order, then triangle order).
pub fn extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool, out: &mut VolumeGeometry) {
    out.clear();
    let positions = &mesh.positions;
    let chunks: Vec<Vec<[f32; 4]>> = (0..adj.len())
        .into_par_iter()
        .step_by(EDGES_PER_CHUNK)
        .map(|start| {
            let end = (start + EDGES_PER_CHUNK).min(adj.len());
            let mut local = Vec::new();
            for e in start..end {
                let edge = adj.edges[e];
                let m = edge_multiplicity(positions, edge, adj.opposites(e), light);
                if m != 0 {
                    emit_sides(&mut local, positions[edge[0] as usize], positions[edge[1] as usize], m, light);
                }
            }
            local
        })
        .collect();
    out.sides.reserve(chunks.iter().map(Vec::len).sum());
    for c in &chunks {
        out.sides.extend_from_slice(c);
    }
    if !caps {
        return;
    }
    let directional = light[3] == 0.0;
    let cap_chunks: Vec<(Vec<[f32; 4]>, Vec<[f32; 4]>)> = mesh
        .triangles
        .par_chunks(EDGES_PER_CHUNK)
        .map(|tris| {
            let mut light_caps = Vec::new();
            let mut dark_caps = Vec::new();
            for &tri in tris {
                let s = triangle_orientation(positions, tri, light);
                if s == 0 {
                    continue;
                }
                // Wind the cap so that it faces the light.
                let [i0, i1, i2] = if s > 0 { tri } else { [tri[0], tri[2], tri[1]] };
                let [p0, p1, p2] = [i0, i1, i2].map(|i| positions[i as usize]);
                light_caps.extend_from_slice(&[point(p0), point(p1), point(p2)]);
                if !directional {
                    dark_caps.extend_from_slice(&[extrude(p0, light), extrude(p2, light), extrude(p1, light)]);
                }
            }
            (light_caps, dark_caps)
        })
        .collect();
    for (l, d) in &cap_chunks {
        out.light_caps.extend_from_slice(l);
        out.dark_caps.extend_from_slice(d);
    }
}

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
