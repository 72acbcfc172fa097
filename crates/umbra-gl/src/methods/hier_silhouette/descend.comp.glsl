// hier-silhouette, per light and level (u_pass_level >= 1), top-down: one invocation per queued
// pair (face, node): the face against the node's 16 children (RSSV's traversal; Sintorn et al.
// 2014, Section 4, breadth-first): the bridge from the node's point to each child's point
// (faces.glsl bridge_crossings: the face's signed crossings, added to the child's bridge count)
// and the child's bounds (classify_face: a child the face may meet is queued for the next
// level). The face can only cross bridges inside nodes it meets: every bridge below a node lies
// within the node's bounds. The face's data is loaded and its bounds computed once per pair.
// With u_negate (a face turned away by a full queue: its redo flag is set), the same bridges
// are subtracted and nothing is queued: the face is counted again, whole, by the redo rounds.
// Dispatched indirectly (args.comp.glsl): 64 pairs per workgroup, the group index spread over x
// and y. Prepended: hier/hierarchy.glsl, hier/region.glsl, shared/multiplicity.glsl,
// faces.glsl.

layout(local_size_x = 64) in;

uniform uint u_pass_level;
uniform uint u_negate;

void main() {
    uint entry = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    uint level = u_pass_level;
    if (entry >= min(state[4u * level], u_queue_capacity[level])) {
        return;
    }
    uvec2 pair = queue[u_level[level].w + entry];
    bool turned_away = (state[u_redo_flags_offset + pair.x / 32u] & (1u << (pair.x % 32u))) != 0u;
    if (u_negate != 0u && !turned_away) {
        return;
    }
    Face F = load_face(pair.x);
    Frustum fr;
    if (u_negate == 0u) {
        fr = face_frustum(F);
    }
    vec3 cp = node_point(level, pair.y);
    for (uint k = 0u; k < CHILDREN; ++k) {
        uint child;
        if (!child_of(level, pair.y, k, child)) {
            continue;
        }
        uint g = node_index(level - 1u, child);
        if (nodes[NODE_VEC4S * g].w > nodes[NODE_VEC4S * g + 1u].w) {
            continue;
        }
        int x = bridge_crossings(F, cp, node_point(level - 1u, child));
        if (x != 0) {
            atomicAdd(counts[u_counts_bridges + g], u_negate != 0u ? -x : x);
        }
        if (u_negate == 0u && classify_face(fr, F.quad, level - 1u, child) == PARTIAL) {
            descend_into(pair.x, level - 1u, child);
        }
    }
}
