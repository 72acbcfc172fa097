// hier-silhouette, per light: the faces a full queue turned away in the last redo round (redo
// list u_redo_in, hier/hierarchy.glsl descend_into), each counted whole by one invocation: the
// face against every top node and, depth-first, every bridge and sample below the nodes it may
// meet, with atomic additions (other invocations count the same nodes and samples). Normally
// the list is empty and this pass has no workgroup at all (indirect dispatch of args.comp.glsl's
// count). Its own program: llvmpipe runs untaken branches under a mask, so this code inlined
// into the main passes would slow them down. Prepended: hier/hierarchy.glsl, hier/region.glsl,
// shared/multiplicity.glsl, faces.glsl.
//
// The depth-first walk keeps an explicit stack, one (node, next child) entry per level: GLSL
// has no recursion, and the walk must not be written as nested constant-bound loops, one per
// level: NVIDIA's compiler unrolls those (16^7 bodies for 7 upper levels) and never finishes
// linking (found on an H100, driver 580). The walk is two nested loops of at most 65,535 steps
// each (llvmpipe silently ends a loop after 65,535 iterations; one step visits one child or
// leaves one node, so no real walk comes near 65,535^2).

layout(local_size_x = 64) in;

// The samples of leaf `node`: each one's crossings from the leaf's point.
void count_leaf(Face F, uint node) {
    vec3 cp = node_point(0u, node);
    for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
        uint x = (node % u_level[0].x) * LEAF_SIDE + k % LEAF_SIDE;
        uint y = (node / u_level[0].x) * LEAF_SIDE + k / LEAF_SIDE;
        if (x >= u_frame.x || y >= u_frame.y) {
            continue;
        }
        uint pixel = y * u_frame.x + x;
        uvec4 s = samples[pixel];
        if (s.w == NO_TRIANGLE) {
            continue;
        }
        int c = sample_crossings(F, cp, count_point(uintBitsToFloat(s.xyz), s.w));
        if (c != 0) {
            atomicAdd(counts[u_counts_partial + pixel], c);
        }
    }
}

// Counts face F below `node` at `level`, a node it may meet: every bridge from a node to a
// non-empty child, and the samples of every leaf reached.
void walk(Face F, Frustum fr, uint level, uint node) {
    uint stack_node[MAX_LEVELS];
    uint stack_next[MAX_LEVELS];
    uint l = level;
    stack_node[l] = node;
    stack_next[l] = 0u;
    for (uint outer = 0u; outer < 65535u; ++outer) {
        for (uint inner = 0u; inner < 65535u; ++inner) {
            if (l == 0u) {
                count_leaf(F, stack_node[0]);
                l = 1u;
                if (l > level) {
                    return;
                }
                continue;
            }
            uint k = stack_next[l];
            if (k == CHILDREN) {
                l += 1u;
                if (l > level) {
                    return;
                }
                continue;
            }
            stack_next[l] = k + 1u;
            uint child;
            if (!child_of(l, stack_node[l], k, child)) {
                continue;
            }
            uint g = node_index(l - 1u, child);
            if (nodes[NODE_VEC4S * g].w > nodes[NODE_VEC4S * g + 1u].w) {
                continue;
            }
            int c = bridge_crossings(F, node_point(l, stack_node[l]), node_point(l - 1u, child));
            if (c != 0) {
                atomicAdd(counts[u_counts_bridges + g], c);
            }
            if (classify_face(fr, F.quad, l - 1u, child) == PARTIAL) {
                l -= 1u;
                stack_node[l] = child;
                stack_next[l] = 0u;
            }
        }
    }
}

void main() {
    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
    if (i >= state[REDO_CONTROL + 4u * u_redo_in]) {
        return;
    }
    uint f = queue[u_redo_offset + u_redo_in * u_triangles + i].x;
    Face F = load_face(f);
    if (F.weight == 0) {
        return;
    }
    Frustum fr = face_frustum(F);
    uint top = u_levels - 1u;
    uint top_nodes = u_level[top].x * u_level[top].y;
    for (uint node = 0u; node < top_nodes; ++node) {
        if (classify_face(fr, F.quad, top, node) == PARTIAL) {
            walk(F, fr, top, node);
        }
    }
}
