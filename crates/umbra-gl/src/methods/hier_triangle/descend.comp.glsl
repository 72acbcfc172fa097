// hier-triangle, per light and level (u_pass_level >= 1), top-down: one invocation per queued
// pair: the pair's triangle against the 16 children of its node (Sintorn et al. 2014, Section
// 4: the hierarchy traversed breadth-first, a frustum cutting a node is tested against its
// children), the triangle's data loaded once. A child inside the frustum is marked covered,
// one it cuts is queued for the next level (descend_into). Prepended: hier/hierarchy.glsl,
// hier/region.glsl, frustum.glsl. Dispatched indirectly (args.comp.glsl): 64 pairs per
// workgroup, the group index spread over x and y.

layout(local_size_x = 64) in;

uniform uint u_pass_level;

void main() {
    uint entry = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    uint level = u_pass_level;
    if (entry >= min(state[4u * level], u_queue_capacity[level])) {
        return;
    }
    uvec2 pair = queue[u_level[level].w + entry];
    if (covered_from_above(level, pair.y)) {
        return;
    }
    Frustum f = load_frustum(pair.x);
    for (uint k = 0u; k < CHILDREN; ++k) {
        uint child;
        if (child_of(level, pair.y, k, child) && visit(f, level - 1u, child) == PARTIAL) {
            descend_into(pair.x, level - 1u, child);
        }
    }
}
