//! Edge patches: the input of the tessellation-shader silhouette (and, read as storage
//! buffers, of the geometry-shader silhouette).
//!
//! Paper 001, Section 2.2, Fig. 4-5: an input patch holds the edge's two vertices, the number
//! of its opposite vertices and the opposite vertices; the patch size is constant, so some
//! slots are unused; an element buffer indexes the model's vertex buffer, which only has to be
//! *extended* by vertices that carry the counts, so no vertex data is duplicated.
//!
//! Layout here, for `V` vertices, capacity `K` (opposite vertices per patch) and `P` patches:
//! * vertex buffer: `V + K` tightly packed `vec3` (12 bytes each): the welded positions
//!   `0..V`, then the count vertices `(k, 0, 0)` for `k = 1..=K` at index `V + k - 1`.
//!   (The paper extends the buffer by one vec4 per edge; a count vertex only carries a number,
//!   so patches with the same count share one through the element buffer, and the positions
//!   need no fourth component.)
//! * element buffer: `P` patches of `3 + K` u32 indices: `A, B, count vertex, O_1 .. O_n`,
//!   unused slots repeating `A` (never read by the shaders; `A` is already in the vertex cache).
//!
//! Total: `patch_bytes = 12 · (V + K) + 4 · (3 + K) · P`, with `V` = 1 + the largest vertex
//! index in the adjacency, `K = min(max_e n_e, limit)` and `P = Σ_edges ceil(n_e / K)`
//! (`n_e` = opposite vertices of edge e; `P` = the number of edges unless an edge has more than
//! `limit` opposites).
//!
//! Splitting: an edge with `n_e > K` opposite vertices becomes `ceil(n_e / K)` consecutive
//! patches, each holding the edge and up to `K` of its opposites. The multiplicity of an edge is
//! a sum of independent per-opposite terms (Alg. 3), so the patches' sub-multiplicities add up
//! to the edge's; each patch draws `|m_sub|` quads of sign `sgn(m_sub)`, and quads of opposite
//! sign over one edge are the same quad reversed, which cancel in the stencil count (but see
//! the choice of `K` for how exactly they cancel on a rasterizer). Any multiplicity works,
//! whatever the tessellation level or output-vertex limits.
//!
//! Choice of `K`: the largest number of opposite vertices of any edge, capped by `limit`
//! (from the GL limits, see [`ts_capacity_limit`], [`gs_capacity_limit`];
//! [`crate::methods::ts_silhouette::patch_bytes`] uses the limit implied by the GL 4.0
//! minimums, 29, which every GL 4.x implementation meets). So an edge is split only when the
//! GL forces it, like the paper's patch of "maxMultiplicity" opposite slots. Why not split
//! more eagerly to save bytes (K = 2 instead of 4 would shrink Sponza's from 12.5 to 9.4 MiB):
//! a split edge whose opposite vertices contribute with both signs draws a +1 and a -1 copy of
//! its quad, which cancel only if they rasterize to the same fragments with the same depths. They are two
//! different triangulations of the quad (cpu-silhouette's winding for each sign), and a sample
//! lying in the quad's plane - on a caster triangle edge-on to the light next to the edge -
//! can pass the depth test for one and fail it for the other: a wrong count over that whole
//! triangle, not just at a shadow boundary. (Crytek Sponza has such an edge: 4 opposite
//! vertices contributing +1, 0, 0, -1, the two 0s from a triangle edge-on to the light; with
//! K = 2 it drew a +1 and a -1 quad where cpu-silhouette draws none.) Splits forced by the
//! limit (edges with more than 29 opposite vertices for tessellation, 64 for the geometry
//! shader) keep that risk.

use umbra_geom::{EdgeAdjacency, WeldedMesh};

use crate::error::GlError;
use crate::methods::face_depth::FACE_DEPTH_COMPONENTS;

/// Bytes of one vertex of the vertex buffer (`vec3` of f32).
pub const VERTEX_BYTES: usize = 12;
/// Bytes of one element (u32 index).
pub const INDEX_BYTES: usize = 4;
/// Slots of a patch before the opposite vertices: A, B, count vertex.
pub const HEADER_SLOTS: usize = 3;

/// GL 4.0 minimum of GL_MAX_PATCH_VERTICES.
pub const MIN_MAX_PATCH_VERTICES: i32 = 32;
/// GL 4.0 minimum of GL_MAX_TESS_GEN_LEVEL.
pub const MIN_MAX_TESS_GEN_LEVEL: i32 = 64;
/// GL 3.2 minimum of GL_MAX_GEOMETRY_OUTPUT_VERTICES.
pub const MIN_MAX_GEOMETRY_OUTPUT_VERTICES: i32 = 256;
/// GL 3.2 minimum of GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS.
pub const MIN_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS: i32 = 1024;

/// Most opposite vertices a tessellation patch may hold: the patch has `3 + K` vertices
/// (`<= GL_MAX_PATCH_VERTICES`) and draws at most `K` quads with inner level `2K - 1`
/// (`<= GL_MAX_TESS_GEN_LEVEL`, paper 001 Section 2.3). 0 if no patch fits.
pub fn ts_capacity_limit(max_patch_vertices: i32, max_tess_gen_level: i32) -> usize {
    let by_vertices = max_patch_vertices.saturating_sub(HEADER_SLOTS as i32);
    let by_level = max_tess_gen_level.saturating_add(1) / 2;
    by_vertices.min(by_level).max(0) as usize
}

/// Most opposite vertices one geometry-shader invocation may handle: it emits up to `K`
/// quads as 4-vertex strips of `gl_Position` and the flat face depth, a `dvec3`
/// (gs_silhouette/sides.geom.glsl: 4 + 6 components per vertex, 40 per quad).
pub fn gs_capacity_limit(max_output_vertices: i32, max_total_output_components: i32) -> usize {
    let by_vertices = max_output_vertices / 4;
    let by_components = max_total_output_components / (4 * (4 + FACE_DEPTH_COMPONENTS));
    by_vertices.min(by_components).max(0) as usize
}

/// `V`: one more than the largest vertex index the adjacency uses (0 without edges): the
/// positions the patches index. (Every vertex of a triangle is an endpoint of its edges.)
pub fn vertex_count(adj: &EdgeAdjacency) -> usize {
    adj.edges.iter().flatten().chain(&adj.opposites).map(|&i| i as usize + 1).max().unwrap_or(0)
}

/// Number of patches with capacity `k` (`k >= 1`).
pub fn patch_count(adj: &EdgeAdjacency, k: usize) -> usize {
    adj.opposite_start.windows(2).map(|w| (w[1] - w[0]) as usize).map(|n| n.div_ceil(k)).sum()
}

/// `12 · (V + k) + 4 · (3 + k) · P(k)` (see the module documentation).
pub fn layout_bytes(vertices: usize, patches: usize, k: usize) -> usize {
    VERTEX_BYTES * (vertices + k) + INDEX_BYTES * (HEADER_SLOTS + k) * patches
}

/// `K = min(max_e n_e, limit)`, at least 1 (1 if `limit` is 0: the caller rejects that limit).
pub fn choose_capacity(adj: &EdgeAdjacency, limit: usize) -> usize {
    adj.max_opposites().min(limit).max(1)
}

/// Vertex and element buffers of the edge patches, built once per mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct EdgePatches {
    /// `K`, opposite vertices per patch.
    pub capacity: usize,
    /// `V` welded positions, then the `K` count vertices.
    pub vertices: Vec<[f32; 3]>,
    /// `P · (3 + K)` indices.
    pub elements: Vec<u32>,
}

impl EdgePatches {
    /// Lays out the patches of `adj` (built from `mesh`) with capacity `capacity >= 1`.
    /// Errors (typed, no panic) when an index is outside `mesh.positions` or the layout does
    /// not fit u32 indices.
    pub fn build(mesh: &WeldedMesh, adj: &EdgeAdjacency, capacity: usize) -> Result<Self, GlError> {
        if capacity == 0 {
            return Err(GlError::InvalidParams("edge patches: capacity 0 (no opposite vertex fits a patch)".into()));
        }
        let v = vertex_count(adj);
        if v > mesh.positions.len() {
            return Err(GlError::InvalidParams(format!(
                "edge patches: the adjacency indexes vertex {} but the mesh has {} positions",
                v - 1,
                mesh.positions.len()
            )));
        }
        let stride = HEADER_SLOTS + capacity;
        let patches = patch_count(adj, capacity);
        let total_vertices = v + capacity;
        if u32::try_from(total_vertices).is_err()
            || patches.checked_mul(stride).is_none_or(|n| i32::try_from(n).is_err())
        {
            return Err(GlError::InvalidParams(format!(
                "edge patches: {patches} patches of {stride} indices over {total_vertices} vertices exceed one draw call"
            )));
        }
        let mut vertices = Vec::with_capacity(total_vertices);
        vertices.extend_from_slice(&mesh.positions[..v]);
        vertices.extend((1..=capacity).map(|k| [k as f32, 0.0, 0.0]));
        let mut elements = Vec::with_capacity(patches * stride);
        for (e, &[a, b]) in adj.edges.iter().enumerate() {
            for chunk in adj.opposites(e).chunks(capacity) {
                elements.extend_from_slice(&[a, b, (v + chunk.len() - 1) as u32]);
                elements.extend_from_slice(chunk);
                elements.extend(std::iter::repeat_n(a, capacity - chunk.len()));
            }
        }
        debug_assert_eq!(elements.len(), patches * stride);
        Ok(Self { capacity, vertices, elements })
    }

    /// `3 + K`: indices per patch (GL_PATCH_VERTICES).
    pub fn stride(&self) -> usize {
        HEADER_SLOTS + self.capacity
    }

    /// `P`.
    pub fn patch_count(&self) -> usize {
        self.elements.len() / self.stride()
    }

    /// Bytes of the vertex buffer plus the element buffer.
    pub fn bytes(&self) -> usize {
        VERTEX_BYTES * self.vertices.len() + INDEX_BYTES * self.elements.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use umbra_geom::weld::weld;
    use umbra_geom::Mesh;

    /// `pages` triangles on the spine (0,0,0)-(1,0,0).
    fn book(pages: usize) -> WeldedMesh {
        let mut m = Mesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], ..Default::default() };
        for k in 0..pages {
            let a = k as f32 * 0.1;
            m.positions.push([0.5, a.cos(), a.sin()]);
            m.triangles.push([0, 1, 2 + k as u32]);
        }
        weld(&m)
    }

    #[test]
    fn split_edge_keeps_every_opposite_once() {
        let w = book(40);
        let adj = EdgeAdjacency::build(&w);
        let p = EdgePatches::build(&w, &adj, 3).unwrap();
        let v = vertex_count(&adj);
        assert_eq!(v, 42);
        // Spine: ceil(40 / 3) = 14 patches; the 80 page edges one each.
        assert_eq!(p.patch_count(), 14 + 80);
        assert_eq!(p.bytes(), layout_bytes(v, 14 + 80, 3));
        let mut spine_opposites = Vec::new();
        for patch in p.elements.chunks_exact(p.stride()) {
            let count = p.vertices[patch[2] as usize][0] as usize;
            assert!((1..=3).contains(&count));
            assert_eq!(patch[2] as usize, v + count - 1, "count vertex k sits at V + k - 1");
            if patch[..2] == [0, 1] {
                spine_opposites.extend_from_slice(&patch[3..3 + count]);
            }
            assert!(patch[3 + count..].iter().all(|&i| i == patch[0]), "padding repeats A");
        }
        assert_eq!(spine_opposites, (2..42).collect::<Vec<u32>>());
    }

    #[test]
    fn capacity_is_max_opposites_capped() {
        // A closed box: every edge has 2 opposites -> K = 2, no split.
        let cube = umbra_geom::scene::build(&umbra_geom::scene::parse("box").unwrap()).unwrap();
        let w = weld(&cube);
        let adj = EdgeAdjacency::build(&w);
        assert_eq!(adj.max_opposites(), 2);
        assert_eq!(choose_capacity(&adj, 29), 2);
        assert_eq!(patch_count(&adj, 2), adj.len());
        // A lone triangle: three open edges -> K = 1.
        assert_eq!(choose_capacity(&EdgeAdjacency::build(&book(1)), 29), 1);
        // 40 pages on one spine: capped by the limit, the spine split.
        let adj = EdgeAdjacency::build(&book(40));
        assert_eq!(choose_capacity(&adj, 29), 29);
        assert_eq!(patch_count(&adj, 29), 2 + 80);
        assert_eq!(choose_capacity(&adj, 64), 40);
        assert_eq!(choose_capacity(&adj, 0), 1);
    }

    #[test]
    fn limits_from_gl_minimums() {
        assert_eq!(ts_capacity_limit(MIN_MAX_PATCH_VERTICES, MIN_MAX_TESS_GEN_LEVEL), 29);
        assert_eq!(ts_capacity_limit(32, 16), 8);
        assert_eq!(ts_capacity_limit(3, 64), 0);
        assert_eq!(gs_capacity_limit(MIN_MAX_GEOMETRY_OUTPUT_VERTICES, MIN_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS), 25);
        assert_eq!(gs_capacity_limit(1024, 1024), 25);
        assert_eq!(gs_capacity_limit(1024, 16384), 256);
    }

    #[test]
    fn capacity_zero_is_an_error() {
        let w = book(2);
        let adj = EdgeAdjacency::build(&w);
        assert!(EdgePatches::build(&w, &adj, 0).is_err());
    }

    #[test]
    fn empty_mesh_has_only_count_vertices() {
        let w = weld(&Mesh::default());
        let adj = EdgeAdjacency::build(&w);
        let p = EdgePatches::build(&w, &adj, choose_capacity(&adj, 29)).unwrap();
        assert_eq!(p.patch_count(), 0);
        assert_eq!(p.bytes(), 12, "K = 1: one count vertex");
    }
}
