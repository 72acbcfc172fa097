// hier-silhouette's fallback (shared code, with the method's hooks), per light: the items (its
// faces) a full queue turned away in the last redo round (redo list
// u_redo_in, hierarchy.glsl descend_into), each processed whole by one invocation: the item
// against every top node and, depth-first, down to the samples of every node its test cuts
// (Sintorn et al. 2014's traversal, without the queues). Normally the list is empty and the
// pass has no workgroup at all (indirect dispatch of args.comp.glsl's count). Its own program:
// llvmpipe runs untaken branches under a mask, so this code inlined into the main passes would
// slow them down. Prepended: the method's header, then the method's hooks (its own
// fallback.comp.glsl), which define
//   bool walk_begin(uint item)     loads the item into the hooks' globals; false: nothing to do;
//   bool walk_top(uint node)       the item against top node `node`; true: descend into it;
//   bool walk_child(uint level, uint node, uint child)
//                                  the item against child `child` (at level - 1) of inner node
//                                  `node` at `level` (child_of() said it exists); true: descend;
//   void walk_sample(uint leaf, uint k)
//                                  the item against sample k of leaf `leaf`.
//
// The walk is one loop of at most u_fallback_steps steps per pass; a step visits one child,
// one sample of a leaf, or leaves one node. llvmpipe gives a shader invocation 65,535 loop
// iterations IN ALL, shared by every loop of the shader (gallivm's loop limiter is one counter
// per function, not one per loop; measured: two loops of 40,000 iterations in one shader ran
// 40,000 and 25,534), and ends every loop silently once they are spent. A walk is far longer
// than that where an item's volume covers much of a large frame (hier-silhouette on Crytek
// Sponza at 3840 x 2160: the walks were cut short and thousands of samples were one count off,
// varying from run to run with the faces that the full queues turned away). So a walk that has
// not finished after u_fallback_steps steps writes its place back into its own entry of the
// list, and the next pass of this program (the same dispatch again) goes on from there; a
// finished walk marks its entry WALK_DONE, which later passes skip (hier/mod.rs
// Passes::fallback runs enough passes for the longest walk the hierarchy allows:
// hier/layout.rs fallback_passes). The place is the node the walk is at and its next child (or
// sample): the path to it is implied (each ancestor's next child is the one after the child on
// the path), so it packs into the entry's second word as ((next + 1) << PLACE_NODE_BITS) |
// global node index; 0 = a walk not begun. Where the walk is at the (virtual) root above the
// top nodes, having finished top node t, its place is "top node t, every child visited". The
// stack holds one (node, next) entry per level and one for the root. Entries are the
// invocations' own: no atomics needed. A hook's work is done once per (item, node or sample):
// a pass stops between steps, never inside one.
//
// The walk must not be written as nested constant-bound loops, one per level: NVIDIA's
// compiler unrolls those (16^7 bodies for 7 upper levels) and never finishes linking (found on
// an H100, driver 580).

layout(local_size_x = 64) in;

// Steps of one pass: hier/layout.rs FALLBACK_STEPS (well below llvmpipe's 65,535 loop
// iterations: the few other loop iterations of an invocation, the hooks' and the place's path
// below, fit beside them), or fewer where a test makes every walk resume many times.
uniform uint u_fallback_steps;
// PLACE_NODE_BITS (a global node index fits below that bit; the methods refuse a frame with
// more nodes) is defined by the header (hier/layout.rs).
const uint PLACE_NODE_MASK = (1u << PLACE_NODE_BITS) - 1u;
// A finished walk's entry (next + 1 = 31 is no place: next is at most 16).
const uint WALK_DONE = 0xFFFFFFFFu;

uint place(uint level, uint node, uint next) {
    return ((next + 1u) << PLACE_NODE_BITS) | node_index(level, node);
}

void main() {
    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    if (i >= state[REDO_CONTROL + 4u * u_redo_in]) {
        return;
    }
    uint slot = u_redo_offset + u_redo_in * u_triangles + i;
    uvec2 entry = queue[slot];
    if (entry.y == WALK_DONE) {
        return;
    }
    uint item = entry.x;
    if (!walk_begin(item)) {
        queue[slot] = uvec2(item, WALK_DONE);
        return;
    }
    uint top = u_levels - 1u;
    uint root = u_levels;
    uint top_nodes = u_level[top].x * u_level[top].y;
    uint stack_node[MAX_LEVELS + 1];
    uint stack_next[MAX_LEVELS + 1];
    stack_node[root] = 0u;
    stack_next[root] = 0u;
    uint l = root;
    if (entry.y != 0u) {
        // Resume: the level of the global node index, then the path up from it.
        uint g = entry.y & PLACE_NODE_MASK;
        l = 0u;
        for (uint j = 1u; j < MAX_LEVELS; ++j) {
            if (j <= top && g >= u_level[j].z) {
                l = j;
            }
        }
        stack_node[l] = g - u_level[l].z;
        stack_next[l] = (entry.y >> PLACE_NODE_BITS) - 1u;
        for (uint j = 1u; j < MAX_LEVELS; ++j) {
            if (j > l && j <= top) {
                uint below = stack_node[j - 1u];
                uint x = below % u_level[j - 1u].x;
                uint y = below / u_level[j - 1u].x;
                stack_node[j] = (y / BRANCH_SIDE) * u_level[j].x + x / BRANCH_SIDE;
                stack_next[j] = (y % BRANCH_SIDE) * BRANCH_SIDE + x % BRANCH_SIDE + 1u;
            }
        }
        stack_next[root] = stack_node[top] + 1u;
    }
    bool done = false;
    for (uint step = 0u; step < u_fallback_steps; ++step) {
        uint k = stack_next[l];
        if (l == root) {
            if (k == top_nodes) {
                done = true;
                break;
            }
            stack_next[root] = k + 1u;
            if (walk_top(k)) {
                l = top;
                stack_node[top] = k;
                stack_next[top] = 0u;
            }
        } else if (l == 0u) {
            if (k == LEAF_SAMPLES) {
                l = 1u;
                continue;
            }
            stack_next[0] = k + 1u;
            walk_sample(stack_node[0], k);
        } else {
            if (k == CHILDREN) {
                l += 1u;
                continue;
            }
            stack_next[l] = k + 1u;
            uint child;
            if (child_of(l, stack_node[l], k, child) && walk_child(l, stack_node[l], child)) {
                l -= 1u;
                stack_node[l] = child;
                stack_next[l] = 0u;
                if (l == 0u) {
                    count_work(WORK_LEAVES_TESTED, 1u);
                }
            }
        }
    }
    // Not finished: its place, for the next pass.
    uint at = l == root ? place(top, stack_next[root] - 1u, CHILDREN) : place(l, stack_node[l], stack_next[l]);
    queue[slot] = uvec2(item, done ? WALK_DONE : at);
}
