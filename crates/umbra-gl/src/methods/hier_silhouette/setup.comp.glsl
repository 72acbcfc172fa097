// hier-silhouette, per light and batch, one invocation per face of the batch (faces u_first ..
// u_batch_end - 1) or of a redo round's list: the face's weight — a triangle's orientation
// towards the light (umbra_triangle_orientation, paper 001 Alg. 4 through the reference edge)
// or an edge record's multiplicity (Alg. 3, umbra_opposite_contribution over its opposites,
// at most 16,384 of them, with the top nodes' loop below llvmpipe's 65,535 loop iterations per
// invocation, all loops together) — bit for bit
// cpu-silhouette's; then, for a light cap, its crossings of the segment from the light to each
// top node's point (W there, faces.glsl light_crossings); then the face against each top node,
// queuing the pairs it may cut (hier/hierarchy.glsl descend_into). A redo round (u_from_redo)
// only queues again: the weight and the top counts were made by the batch. Prepended:
// hier/hierarchy.glsl, hier/region.glsl, shared/multiplicity.glsl, faces.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_batch_end;
// 1: a redo round: the faces of redo list u_redo_in (indirect dispatch), not a batch.
uniform uint u_from_redo;

void main() {
    uint f;
    if (u_from_redo != 0u) {
        uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
        if (i >= state[REDO_CONTROL + 4u * u_redo_in]) {
            return;
        }
        f = queue[u_redo_offset + u_redo_in * u_triangles + i].x;
    } else {
        f = u_first + gl_GlobalInvocationID.x;
        if (f >= u_batch_end) {
            return;
        }
        if (f < u_caps) {
            counts[u_counts_orient + f] = umbra_triangle_orientation(position(indices[3u * f]),
                position(indices[3u * f + 1u]), position(indices[3u * f + 2u]), u_light);
        } else {
            uint r = f - u_caps;
            vec3 a = position(edges[4u * r]);
            vec3 b = position(edges[4u * r + 1u]);
            uint first = u_opposites_offset + edges[4u * r + 2u];
            uint n = edges[4u * r + 3u];
            int m = 0;
            for (uint k = 0u; k < n; ++k) {
                m += umbra_opposite_contribution(a, b, position(edges[first + k]), u_light);
            }
            counts[u_counts_mult + r] = m;
        }
    }
    Face F = load_face(f);
    if (F.weight == 0) {
        return;
    }
    Frustum fr = face_frustum(F);
    uint top = u_levels - 1u;
    uint top_nodes = u_level[top].x * u_level[top].y;
    for (uint node = 0u; node < top_nodes; ++node) {
        uint g = node_index(top, node);
        if (nodes[NODE_VEC4S * g].w > nodes[NODE_VEC4S * g + 1u].w) {
            continue;
        }
        if (u_from_redo == 0u && !F.quad) {
            int x = light_crossings(F, node_point(top, node));
            if (x != 0) {
                atomicAdd(counts[u_counts_top + node], x);
            }
        }
        if (classify_face(fr, F.quad, top, node) == PARTIAL) {
            descend_into(f, top, node);
        }
    }
}
