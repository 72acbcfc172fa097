// The view-sample hierarchy: fills a range of a buffer — the samples with "no sample" (u_what 0, once per
// frame before the sample pass) or the state words with 0 (u_what 1, once per light: queue
// counts, covered flags, leaf masks). A compute pass because glClearBufferData is not among the
// entry points umbra loads. One invocation per element. Prepended: hierarchy.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_count;
uniform uint u_what;

void main() {
    uint i = u_first + gl_GlobalInvocationID.x;
    if (i >= u_count) {
        return;
    }
    if (u_what == 0u) {
        samples[i] = uvec4(0u, 0u, 0u, NO_TRIANGLE);
    } else {
        state[i] = 0u;
    }
}
