// hier-triangle, per light: the triangles a full queue turned away in the last redo round (redo
// list u_redo_in, hier/hierarchy.glsl descend_into), each processed whole by one invocation: its
// frustum against every top node and, depth-first, down to the samples (Sintorn et al. 2014's
// traversal, without the queues). Normally the list is empty and this pass has no workgroup at
// all (indirect dispatch of args.comp.glsl's count). Its own program: llvmpipe runs untaken
// branches under a mask, so this code inlined into the main passes would slow them down.
// Prepended: hier/hierarchy.glsl, hier/region.glsl, frustum.glsl.
//
// The depth-first walk keeps an explicit stack, one (node, next child) entry per level: GLSL
// has no recursion, and the walk must not be written as nested constant-bound loops, one per
// level: NVIDIA's compiler unrolls those (16^7 bodies for 7 upper levels) and never finishes
// linking (found on an H100, driver 580). One step visits one child or leaves one node.
// llvmpipe gives an invocation 65,535 loop iterations in all, every loop together, so a walk
// longer than that stops silently there (hier-silhouette's fallback, which met this at
// 3840x2160, resumes across passes; porting that here is open in issue 15).

layout(local_size_x = 64) in;

// Processes the pair (tri, node at `level`) whose node tri's frustum cuts, down to the samples.
void walk(uint tri, uint level, uint node) {
    Frustum f = load_frustum(tri);
    uint stack_node[MAX_LEVELS];
    uint stack_next[MAX_LEVELS];
    uint l = level;
    stack_node[l] = node;
    stack_next[l] = 0u;
    for (uint outer = 0u; outer < 65535u; ++outer) {
        for (uint inner = 0u; inner < 65535u; ++inner) {
            if (l == 0u) {
                for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
                    test_sample(tri, stack_node[0], k);
                }
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
            if (child_of(l, stack_node[l], k, child) && visit(f, l - 1u, child) == PARTIAL) {
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
    uint tri = queue[u_redo_offset + u_redo_in * u_triangles + i].x;
    uint top = u_levels - 1u;
    uint top_nodes = u_level[top].x * u_level[top].y;
    Frustum f = load_frustum(tri);
    for (uint node = 0u; node < top_nodes; ++node) {
        if (visit(f, top, node) == PARTIAL) {
            walk(tri, top, node);
        }
    }
}
