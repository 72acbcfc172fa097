// hier-silhouette, per light, one invocation per pixel: a sample's count W = W at its top node's
// point (setup) + the bridge counts of its ancestors from the top node's children down to its
// leaf (each: the crossings from the parent's point to the node's) + the crossings from its
// leaf's point to it (leaves, fallback): the winding number of the shadow volumes at the
// sample, just in front of its surface — cpu-silhouette's z-fail count there. Written over the
// sample's partial count. Prepended: hier/hierarchy.glsl, hier/region.glsl,
// shared/multiplicity.glsl, faces.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;

void main() {
    uint pixel = u_first + gl_GlobalInvocationID.x;
    if (pixel >= u_frame.x * u_frame.y) {
        return;
    }
    if (samples[pixel].w == NO_TRIANGLE) {
        return;
    }
    uint x = (pixel % u_frame.x) / LEAF_SIDE;
    uint y = (pixel / u_frame.x) / LEAF_SIDE;
    int w = counts[u_counts_partial + pixel];
    uint top = u_levels - 1u;
    for (uint l = 0u; l < top; ++l) {
        w += counts[u_counts_bridges + node_index(l, y * u_level[l].x + x)];
        x /= BRANCH_SIDE;
        y /= BRANCH_SIDE;
    }
    w += counts[u_counts_top + y * u_level[top].x + x];
    counts[u_counts_partial + pixel] = w;
}
