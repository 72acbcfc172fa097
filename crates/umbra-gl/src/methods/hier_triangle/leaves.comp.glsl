// hier-triangle, per light and batch: the exact per-sample test (frustum.glsl, shadows_sample)
// of each active leaf (one with pairs in this batch) against every triangle in its list (the
// pairs whose frustum cuts the leaf: Sintorn et al. 2014, Section 4, at the leaves each view
// sample is tested against the triangle's frustum). One workgroup per active leaf (indirect,
// args.comp.glsl), one invocation per sample, walking the leaf's list together (the same
// triangle in every invocation: coherent loads); a sample stops at its first shadowing
// triangle. llvmpipe gives an invocation 65,535 loop iterations in all, every loop together
// (gallivm's one loop limiter per shader function; docs/exactness.md, hier-silhouette): a list
// holds one pair per triangle of a batch (at most 4,096) or of a redo round's turned-away
// triangles, far below it on every measured frame; a longer list would be cut short silently
// (a known limit, docs/exactness.md). Afterwards the leaf is marked covered if
// all its samples are shadowed, and so is each ancestor whose non-empty children all are
// (the smaller triangles of later batches then skip them). Prepended: hier/hierarchy.glsl,
// hier/region.glsl, frustum.glsl.

layout(local_size_x = LEAF_SAMPLES) in;

void test_list(uint leaf) {
    uint k = gl_LocalInvocationIndex;
    uint pixel;
    if (!leaf_pixel(leaf, k, pixel)) {
        return;
    }
    uvec4 s = samples[pixel];
    if (s.w == NO_TRIANGLE) {
        return;
    }
    vec3 rel = uintBitsToFloat(s.xyz) - u_origin;
    float r = length(rel);
    if (u_light.w != 0.0 && !(r > 2.0 * u_eps)) {
        return;
    }
    uint word = u_bits_offset + leaf;
    uint bit = 1u << k;
    if ((state[word] & bit) != 0u) {
        return;
    }
    uint link = state[u_heads_offset + leaf];
    for (uint outer = 0u; outer < 65535u && link != 0u; ++outer) {
        for (uint inner = 0u; inner < 65535u && link != 0u; ++inner) {
            uvec2 pair = queue[u_level[0].w + link - 1u];
            if (pair.x != s.w && shadows_sample(pair.x, rel, r)) {
                atomicOr(state[word], bit);
                return;
            }
            link = pair.y;
        }
    }
}

void main() {
    uint i = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (i >= state[ACTIVE_CONTROL]) {
        return;
    }
    uint leaf = state[u_active_offset + i];
    if (covered_from_above(0u, leaf)) {
        return;
    }
    test_list(leaf);
    memoryBarrierBuffer();
    barrier();
    if (gl_LocalInvocationIndex != 0u) {
        return;
    }
    uint valid = state[u_valid_offset + leaf];
    if (valid == 0u || (state[u_bits_offset + leaf] & valid) != valid) {
        return;
    }
    state[u_covered_offset + node_index(0u, leaf)] = 1u;
    // Upwards while every non-empty child of the parent is covered (racing with other leaves
    // only loses this shortcut, never correctness: a node is marked only when all is shadowed).
    uint node = leaf;
    for (uint level = 1u; level < u_levels; ++level) {
        uint parent = (node / u_level[level - 1u].x / BRANCH_SIDE) * u_level[level].x
            + (node % u_level[level - 1u].x) / BRANCH_SIDE;
        bool all = true;
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, parent, k, child)) {
                uint c = node_index(level - 1u, child);
                all = all && (nodes[NODE_VEC4S * c].w > nodes[NODE_VEC4S * c + 1u].w || state[u_covered_offset + c] != 0u);
            }
        }
        if (!all) {
            return;
        }
        state[u_covered_offset + node_index(level, parent)] = 1u;
        node = parent;
    }
}
