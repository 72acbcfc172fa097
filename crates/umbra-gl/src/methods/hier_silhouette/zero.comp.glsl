// hier-silhouette: sets the count words u_first .. u_count - 1 to 0 (once per light: the
// counters, bridge counts, sample counts and top counts). A compute pass because
// glClearBufferData is not among the entry points umbra loads. One invocation per word.
// Prepended: hier/hierarchy.glsl, hier/region.glsl, shared/multiplicity.glsl, faces.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_count;

void main() {
    uint i = u_first + gl_GlobalInvocationID.x;
    if (i < u_count) {
        counts[i] = 0;
    }
}
