//! The silhouette of one prepared geometry towards a light, on the CPU: what the browser
//! drawer's polygon pass then reads instead of orienting every triangle and visiting every
//! edge record on the GPU.
//!
//! Per frame and light: every triangle's orientation ([`triangle_orientation`], paper 001
//! Alg. 4 through the triangle's reference edge, f32, never contracted: bit for bit the value
//! every native CPU method computes) into one byte each, and the list of the edge records of
//! the export's sides-data whose multiplicity (Alg. 3: `sum sign_i * orientation(T_i)` over the
//! record's opposite slots, the export's edge triangles) is not zero. The drawer uploads both:
//! the caps and the sides read that ONE orientation array, so the volumes stay closed, and only
//! the listed records (the silhouette) go through the polygon and fan passes. The records of
//! multiplicity ±1 come first: the fan pass draws them with one potential copy each, and only
//! the rest with `maxMult` copies.
//!
//! With a receiver cull ([`crate::cull`]) the triangles it drops count as edge-on (orientation
//! 0: no cap, no part in any edge's multiplicity), so the listed records are the silhouette of
//! the kept triangles only, as `umbra_geom::silhouette::extract_clamped` has it; the kept
//! triangles of nonzero orientation are then listed too (the caps the drawer draws).

use umbra_geom::multiplicity::triangle_orientation;
use umbra_geom::{Light, WeldedMesh};

/// One geometry's silhouette data (see the module documentation).
#[derive(Clone, Debug)]
pub struct Silhouette {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Opposite slots used by each edge record (the `count` of sides-data's first texel).
    counts: Vec<u8>,
    /// `max_mult` signed triangle numbers (±(T + 1)) per record: the export's edge triangles.
    edge_triangles: Vec<i32>,
    max_mult: usize,
    orientation: Vec<i8>,
    records: Vec<i32>,
    /// Records of multiplicity ±2 or more, gathered apart, then appended to `records`.
    multiple: Vec<i32>,
    single: usize,
    /// The triangles of nonzero orientation of the last culled [`Silhouette::compute`].
    kept: Vec<i32>,
}

impl Silhouette {
    /// From the welded mesh the export buffers were built from, their sides-data (`2 + max_mult`
    /// vec4 per record) and edge triangles.
    pub fn new(mesh: &WeldedMesh, sides_data: &[f32], edge_triangles: &[i32], max_mult: usize) -> Silhouette {
        let stride = 4 * (2 + max_mult);
        let counts = sides_data.chunks_exact(stride).map(|r| r[3] as u8).collect();
        Silhouette {
            positions: mesh.positions.clone(),
            triangles: mesh.triangles.clone(),
            counts,
            edge_triangles: edge_triangles.to_vec(),
            max_mult,
            orientation: vec![0; mesh.triangles.len()],
            records: Vec::new(),
            multiple: Vec::new(),
            single: 0,
            kept: Vec::new(),
        }
    }

    /// Orients every triangle towards `light` (the geometry's own space, w = 0 directional)
    /// and lists the records of nonzero multiplicity, those of ±1 first; returns how many.
    /// With `keep` (one flag per triangle, a receiver cull's), a triangle not kept counts as
    /// edge-on, and the kept triangles of nonzero orientation are listed
    /// ([`Silhouette::kept_triangles`]).
    pub fn compute(&mut self, light: Light, keep: Option<&[bool]>) -> usize {
        for (o, &t) in self.orientation.iter_mut().zip(&self.triangles) {
            *o = triangle_orientation(&self.positions, t, light) as i8;
        }
        self.kept.clear();
        if let Some(keep) = keep {
            for (t, (o, &k)) in self.orientation.iter_mut().zip(keep).enumerate() {
                if !k {
                    *o = 0;
                } else if *o != 0 {
                    self.kept.push(t as i32);
                }
            }
        }
        self.records.clear();
        self.multiple.clear();
        for (r, &count) in self.counts.iter().enumerate() {
            let slots = &self.edge_triangles[r * self.max_mult..r * self.max_mult + count as usize];
            let mut m = 0i32;
            for &t in slots {
                let o = i32::from(self.orientation[(t.unsigned_abs() - 1) as usize]);
                m += if t > 0 { o } else { -o };
            }
            match m.abs() {
                0 => {}
                1 => self.records.push(r as i32),
                _ => self.multiple.push(r as i32),
            }
        }
        self.single = self.records.len();
        self.records.extend_from_slice(&self.multiple);
        self.records.len()
    }

    /// The orientations of the last [`Silhouette::compute`], one per triangle (+1 faces the
    /// light, -1 faces away, 0 edge-on).
    pub fn orientation(&self) -> &[i8] {
        &self.orientation
    }

    /// The records of nonzero multiplicity of the last [`Silhouette::compute`]: those of ±1,
    /// ascending, then the others, ascending.
    pub fn records(&self) -> &[i32] {
        &self.records
    }

    /// The multiplicity of edge record `r` under the last [`Silhouette::compute`].
    pub fn multiplicity(&self, r: usize) -> i32 {
        let count = self.counts[r] as usize;
        self.edge_triangles[r * self.max_mult..r * self.max_mult + count]
            .iter()
            .map(|&t| {
                let o = i32::from(self.orientation[(t.unsigned_abs() - 1) as usize]);
                if t > 0 {
                    o
                } else {
                    -o
                }
            })
            .sum()
    }

    /// The welded positions.
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    /// The welded triangles.
    pub fn triangle_vertices(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// How many of [`Silhouette::records`] (the first ones) have multiplicity ±1.
    pub fn single(&self) -> usize {
        self.single
    }

    /// The kept triangles of nonzero orientation of the last [`Silhouette::compute`] with a
    /// `keep` (ascending; empty without one).
    pub fn kept_triangles(&self) -> &[i32] {
        &self.kept
    }

    /// Triangles of the geometry.
    pub fn triangles(&self) -> usize {
        self.triangles.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare_welded;
    use umbra_geom::adjacency::EdgeAdjacency;
    use umbra_geom::multiplicity::edge_multiplicity;
    use umbra_geom::scene::load_scene;

    #[test]
    fn the_listed_records_are_the_edges_of_nonzero_multiplicity() {
        let mesh = load_scene("default").expect("default scene");
        let positions: Vec<f32> = mesh.positions.iter().flatten().copied().collect();
        let index: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let (p, welded) = prepare_welded("default", &positions, Some(&index)).expect("default");
        let b = &p.buffers;
        let mut s = Silhouette::new(&welded, &b.sides_data, &b.edge_triangles, b.max_mult);
        let adj = EdgeAdjacency::build(&welded);
        for light in [[1.0, 4.0, 2.0, 1.0], [0.3, 1.0, -0.2, 0.0]] {
            let n = s.compute(light, None);
            assert!(n > 0 && n < b.records, "{n} of {} records", b.records);
            for (t, &tri) in welded.triangles.iter().enumerate() {
                assert_eq!(i32::from(s.orientation()[t]), triangle_orientation(&welded.positions, tri, light));
            }
            // Every edge of nonzero multiplicity has a listed record (records of one split
            // edge share its end points: the key, unordered).
            let key = |p: [f32; 3], q: [f32; 3]| {
                let (p, q) = (p.map(f32::to_bits), q.map(f32::to_bits));
                if p <= q {
                    [p, q]
                } else {
                    [q, p]
                }
            };
            let mut listed = std::collections::HashSet::new();
            let stride = 4 * (2 + b.max_mult);
            for &r in s.records() {
                let rec = &b.sides_data[r as usize * stride..];
                listed.insert(key([rec[0], rec[1], rec[2]], [rec[4], rec[5], rec[6]]));
            }
            let mut silhouette_edges = 0;
            for (e, &[a, bv]) in adj.edges.iter().enumerate() {
                if edge_multiplicity(&welded.positions, [a, bv], adj.opposites(e), light) != 0 {
                    silhouette_edges += 1;
                    let k = key(welded.positions[a as usize], welded.positions[bv as usize]);
                    assert!(listed.contains(&k), "edge {e} of nonzero multiplicity is not listed");
                }
            }
            assert!(silhouette_edges > 0 && listed.len() <= n);
            // ±1 first, then the rest; the multiplicities recomputed from the orientations.
            let mult = |r: i32| {
                let r = r as usize;
                let count = b.sides_data[r * stride + 3] as usize;
                let slots = &b.edge_triangles[r * b.max_mult..r * b.max_mult + count];
                slots
                    .iter()
                    .map(|&t| i32::from(s.orientation()[(t.unsigned_abs() - 1) as usize]) * t.signum())
                    .sum::<i32>()
            };
            assert!(s.records()[..s.single()].iter().all(|&r| mult(r).abs() == 1));
            assert!(s.records()[s.single()..].iter().all(|&r| mult(r).abs() >= 2));
        }
    }
}
