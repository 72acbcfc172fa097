// hier-triangle, per light: the triangles a full queue turned away in the last redo round (redo
// list u_redo_in,
// hier/hierarchy.glsl descend_into), each processed whole by one invocation: its frustum against every
// top node and, depth-first, down to the samples (Sintorn et al. 2014's traversal, without the
// queues). The generated chain inline_level{l} (mod.rs, fallback_chain) descends through
// nested loops of at most 64 iterations each — no recursion in GLSL, and no loop near
// llvmpipe's 65,535. Normally the list is empty and this pass has no workgroup at all
// (indirect dispatch of args.comp.glsl's count). Prepended: hier/hierarchy.glsl,
// hier/region.glsl, frustum.glsl, the chain.

layout(local_size_x = 64) in;

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
            inline_level(top, tri, node);
        }
    }
}
