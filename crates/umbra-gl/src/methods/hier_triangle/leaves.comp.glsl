// hier-triangle, per light: the exact per-sample test (common.glsl, test_sample) of every
// queued (triangle, leaf) pair: one workgroup per pair, one invocation per sample of the leaf
// (Sintorn et al. 2014, Section 4: at the leaves each view sample is tested against the
// triangle's frustum). Leaves covered by then (here or above) are skipped whole. Prepended:
// the header and common.glsl. Dispatched indirectly (args.comp.glsl).

layout(local_size_x = 64) in;

void main() {
    uint entry = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (entry >= min(state[0], u_queue_capacity[0])) {
        return;
    }
    uvec2 pair = queue[u_level[0].w + entry];
    if (covered_from_above(0u, pair.y)) {
        return;
    }
    test_sample(pair.x, pair.y, gl_LocalInvocationIndex);
}
