// hier-triangle, per light and level (u_pass_level >= 1), top-down: one invocation per (queued
// pair, child): the pair's triangle against one of the 16 children of its node (Sintorn et al.
// 2014, Section 4: the hierarchy traversed breadth-first, a frustum cutting a node is tested
// against its children). A child inside the frustum is marked covered, one it cuts is queued
// for the next level (or, when that queue is full, processed here: descend_into). Prepended: the
// header, common.glsl and the fallback chain. Dispatched indirectly (args.comp.glsl): 4 pairs
// per workgroup of 64, the group index spread over x and y.

layout(local_size_x = 64) in;

uniform uint u_pass_level;

void main() {
    uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint entry = group * (64u / CHILDREN) + gl_LocalInvocationIndex / CHILDREN;
    uint level = u_pass_level;
    if (entry >= min(state[4u * level], u_queue_capacity[level])) {
        return;
    }
    uvec2 pair = queue[u_level[level].w + entry];
    uint child;
    if (!child_of(level, pair.y, gl_LocalInvocationIndex % CHILDREN, child)) {
        return;
    }
    if (visit(pair.x, level - 1u, child) == PARTIAL) {
        descend_into(pair.x, level - 1u, child);
    }
}
