//! Sides-data and caps-data of paper 003 (Milet et al., "Fast robust and precise shadow
//! algorithm for WebGL 1.0 platform"), Section 2.2 (Fig. 3-5) in the compact instanced layout
//! of Section 2.6: CPU preprocessing for the `vs-silhouette` method, no GL.
//!
//! **Sides-data** (Fig. 3 without the per-vertex copies): one *edge record* of `2 + maxMult`
//! `vec4`s per edge, the same for all `6 · maxMult` vertices the vertex shader runs for it
//! (instancing; the vertex and side index come from `gl_VertexID`):
//!
//! | vec4 | x y z | w |
//! | --- | --- | --- |
//! | 0 | edge vertex `A` | number of opposite vertices in this record (as f32, exact) |
//! | 1 | edge vertex `B` (`A < B` in the vertex order of [`crate::order`]) | 1 if the edge is split into several records, else 0 |
//! | 2 + j, j < count | opposite vertex `O_j` | 1 |
//! | 2 + j, j ≥ count | 0 | 0 (unused slot) |
//!
//! Size: Eq. 8, `16 · (2 + maxMult) · e` bytes ([`sides_data_bytes`]), `e` edge records.
//!
//! **Splitting** (as paper 001 splits edge patches): an edge with `k > maxMult` opposite
//! vertices becomes `ceil(k / maxMult)` consecutive records holding consecutive subsets of its
//! opposites (all but the last full). The multiplicity is a sum over opposites (001 Alg. 3),
//! so the records' sub-multiplicities add up to the edge's; each record extrudes `|m_i|`
//! quads wound by `sgn(m_i)`, and quads of opposite sign over the same edge cancel in the
//! stencil. That keeps `maxMult` — and with it the vertex-attribute count `2 + maxMult` and
//! the per-record work — bounded whatever the scene's largest multiplicity.
//!
//! **Caps-data** (Fig. 4 without the per-vertex copies): one record of 3 `vec4`s per
//! triangle, `(P_i, 1)` for its three vertices in the triangle's own order; Eq. 9,
//! `48 · t` bytes ([`caps_data_bytes`]).

use crate::adjacency::EdgeAdjacency;
use crate::multiplicity::opposite_contribution;
use crate::weld::WeldedMesh;
use crate::Light;

/// Bytes of one `vec4` of f32.
pub const VEC4_BYTES: usize = 16;

/// Largest `maxMult` of the layout: 16 vertex attributes (the minimum of both OpenGL 4.5 and
/// OpenGL ES 3.0 / WebGL 2) minus the two edge vertices.
pub const MAX_MULT_LIMIT: usize = 14;

/// Paper 003, Eq. 8: bytes of the compact sides-data, `16 · (2 + maxMult) · e`.
pub fn sides_data_bytes(edge_records: usize, max_mult: usize) -> usize {
    VEC4_BYTES * (2 + max_mult) * edge_records
}

/// Paper 003, Eq. 9: bytes of the compact caps-data, `48 · t`.
pub fn caps_data_bytes(triangles: usize) -> usize {
    3 * VEC4_BYTES * triangles
}

/// Why sides-data or caps-data could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SidesDataError {
    /// `maxMult` outside 1..=[`MAX_MULT_LIMIT`].
    #[error("sides-data: maxMult must be between 1 and {MAX_MULT_LIMIT}, got {0}")]
    MaxMult(usize),
    /// An edge refers to a vertex the mesh does not have.
    #[error("sides-data: edge {edge} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    EdgeVertex {
        /// The edge index.
        edge: usize,
        /// The vertex index.
        vertex: u32,
        /// Vertices the mesh has.
        vertices: usize,
    },
    /// A triangle refers to a vertex the mesh does not have.
    #[error("caps-data: triangle {triangle} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    TriangleVertex {
        /// The triangle index.
        triangle: usize,
        /// The vertex index.
        vertex: u32,
        /// Vertices the mesh has.
        vertices: usize,
    },
}

/// Sides-data in the compact layout (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SidesData {
    /// Opposite-vertex slots per record (`maxMult` of Eq. 8).
    pub max_mult: usize,
    /// `(2 + max_mult)` vec4s per record, records in edge order.
    pub data: Vec<[f32; 4]>,
    /// The [`EdgeAdjacency`] edge each record belongs to (non-decreasing).
    pub source_edge: Vec<u32>,
}

impl SidesData {
    /// Number of edge records (`e` of Eq. 8).
    pub fn records(&self) -> usize {
        self.source_edge.len()
    }

    /// `vec4`s per record.
    pub fn stride(&self) -> usize {
        2 + self.max_mult
    }

    /// Bytes of [`SidesData::data`]; equals [`sides_data_bytes`]`(records, max_mult)`.
    pub fn bytes(&self) -> usize {
        self.data.len() * VEC4_BYTES
    }

    /// The `vec4`s of record `r`.
    pub fn record(&self, r: usize) -> &[[f32; 4]] {
        let s = self.stride();
        &self.data[r * s..(r + 1) * s]
    }

    /// What the vertex shader computes for record `r` (paper 001 Alg. 3 over the record's
    /// opposites): the record's sub-multiplicity. The CPU twin of `vs_silhouette/sides.vert.glsl`.
    pub fn record_multiplicity(&self, r: usize, light: Light) -> i32 {
        let rec = self.record(r);
        let xyz = |v: [f32; 4]| [v[0], v[1], v[2]];
        let count = rec[0][3] as usize;
        rec[2..2 + count].iter().map(|&o| opposite_contribution(xyz(rec[0]), xyz(rec[1]), xyz(o), light)).sum()
    }
}

/// Records edge `k` (with `k` opposites) needs at `max_mult` slots per record.
fn records_for(k: usize, max_mult: usize) -> usize {
    k.div_ceil(max_mult).max(1)
}

/// Number of edge records for `adj` at `max_mult` (0 for `max_mult == 0`).
pub fn record_count(adj: &EdgeAdjacency, max_mult: usize) -> usize {
    if max_mult == 0 {
        return 0;
    }
    adj.opposite_start.windows(2).map(|w| records_for((w[1] - w[0]) as usize, max_mult)).sum()
}

/// One edge record of the split (see the module documentation): edge `edge` of the adjacency,
/// its opposite slots `first..first + count`, and whether the edge needs several records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RecordRange {
    /// Index of the edge in the adjacency.
    pub edge: usize,
    /// First opposite slot of the record (an index into `EdgeAdjacency::opposites`).
    pub first: u32,
    /// Opposite slots in the record, at most `max`.
    pub count: u32,
    /// The edge has more than `max` opposites (several records).
    pub split: bool,
}

/// The edge records of `adj` at most `max` (at least 1) opposites each, in edge order: an edge
/// with more opposites becomes consecutive records of consecutive opposites, all but the last
/// full; an edge without opposites keeps one empty record. [`record_count`] of them.
pub fn record_ranges(adj: &EdgeAdjacency, max: usize) -> impl Iterator<Item = RecordRange> + '_ {
    let max = max.max(1) as u32;
    (0..adj.len()).flat_map(move |edge| {
        let (start, end) = (adj.opposite_start[edge], adj.opposite_start[edge + 1]);
        let split = end - start > max;
        (0..(end - start).div_ceil(max).max(1)).map(move |r| {
            let first = start + r * max;
            RecordRange { edge, first, count: (end - first).min(max), split }
        })
    })
}

/// The `maxMult` to use for `adj` with at most `limit` slots per record: the scene's largest
/// number of opposite vertices, but no more than `limit`, and no more than the smallest
/// count that holds 99.9 % of the edges in one record when larger counts are rare (each
/// vertex of every record loops over `maxMult` opposites, `6 · maxMult` vertices per record:
/// a single 40-sheet book spine must not make every edge of the scene 20 times as expensive;
/// the few edges above it are split). At least 1 when there is an edge.
pub fn choose_max_mult(adj: &EdgeAdjacency, limit: usize) -> usize {
    let limit = limit.clamp(1, MAX_MULT_LIMIT);
    let mut histogram = [0usize; MAX_MULT_LIMIT + 1];
    let mut largest = 0;
    for w in adj.opposite_start.windows(2) {
        let k = (w[1] - w[0]) as usize;
        histogram[k.min(MAX_MULT_LIMIT)] += 1;
        largest = largest.max(k);
    }
    if largest == 0 {
        return if adj.is_empty() { 0 } else { 1 };
    }
    let edges = adj.len();
    // Smallest c with at least 99.9 % of the edges having k <= c.
    let mut covered = 0;
    let mut quantile = MAX_MULT_LIMIT;
    for (c, &n) in histogram.iter().enumerate() {
        covered += n;
        if covered * 1000 >= edges * 999 {
            quantile = c;
            break;
        }
    }
    largest.min(limit).min(quantile.max(1))
}

/// The `maxMult` of a vertex layout with `attribs` vertex attributes (a record takes
/// `2 + maxMult` of them) and at most `max_mult_limit` slots: [`choose_max_mult`] under the
/// tightest of those and [`MAX_MULT_LIMIT`], at least 1. The one rule `vs-silhouette`'s layout
/// (umbra-gl) and the export buffers ([`crate::export_buffers`]) share.
pub fn max_mult_for_attribs(adj: &EdgeAdjacency, attribs: usize, max_mult_limit: usize) -> usize {
    let limit = max_mult_limit.min(MAX_MULT_LIMIT).min(attribs.saturating_sub(2)).max(1);
    choose_max_mult(adj, limit).max(1)
}

/// Builds the compact sides-data of `mesh` with `max_mult` opposite slots per record,
/// splitting edges with more opposites (see the module documentation).
pub fn build_sides_data(mesh: &WeldedMesh, adj: &EdgeAdjacency, max_mult: usize) -> Result<SidesData, SidesDataError> {
    if adj.is_empty() {
        return Ok(SidesData { max_mult, data: Vec::new(), source_edge: Vec::new() });
    }
    if max_mult == 0 || max_mult > MAX_MULT_LIMIT {
        return Err(SidesDataError::MaxMult(max_mult));
    }
    let p = &mesh.positions;
    let vertex = |edge: usize, i: u32| {
        p.get(i as usize).copied().ok_or(SidesDataError::EdgeVertex { edge, vertex: i, vertices: p.len() })
    };
    let stride = 2 + max_mult;
    let records = record_count(adj, max_mult);
    let mut data = Vec::with_capacity(records * stride);
    let mut source_edge = Vec::with_capacity(records);
    for (e, &[ia, ib]) in adj.edges.iter().enumerate() {
        let (a, b) = (vertex(e, ia)?, vertex(e, ib)?);
        let opposites = adj.opposites(e);
        // An edge without opposites (not produced by EdgeAdjacency::build) still gets one
        // empty record, multiplicity 0.
        let chunks: Vec<&[u32]> = if opposites.is_empty() { vec![&[]] } else { opposites.chunks(max_mult).collect() };
        let split = if chunks.len() > 1 { 1.0 } else { 0.0 };
        for chunk in chunks {
            data.push([a[0], a[1], a[2], chunk.len() as f32]);
            data.push([b[0], b[1], b[2], split]);
            for &o in chunk {
                let o = vertex(e, o)?;
                data.push([o[0], o[1], o[2], 1.0]);
            }
            data.resize(data.len() + max_mult - chunk.len(), [0.0; 4]);
            source_edge.push(e as u32);
        }
    }
    Ok(SidesData { max_mult, data, source_edge })
}

/// Builds the compact caps-data: per triangle its three vertices `(P_i, 1)`, `48 · t` bytes.
pub fn build_caps_data(mesh: &WeldedMesh) -> Result<Vec<[f32; 4]>, SidesDataError> {
    let p = &mesh.positions;
    let mut out = Vec::with_capacity(mesh.triangles.len() * 3);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &i in tri {
            let v = p.get(i as usize).ok_or(SidesDataError::TriangleVertex {
                triangle: t,
                vertex: i,
                vertices: p.len(),
            })?;
            out.push([v[0], v[1], v[2], 1.0]);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::multiplicity::edge_multiplicity;
    use crate::weld::tests::{reference_inputs, reference_lights};
    use crate::weld::weld;

    /// A fan of `k` triangles around the edge (0,0,0)-(1,0,0): one edge with `k` opposites.
    fn book(k: usize) -> WeldedMesh {
        let mut m = Mesh::default();
        m.positions.push([0.0, 0.0, 0.0]);
        m.positions.push([1.0, 0.0, 0.0]);
        for i in 0..k {
            let angle = 0.3 + 5.5 * i as f32 / k as f32;
            m.positions.push([0.5, angle.cos(), angle.sin()]);
            m.triangles.push([0, 1, 2 + i as u32]);
        }
        weld(&m)
    }

    #[test]
    fn eq8_and_eq9_byte_formulas() {
        // Paper 003's own example: e = 1000, maxMult = 3 -> 80000 bytes (Section 2.6).
        assert_eq!(sides_data_bytes(1000, 3), 80_000);
        assert_eq!(caps_data_bytes(1000), 48_000);
        assert_eq!(sides_data_bytes(0, 14), 0);
    }

    #[test]
    fn built_buffers_have_exactly_the_eq8_eq9_sizes() {
        for mesh in reference_inputs() {
            let w = weld(&mesh);
            let adj = EdgeAdjacency::build(&w);
            for max_mult in [1, 2, 3, 7, 14] {
                let s = build_sides_data(&w, &adj, max_mult).expect("valid mesh");
                assert_eq!(s.records(), record_count(&adj, max_mult));
                assert_eq!(s.bytes(), sides_data_bytes(s.records(), max_mult));
            }
            let c = build_caps_data(&w).expect("valid mesh");
            assert_eq!(c.len() * VEC4_BYTES, caps_data_bytes(w.triangles.len()));
        }
    }

    /// Every edge's records add up to its multiplicity (001 Alg. 3), for every split size.
    #[test]
    fn split_records_sum_to_the_edge_multiplicity() {
        let mut meshes: Vec<WeldedMesh> = reference_inputs().iter().map(weld).collect();
        meshes.push(book(40));
        let mut checked_splits = 0;
        for w in &meshes {
            let adj = EdgeAdjacency::build(w);
            for max_mult in [1, 2, 3, 14] {
                let s = build_sides_data(w, &adj, max_mult).expect("valid mesh");
                for light in reference_lights(w) {
                    let mut sums = vec![0i32; adj.len()];
                    for r in 0..s.records() {
                        sums[s.source_edge[r] as usize] += s.record_multiplicity(r, light);
                    }
                    for (e, &sum) in sums.iter().enumerate() {
                        let m = edge_multiplicity(&w.positions, adj.edges[e], adj.opposites(e), light);
                        assert_eq!(sum, m, "edge {e}, maxMult {max_mult}");
                        if adj.opposites(e).len() > max_mult {
                            checked_splits += 1;
                        }
                    }
                }
            }
        }
        assert!(checked_splits > 0);
    }

    #[test]
    fn forty_sheet_book_spine_splits_into_ceil_k_over_max_mult_records() {
        let w = book(40);
        let adj = EdgeAdjacency::build(&w);
        let spine = (0..adj.len()).find(|&e| adj.opposites(e).len() == 40).expect("spine edge");
        let s = build_sides_data(&w, &adj, 14).expect("valid mesh");
        let spine_records: Vec<usize> = (0..s.records()).filter(|&r| s.source_edge[r] as usize == spine).collect();
        assert_eq!(spine_records.len(), 3);
        let counts: Vec<f32> = spine_records.iter().map(|&r| s.record(r)[0][3]).collect();
        assert_eq!(counts, vec![14.0, 14.0, 12.0]);
        // B.w flags the split edge's records, and only those.
        for r in 0..s.records() {
            assert_eq!(s.record(r)[1][3], if s.source_edge[r] as usize == spine { 1.0 } else { 0.0 });
        }
        // Unused slots of the last record are zero.
        assert_eq!(s.record(spine_records[2])[2 + 12..], [[0.0; 4]; 2]);
    }

    #[test]
    fn record_ranges_split_like_the_sides_data() {
        for (mesh, max) in [(book(1), 1), (book(7), 3), (book(7), 7), (weld(&reference_inputs()[0]), 2)] {
            let adj = EdgeAdjacency::build(&mesh);
            let ranges: Vec<RecordRange> = record_ranges(&adj, max).collect();
            assert_eq!(ranges.len(), record_count(&adj, max), "max {max}");
            let sides = build_sides_data(&mesh, &adj, max).expect("valid");
            assert_eq!(sides.source_edge, ranges.iter().map(|r| r.edge as u32).collect::<Vec<_>>(), "max {max}");
            for e in 0..adj.len() {
                let of_edge: Vec<&RecordRange> = ranges.iter().filter(|r| r.edge == e).collect();
                // Consecutive, covering the edge's opposites exactly, all but the last full.
                let mut next = adj.opposite_start[e];
                for (i, r) in of_edge.iter().enumerate() {
                    assert_eq!(r.first, next);
                    assert!(r.count as usize <= max && (i + 1 == of_edge.len() || r.count as usize == max));
                    assert_eq!(r.split, of_edge.len() > 1);
                    next += r.count;
                }
                assert_eq!(next, adj.opposite_start[e + 1], "edge {e}, max {max}");
            }
        }
    }

    #[test]
    fn choose_max_mult_takes_the_common_case_not_the_rare_spine() {
        // 9 spheres (manifold: every edge has 2 opposites) and one 40-sheet book.
        let mut m = Mesh::default();
        for k in 0..9 {
            m.append(&crate::scene::uv_sphere([3.0 * k as f32, 0.0, 0.0], 1.0, 40, 25));
        }
        let spheres = weld(&m);
        let adj = EdgeAdjacency::build(&spheres);
        assert_eq!(choose_max_mult(&adj, 14), 2);
        let mut with_book = m.clone();
        let b = book(40);
        with_book.append(&Mesh { positions: b.positions.clone(), triangles: b.triangles.clone(), normals: None });
        let adj = EdgeAdjacency::build(&weld(&with_book));
        assert_eq!(adj.max_opposites(), 40);
        assert_eq!(choose_max_mult(&adj, 14), 2);
        // The book alone: 80 page edges with 1 opposite and the spine with 40, so 99.9 % of
        // the edges need the spine's count, capped by the limit.
        let adj = EdgeAdjacency::build(&book(40));
        assert_eq!(choose_max_mult(&adj, 14), 14);
        assert_eq!(choose_max_mult(&adj, 3), 3);
        assert_eq!(choose_max_mult(&EdgeAdjacency::default(), 14), 0);
    }

    #[test]
    fn invalid_max_mult_is_a_typed_error() {
        let w = book(3);
        let adj = EdgeAdjacency::build(&w);
        assert_eq!(build_sides_data(&w, &adj, 0), Err(SidesDataError::MaxMult(0)));
        assert_eq!(build_sides_data(&w, &adj, 15), Err(SidesDataError::MaxMult(15)));
    }

    #[test]
    fn out_of_range_vertex_is_a_typed_error() {
        let mut w = book(2);
        let adj = EdgeAdjacency::build(&w);
        w.positions.truncate(3);
        assert!(matches!(build_sides_data(&w, &adj, 2), Err(SidesDataError::EdgeVertex { .. })));
        assert!(matches!(build_caps_data(&w), Err(SidesDataError::TriangleVertex { triangle: 1, vertex: 3, .. })));
    }

    #[test]
    fn empty_mesh_has_empty_data() {
        let w = WeldedMesh::default();
        let adj = EdgeAdjacency::build(&w);
        let s = build_sides_data(&w, &adj, choose_max_mult(&adj, 14)).expect("empty is fine");
        assert_eq!(s.bytes(), 0);
        assert!(build_caps_data(&w).expect("empty is fine").is_empty());
    }
}
