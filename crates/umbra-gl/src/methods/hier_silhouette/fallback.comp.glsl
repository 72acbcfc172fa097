// hier-silhouette, per light: the faces a full queue turned away in the last redo round (redo
// list u_redo_in, hier/hierarchy.glsl descend_into), each counted whole by one invocation: the
// face against every top node and, depth-first, every bridge and sample below the nodes it may
// meet, with atomic additions (other invocations count the same nodes and samples). The
// generated chain inline_level{l} (mod.rs, fallback_chain) descends through nested loops of at
// most 64 iterations each: no recursion in GLSL, no loop near llvmpipe's 65,535. Normally the
// list is empty and this pass has no workgroup at all (indirect dispatch of args.comp.glsl's
// count). Its own program: llvmpipe runs untaken branches under a mask, so the chain inlined
// into the main passes would slow them down. Prepended: hier/hierarchy.glsl, hier/region.glsl,
// shared/multiplicity.glsl, faces.glsl, the chain.

layout(local_size_x = 64) in;

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
            inline_level(top, F, fr, node);
        }
    }
}
