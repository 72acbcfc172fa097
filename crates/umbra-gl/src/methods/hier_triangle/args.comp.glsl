// hier-triangle: the DispatchIndirectCommand of the pass that reads level u_args_level's queue:
// ceil(pairs / u_pairs_per_group) workgroups, at most 65,535 along x (the smallest
// GL_MAX_COMPUTE_WORK_GROUP_COUNT GL 4.5 allows), the rest along y. One invocation. Prepended:
// the header and common.glsl.

layout(local_size_x = 1) in;

uniform uint u_args_level;
uniform uint u_pairs_per_group;

void main() {
    uint level = u_args_level;
    uint pairs = min(state[4u * level], u_queue_capacity[level]);
    uint groups = (pairs + u_pairs_per_group - 1u) / u_pairs_per_group;
    uint x = min(groups, 65535u);
    state[4u * level + 1u] = x;
    state[4u * level + 2u] = x == 0u ? 1u : (groups + x - 1u) / x;
    state[4u * level + 3u] = 1u;
}
