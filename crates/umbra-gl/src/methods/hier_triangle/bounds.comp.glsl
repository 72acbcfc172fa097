// hier-triangle, per frame (once for all lights), bottom-up: the bounds of the view samples of
// each node (Sintorn et al. 2014, Section 4: the cluster hierarchy's nodes bound their samples
// in 3-D; axis-aligned boxes in world space here). Level 0: the samples of the leaf's 8 x 8
// pixels; above: the union of the 16 children. One invocation per node of level
// u_bounds_level. A node without samples gets count 0 (empty). Prepended: the header and
// common.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_bounds_level;

void main() {
    uint level = u_bounds_level;
    uint node = u_first + gl_GlobalInvocationID.x;
    if (node >= u_level[level].x * u_level[level].y) {
        return;
    }
    vec3 lo = vec3(3.0e38);
    vec3 hi = vec3(-3.0e38);
    float count = 0.0;
    if (level == 0u) {
        uint x0 = (node % u_level[0].x) * LEAF_SIDE;
        uint y0 = (node / u_level[0].x) * LEAF_SIDE;
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint x = x0 + k % LEAF_SIDE;
            uint y = y0 + k / LEAF_SIDE;
            if (x < u_frame.x && y < u_frame.y) {
                uvec4 s = samples[y * u_frame.x + x];
                if (s.w != NO_TRIANGLE) {
                    vec3 p = uintBitsToFloat(s.xyz);
                    lo = min(lo, p);
                    hi = max(hi, p);
                    count += 1.0;
                }
            }
        }
    } else {
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, node, k, child)) {
                uint g = node_index(level - 1u, child);
                vec4 c_lo = nodes[2u * g];
                if (c_lo.w > 0.0) {
                    lo = min(lo, c_lo.xyz);
                    hi = max(hi, nodes[2u * g + 1u].xyz);
                    count += c_lo.w;
                }
            }
        }
    }
    uint g = node_index(level, node);
    nodes[2u * g] = vec4(lo, count);
    nodes[2u * g + 1u] = vec4(hi, 0.0);
}
