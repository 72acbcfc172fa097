// hier-triangle, per frame (once for all lights), bottom-up: the bounds of the view samples of
// each node (Sintorn et al. 2014, Section 4: the cluster hierarchy's nodes bound their samples
// in 3-D): here the axis-aligned box of their world positions and the range of their clip w
// (view depth), which with the node's screen tile bounds them in a frustum slab (common.glsl).
// Level 0: the samples of the leaf's pixels (and the mask of the samples present); above: the
// union of the 16 children. One
// invocation per node of level u_bounds_level. A node without samples is empty (w_min > w_max).
// A sample's w is computed in f32: the range is widened by 2^-20 of the magnitudes involved.
// Prepended: the header and common.glsl.

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
    vec2 w = vec2(3.0e38, -3.0e38);
    uint valid = 0u;
    if (level == 0u) {
        uint x0 = (node % u_level[0].x) * LEAF_SIDE;
        uint y0 = (node / u_level[0].x) * LEAF_SIDE;
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint x = x0 + k % LEAF_SIDE;
            uint y = y0 + k / LEAF_SIDE;
            if (x < u_frame.x && y < u_frame.y) {
                uvec4 s = samples[y * u_frame.x + x];
                if (s.w != NO_TRIANGLE) {
                    valid |= 1u << k;
                    vec3 p = uintBitsToFloat(s.xyz);
                    lo = min(lo, p);
                    hi = max(hi, p);
                    float pw = dot(u_view_w.xyz, p) + u_view_w.w;
                    float tol = (dot(abs(u_view_w.xyz), abs(p)) + abs(u_view_w.w)) * (1.0 / 1048576.0);
                    w = vec2(min(w.x, pw - tol), max(w.y, pw + tol));
                }
            }
        }
    } else {
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, node, k, child)) {
                uint g = node_index(level - 1u, child);
                vec4 c_lo = nodes[3u * g];
                vec4 c_hi = nodes[3u * g + 1u];
                if (c_lo.w <= c_hi.w) {
                    lo = min(lo, c_lo.xyz);
                    hi = max(hi, c_hi.xyz);
                    w = vec2(min(w.x, c_lo.w), max(w.y, c_hi.w));
                }
            }
        }
    }
    if (level == 0u) {
        state[u_valid_offset + node] = valid;
    }
    uint g = node_index(level, node);
    nodes[3u * g] = vec4(lo, w.x);
    nodes[3u * g + 1u] = vec4(hi, w.y);
}
