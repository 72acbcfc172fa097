// The view-sample hierarchy: the DispatchIndirectCommand of the pass that reads a list whose count is
// state[u_args_word] (a level's queue, clamped to u_args_capacity; the active leaves; a redo
// list): ceil(entries / u_pairs_per_group) workgroups, at most 65,535 along x (the smallest
// GL_MAX_COMPUTE_WORK_GROUP_COUNT GL 4.5 allows), the rest along y, written to the three words
// after the count. With a gate (u_args_gate a state word, not 0xFFFFFFFF), no workgroup at all
// while that word is 0 (hier-silhouette's passes that only matter once a queue overflowed).
// One invocation. Prepended: hierarchy.glsl.

layout(local_size_x = 1) in;

uniform uint u_args_word;
uniform uint u_args_capacity;
uniform uint u_pairs_per_group;
uniform uint u_args_gate;

void main() {
    uint w = u_args_word;
    uint pairs = min(state[w], u_args_capacity);
    if (u_args_gate != 0xFFFFFFFFu && state[u_args_gate] == 0u) {
        pairs = 0u;
    }
    uint groups = (pairs + u_pairs_per_group - 1u) / u_pairs_per_group;
    uint x = min(groups, 65535u);
    state[w + 1u] = x;
    state[w + 2u] = x == 0u ? 1u : (groups + x - 1u) / x;
    state[w + 3u] = 1u;
}
