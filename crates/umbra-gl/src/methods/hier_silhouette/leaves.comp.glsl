// hier-silhouette, per light and batch: each active leaf (one with pairs in this batch) against
// its list of faces: per sample, the signed crossings of the bridge from the leaf's point to the
// sample's count point (faces.glsl count_point, sample_crossings), summed over the list and
// added to the sample's count.
// Faces turned away by a full queue (their redo flag set) are skipped: the redo rounds count
// them whole. One workgroup per active leaf (indirect, args.comp.glsl), one invocation per
// sample, walking the list together (the same face in every invocation: coherent loads).
// llvmpipe gives an invocation 65,535 loop iterations in all, every loop of the shader together
// (fallback.comp.glsl): a list holds at most one pair per face of the batch (BATCH, 4,096) or
// of the redo round's input list (the faces turned away, thousands at most on the shared scenes
// at 3840 x 2160), far below it. A sample's count is written by its own invocation
// only (a leaf is listed once per batch): no atomic needed. Prepended: hier/hierarchy.glsl,
// hier/region.glsl, shared/multiplicity.glsl, faces.glsl.

layout(local_size_x = LEAF_SAMPLES) in;

void main() {
    uint i = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (i >= state[ACTIVE_CONTROL]) {
        return;
    }
    uint leaf = state[u_active_offset + i];
    uint k = gl_LocalInvocationIndex;
    uint pixel;
    if (!leaf_pixel(leaf, k, pixel)) {
        return;
    }
    uvec4 s = samples[pixel];
    if (s.w == NO_TRIANGLE) {
        return;
    }
    vec3 sp = count_point(uintBitsToFloat(s.xyz), s.w);
    vec3 cp = node_point(0u, leaf);
    int sum = 0;
    uint link = state[u_heads_offset + leaf];
    for (uint outer = 0u; outer < 65535u && link != 0u; ++outer) {
        for (uint inner = 0u; inner < 65535u && link != 0u; ++inner) {
            uvec2 pair = queue[u_level[0].w + link - 1u];
            if ((state[u_redo_flags_offset + pair.x / 32u] & (1u << (pair.x % 32u))) == 0u) {
                sum += sample_crossings(load_face(pair.x), cp, sp);
            }
            link = pair.y;
        }
    }
    if (sum != 0) {
        counts[u_counts_partial + pixel] += sum;
    }
}
