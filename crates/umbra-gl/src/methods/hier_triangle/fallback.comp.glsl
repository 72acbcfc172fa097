// hier-triangle's hooks of the shared fallback walk (hier/walk.comp.glsl, appended after this
// file: the walk, its resumption across passes and its reasons): each triangle a full queue
// turned away in the last redo round is tested whole, its shadow frustum against every top
// node and, depth-first, down to the samples of every node it cuts (Sintorn et al. 2014's
// traversal, without the queues); a node it covers is marked covered (visit), a sample it
// shadows gets its bit. Prepended: hier/hierarchy.glsl, hier/region.glsl, frustum.glsl.

// The triangle being walked and its frustum (walk_begin).
uint g_tri;
Frustum g_frustum;

bool walk_begin(uint item) {
    g_tri = item;
    g_frustum = load_frustum(item);
    return true;
}

bool walk_top(uint node) {
    return visit(g_frustum, u_levels - 1u, node) == PARTIAL;
}

bool walk_child(uint level, uint node, uint child) {
    return visit(g_frustum, level - 1u, child) == PARTIAL;
}

void walk_sample(uint leaf, uint k) {
    test_sample(g_tri, leaf, k);
}
