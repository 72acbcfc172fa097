// hier-silhouette's hooks of the shared fallback walk (hier/walk.comp.glsl, appended after
// this file: the walk, its resumption across passes and its reasons): each face a full queue
// turned away in the last redo round is counted whole, against every top node and,
// depth-first, every bridge and sample below the nodes it may meet, with atomic additions
// (other invocations count the same nodes and samples). Prepended: hier/hierarchy.glsl,
// hier/region.glsl, shared/multiplicity.glsl, faces.glsl.

// The face being walked and its frustum (walk_begin).
Face g_face;
Frustum g_frustum;

bool walk_begin(uint item) {
    g_face = load_face(item);
    if (g_face.weight == 0) {
        return false;
    }
    g_frustum = face_frustum(g_face);
    return true;
}

// The root's children are the top nodes (their counts W come from setup: no bridge).
bool walk_top(uint node) {
    return classify_face(g_frustum, g_face.quad, u_levels - 1u, node) == PARTIAL;
}

// The bridge from the node's point into the child's (an empty child has none), then the child.
bool walk_child(uint level, uint node, uint child) {
    uint g = node_index(level - 1u, child);
    if (nodes[NODE_VEC4S * g].w > nodes[NODE_VEC4S * g + 1u].w) {
        return false;
    }
    int c = bridge_crossings(g_face, node_point(level, node), node_point(level - 1u, child));
    if (c != 0) {
        atomicAdd(counts[u_counts_bridges + g], c);
    }
    return classify_face(g_frustum, g_face.quad, level - 1u, child) == PARTIAL;
}

// Sample k of leaf `leaf`: its crossings from the leaf's point.
void walk_sample(uint leaf, uint k) {
    uint pixel;
    if (!leaf_pixel(leaf, k, pixel)) {
        return;
    }
    uvec4 s = samples[pixel];
    if (s.w == NO_TRIANGLE) {
        return;
    }
    int c = sample_crossings(g_face, node_point(0u, leaf), count_point(uintBitsToFloat(s.xyz), s.w));
    if (c != 0) {
        atomicAdd(counts[u_counts_partial + pixel], c);
    }
}
