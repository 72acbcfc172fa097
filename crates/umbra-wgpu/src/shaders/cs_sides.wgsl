// cs-silhouette: silhouette edges found by a compute shader and compacted for an indirect draw.
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.2 and its future work (a compute-shader
// silhouette); the twin of umbra-gl's cs_silhouette/sides.comp.glsl, except where the
// multiplicity comes from: Alg. 3 sums, over the edge's triangles, the orientation of each
// triangle wound A -> B -> O; that is the triangle's own orientation (computed once by
// orientation.wgsl) negated when the triangle runs B -> A (umbra_geom::silhouette::
// TriangleSlots: slot = t << 1 | against). Bit for bit what evaluating Alg. 4 here would give
// with `precise`, and the same value the caps read without it.
//
// One invocation per edge record: an edge with more than MAX_TRIANGLES_PER_RECORD (mod.rs)
// triangles is split into records over consecutive ranges of them, because lavapipe and
// llvmpipe (Mesa gallivm) silently end a shader loop after 65,535 iterations. A record emits
// the quads of its partial multiplicity with its own sign; the stencil counts of an edge's
// records add up to its multiplicity. Compaction: a record with m != 0 reserves |m| slots with
// one atomicAdd on the sides draw command's vertex count (6 per quad).
// Prepended: volume.wgsl (the light slot `u`: u.records; umbra_item, DrawCommand).

// Per edge record: (A, B, first slot, slot count), A < B in the vertex order.
@group(1) @binding(0) var<storage, read> records: array<vec4<u32>>;
@group(1) @binding(1) var<storage, read> slots: array<u32>;
@group(1) @binding(2) var<storage, read> orientation: array<i32>;
@group(1) @binding(3) var<storage, read_write> sides_command: DrawCommand;
// One record per side quad: (X, Y) vertex indices, the quad is Y X X_inf Y_inf
// (m > 0: X = A, Y = B; m < 0: X = B, Y = A).
@group(1) @binding(4) var<storage, read_write> quads: array<vec2<u32>>;

@compute @workgroup_size(256)
fn sides(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = umbra_item(gid, groups);
    if e >= u.records {
        return;
    }
    let record = records[e];
    var m = 0;
    for (var k = 0u; k < record.w; k++) {
        let slot = slots[record.z + k];
        let o = orientation[slot >> 1u];
        m += select(o, -o, (slot & 1u) != 0u);
    }
    if m == 0 {
        return;
    }
    let n = u32(abs(m));
    let first = atomicAdd(&sides_command.vertex_count, 6u * n) / 6u;
    let q = select(record.yx, record.xy, m > 0);
    for (var k = 0u; k < n; k++) {
        quads[first + k] = q;
    }
}
