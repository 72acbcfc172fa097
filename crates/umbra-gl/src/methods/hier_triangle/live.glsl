// hier-triangle: the global bitmask of live nodes (Sintorn et al. 2014, Section 5: a node found
// wholly inside a triangle's shadow is cleared for every later triangle). One word per node of
// every level, in the state buffer's per-node region (u_covered_offset), and one for the
// virtual root above the top nodes (state word ROOT_LIVE): bit k of a node's word is set while
// child k (a leaf's sample k) holds samples and not all of them are known to be shadowed. Set
// per light by init.comp.glsl; bits are only ever cleared (atomicAnd), so a clear is never
// lost and never undone. A sample is shadowed when its bit, or the bit of any node on its path
// to the root, is clear (resolve.frag.glsl). Prepended after hier/hierarchy.glsl,
// hier/region.glsl and frustum.glsl.

// The root's word: the control block's first word (hier-triangle has no queues to count).
const uint ROOT_LIVE = 0u;

// The live word of node `node` at `level`; level u_levels is the virtual root (node 0).
uint live_word(uint level, uint node) {
    return level >= u_levels ? ROOT_LIVE : u_covered_offset + node_index(level, node);
}

// The parent of node `node` at `level` (< u_levels) and the node's bit there: a top node is child
// `node` of the virtual root; any other node is child (y % 4) * 4 + x % 4 of the node above.
void parent_of(uint level, uint node, out uint parent, out uint k) {
    if (level + 1u >= u_levels) {
        parent = 0u;
        k = node;
        return;
    }
    uint x = node % u_level[level].x;
    uint y = node / u_level[level].x;
    parent = (y / BRANCH_SIDE) * u_level[level + 1u].x + x / BRANCH_SIDE;
    k = (y % BRANCH_SIDE) * BRANCH_SIDE + x % BRANCH_SIDE;
}

// Child k of node `node` at `level` (>= 1; u_levels: the virtual root, whose children are the
// top nodes), as an index at level - 1; false where there is none.
bool live_child(uint level, uint node, uint k, out uint child) {
    if (level >= u_levels) {
        child = k;
        return k < u_level[u_levels - 1u].x * u_level[u_levels - 1u].y;
    }
    return k < CHILDREN && child_of(level, node, k, child);
}

// Node `node` at `level` has no live sample left (wholly shadowed): its bit in its parent is
// cleared, and so on upwards while a parent is left with no live child. Exactly one caller
// sees a word become 0 (atomicAnd returns the old value), so each node is cleared in its
// parent once. At most MAX_LEVELS iterations.
void clear_node(uint level, uint node) {
    for (uint l = level; l < u_levels; ++l) {
        uint parent;
        uint k;
        parent_of(l, node, parent, k);
        uint bit = 1u << k;
        uint old = atomicAnd(state[live_word(l + 1u, parent)], ~bit);
        if ((old & bit) == 0u || (old & ~bit) != 0u) {
            return;
        }
        node = parent;
    }
}

// Child k of node `node` at `level` (u_levels: the root) against the triangle: cleared when
// inside its shadow, true when cut (to be entered). Only a live child is tested.
bool test_child(Frustum f, uint level, uint node, uint k) {
    if ((state[live_word(level, node)] & (1u << k)) == 0u) {
        return false;
    }
    uint child;
    if (!live_child(level, node, k, child)) {
        return false;
    }
    uint g = node_index(level - 1u, child);
    int c = classify_node(f, level - 1u, child, nodes[NODE_VEC4S * g], nodes[NODE_VEC4S * g + 1u]);
    count_work(WORK_NODES_TESTED, 1u);
    if (c != PARTIAL) {
        count_work(WORK_NODES_PRUNED, 1u);
    }
    if (c == INSIDE) {
        clear_node(level - 1u, child);
    }
    return c == PARTIAL;
}

// Sample k of leaf `leaf` against triangle `tri`: its bit cleared when shadowed (and the leaf
// cleared upwards when that was its last live sample). Only a live sample is tested; not one
// of `tri` itself, nor one within 2 eps of a point light (the reference's segment is empty).
void test_sample(uint tri, uint leaf, uint k) {
    uint word = live_word(0u, leaf);
    uint bit = 1u << k;
    uint pixel;
    if ((state[word] & bit) == 0u || !leaf_pixel(leaf, k, pixel)) {
        return;
    }
    uvec4 s = samples[pixel];
    if (s.w == tri) {
        return;
    }
    vec3 rel = uintBitsToFloat(s.xyz) - u_origin;
    float r = length(rel);
    if (u_light.w != 0.0 && !(r > 2.0 * u_eps)) {
        return;
    }
    if (shadows_sample(tri, rel, r)) {
        uint old = atomicAnd(state[word], ~bit);
        if ((old & bit) != 0u && (old & ~bit) == 0u) {
            clear_node(0u, leaf);
        }
    }
}
