// vs-silhouette: shadow-volume sides and caps evaluated in the vertex shader, paper 003
// (Milet et al., WebGL 1.0 shadows), Section 2: sides by Algorithm 1 (Eq. 1-5), caps by
// Algorithm 2 with the light cap shifted to infinity (Eq. 6); the twin of umbra-gl's
// vs_silhouette/sides.vert.glsl and caps.vert.glsl. Paper 003's draw structure: a fixed
// 6 * maxMult vertices per edge record and 6 (3 for a directional light) per triangle, useless
// vertices sent to UMBRA_CULLED, nothing compacted.
//
// Where the orientations come from (the one change WGSL forces, it has no `precise`): not
// from positions in the record (paper 003's sides-data) but from the orientation pass
// (orientation.wgsl, once per triangle and light): a record holds (A, B, first slot, count |
// split << 8) and the slots name the triangle behind each opposite vertex and its direction
// (umbra_geom::silhouette::TriangleSlots), so Alg. 1's curMult is the sum of +-orientation, the
// same bits every vertex of the record and every cap reads. The same for positions: no vertex
// is transformed here, every clip position comes from the transform pass.
// Prepended: `enable clip_distances;`, volume.wgsl.

// From the transform pass (transform.wgsl): clip[2 v] vertex v, clip[2 v + 1] it extruded.
@group(1) @binding(0) var<storage, read> clip: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read> records: array<vec4<u32>>;
@group(1) @binding(2) var<storage, read> slots: array<u32>;
@group(1) @binding(3) var<storage, read> orientation: array<i32>;
// The scene's index buffer: 3 vertex indices per triangle.
@group(1) @binding(4) var<storage, read> indices: array<u32>;

// Where a useless vertex goes (paper 003 Alg. 1 line 7 / Alg. 2 line 3 use (0,0,0,0)): beyond
// the right and top clip planes (x = y = 2w), so every triangle made of such vertices is
// rejected by the clip test before any setup (an all-zero vertex passes every clip test with
// equality and reaches triangle setup with 0/0 coordinates).
const UMBRA_CULLED = vec4<f32>(2.0, 2.0, 0.0, 1.0);

fn umbra_culled() -> UmbraVolumeVertex {
    return umbra_volume_vertex(UMBRA_CULLED, 1.0);
}

// Eq. 3-5 tables: which of P0 = A, P1 = B, P2 = A_inf, P3 = B_inf vertex v of a side is, up to
// the rotation of each triangle, chosen so that the triangles are exactly cpu-silhouette's:
//   curMult > 0 (id_CCW): (B, A, A_inf), (B, A_inf, B_inf) = quad B A A_inf B_inf;
//   curMult < 0 (id_CW):  (A, B, B_inf), (A, B_inf, A_inf) = quad A B B_inf A_inf.
// Records of a SPLIT edge may have opposite signs that must cancel in the stencil: their
// curMult < 0 sides are the curMult > 0 triangles with the last two vertices swapped,
// (B, A_inf, A), (B, B_inf, A_inf): the same first vertex and edges, so the rasterizer sets up
// the same coverage and depth plane, only the facing differs.
const UMBRA_ID_CCW = array<u32, 6>(1u, 0u, 2u, 1u, 2u, 3u);
const UMBRA_ID_CW = array<u32, 6>(0u, 1u, 3u, 0u, 3u, 2u);
const UMBRA_ID_CW_SPLIT = array<u32, 6>(1u, 2u, 0u, 1u, 3u, 2u);

@vertex
fn vs_sides(@builtin(vertex_index) vertex: u32) -> UmbraVolumeVertex {
    let per_record = 6u * u.max_mult;
    let r = vertex / per_record;
    let within = vertex % per_record;
    let s = within / 6u; // potential side of the record (Alg. 1 "s")
    let v = within % 6u; // vertex of the side (Eq. 4-5 "v")
    let rec = records[r];
    let count = rec.w & 0xFFu;
    let split = (rec.w >> 8u) != 0u;
    // Alg. 1, line 2: the record's (sub-)multiplicity, Alg. 3 as a sum of orientations.
    var m = 0;
    for (var k = 0u; k < count; k++) {
        let slot = slots[rec.z + k];
        let o = orientation[slot >> 1u];
        m += select(o, -o, (slot & 1u) != 0u);
    }
    if s >= u32(abs(m)) {
        // Alg. 1, line 7: useless vertex, degenerate side.
        return umbra_culled();
    }
    var id: u32;
    if m > 0 {
        id = UMBRA_ID_CCW[v];
    } else if split {
        id = UMBRA_ID_CW_SPLIT[v];
    } else {
        id = UMBRA_ID_CW[v];
    }
    // Eq. 1-2: P2, P3 extruded to infinity (w = 0); P0, P1 the edge itself (w = 1); both
    // transformed once by the transform pass.
    let i = select(rec.y, rec.x, id == 0u || id == 2u);
    return umbra_volume_vertex(clip[2u * i + select(0u, 1u, id >= 2u)], 1.0);
}

@vertex
fn vs_caps(@builtin(vertex_index) vertex: u32) -> UmbraVolumeVertex {
    let t = vertex / u.vertices_per_cap;
    let v = vertex % u.vertices_per_cap;
    // Alg. 2, line 1: the triangle's orientation, read (computed once by the orientation pass).
    let o = orientation[t];
    if o == 0 {
        // Alg. 2, lines 2-4: edge-on triangle, no cap (its edges' sides cancel too).
        return umbra_culled();
    }
    let tri = vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    // Alg. 2, lines 5-6: wind the cap to face the light (swap two vertices).
    let wound = select(tri.xzy, tri, o > 0);
    // Light cap P0 P1 P2 (v < 3); dark cap P2 P1 P0 extruded (Alg. 2, line 11: P_{5-v}).
    let k = select(5u - v, v, v < 3u);
    let i = wound[k];
    if v < 3u {
        // Alg. 2, lines 8-9 / Eq. 6, clipped at the near plane first.
        let p = clip[2u * i];
        return umbra_volume_vertex(umbra_push_to_far(p), umbra_near_distance(p));
    }
    return umbra_volume_vertex(clip[2u * i + 1u], 1.0);
}
