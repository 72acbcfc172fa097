// The view-sample hierarchy, per frame (once for all lights), bottom-up: the bounds of the view
// samples of each node (Sintorn et al. 2014, Section 4: the cluster hierarchy's nodes bound
// their samples in 3-D): here the axis-aligned box of their world positions and the range of
// their clip w (view depth), which with the node's screen tile bounds them in a frustum slab
// (region.glsl). Level 0: the samples of the leaf's pixels (first moved onto their own
// triangle's plane, and the mask of the samples present); above: the union of the 16
// children. One invocation per node of level u_bounds_level. A node without samples is empty
// (w_min > w_max). A sample's w is computed in f32: the range is widened by 2^-20 of the
// magnitudes involved. With LIFT (hier-silhouette) the bounds also hold every sample's lifted
// point (hierarchy.glsl, lifted()) and each node gets its own point: the lifted point of its
// most central sample (a leaf) or its most central non-empty child's point (above), so that
// a node's point, its descendants' points and its samples all lie within its bounds.
// Prepended: hierarchy.glsl.

layout(local_size_x = 64) in;

// The sample moved onto its own triangle's plane, in double precision, as the reference does
// before its segment test (crates/umbra-oracle, reference.rs): the interpolated position lies
// off the plane by rounding, and where a neighbour meets the segment at a grazing angle that
// offset, divided by the angle, can put the hit beyond eps. A degenerate triangle keeps it.
vec3 on_own_plane(uvec4 s) {
    dvec3 p = dvec3(uintBitsToFloat(s.xyz));
    uint t = s.w;
    dvec3 a = dvec3(positions[3u * indices[3u * t]], positions[3u * indices[3u * t] + 1u],
                    positions[3u * indices[3u * t] + 2u]);
    dvec3 b = dvec3(positions[3u * indices[3u * t + 1u]], positions[3u * indices[3u * t + 1u] + 1u],
                    positions[3u * indices[3u * t + 1u] + 2u]);
    dvec3 c = dvec3(positions[3u * indices[3u * t + 2u]], positions[3u * indices[3u * t + 2u] + 1u],
                    positions[3u * indices[3u * t + 2u] + 2u]);
    dvec3 n = cross(b - a, c - a);
    double nn = dot(n, n);
    return nn > 0.0lf ? vec3(p - n * (dot(n, p - a) / nn)) : vec3(p);
}

uniform uint u_first;
uniform uint u_bounds_level;

#if LIFT
// Distance of cell k of a 4 x 4 block from the block's centre, times 2 (2: the four central
// cells, 6: the corners), then k: a total order, the most central cell first.
uint centrality(uint k) {
    uint dx = uint(abs(2 * int(k % BRANCH_SIDE) - 3));
    uint dy = uint(abs(2 * int(k / BRANCH_SIDE) - 3));
    return (dx + dy) * 64u + k;
}
#endif

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
#if LIFT
    // The node's point and the centrality of the sample or child it comes from (lower = nearer
    // the centre of the 4 x 4 block; ties: the lowest index).
    vec3 point = vec3(0.0);
    uint best = 0xFFFFFFFFu;
#endif
    if (level == 0u) {
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint pixel;
            if (leaf_pixel(node, k, pixel)) {
                uvec4 s = samples[pixel];
                if (s.w != NO_TRIANGLE) {
                    valid |= 1u << k;
                    vec3 p = on_own_plane(s);
                    samples[pixel] = uvec4(floatBitsToUint(p), s.w);
                    lo = min(lo, p);
                    hi = max(hi, p);
                    float pw = dot(u_view_w.xyz, p) + u_view_w.w;
                    float tol = (dot(abs(u_view_w.xyz), abs(p)) + abs(u_view_w.w)) * (1.0 / 1048576.0);
                    w = vec2(min(w.x, pw - tol), max(w.y, pw + tol));
#if LIFT
                    vec3 q = lifted(p);
                    lo = min(lo, q);
                    hi = max(hi, q);
                    float qw = dot(u_view_w.xyz, q) + u_view_w.w;
                    float q_tol = (dot(abs(u_view_w.xyz), abs(q)) + abs(u_view_w.w)) * (1.0 / 1048576.0);
                    w = vec2(min(w.x, qw - q_tol), max(w.y, qw + q_tol));
                    uint score = centrality(k);
                    if (score < best) {
                        best = score;
                        point = q;
                    }
#endif
                }
            }
        }
    } else {
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, node, k, child)) {
                uint g = node_index(level - 1u, child);
                vec4 c_lo = nodes[NODE_VEC4S * g];
                vec4 c_hi = nodes[NODE_VEC4S * g + 1u];
                if (c_lo.w <= c_hi.w) {
                    lo = min(lo, c_lo.xyz);
                    hi = max(hi, c_hi.xyz);
                    w = vec2(min(w.x, c_lo.w), max(w.y, c_hi.w));
#if LIFT
                    uint score = centrality(k);
                    if (score < best) {
                        best = score;
                        point = nodes[NODE_VEC4S * g + 3u].xyz;
                    }
#endif
                }
            }
        }
    }
    if (level == 0u) {
        state[u_valid_offset + node] = valid;
    }
#if OCCUPANCY
    // The depth occupancy (region.glsl) over the range just found: a second pass over the
    // samples' w intervals (leaves) or the children's occupied bins (above).
    uint occupied = 0u;
    float scale = w.y > w.x ? float(OCCUPANCY_BINS) / (w.y - w.x) : 0.0;
    if (level == 0u) {
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint pixel;
            if ((valid & (1u << k)) != 0u && leaf_pixel(node, k, pixel)) {
                // The sample as stored above (moved onto its plane), its w as bounded there.
                vec3 p = uintBitsToFloat(samples[pixel].xyz);
                float pw = dot(u_view_w.xyz, p) + u_view_w.w;
                float tol = (dot(abs(u_view_w.xyz), abs(p)) + abs(u_view_w.w)) * (1.0 / 1048576.0);
                occupied |= occupancy_span(pw - tol, pw + tol, w.x, scale);
            }
        }
    } else {
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, node, k, child)) {
                uint g = node_index(level - 1u, child);
                float c_lo = nodes[NODE_VEC4S * g].w;
                float c_hi = nodes[NODE_VEC4S * g + 1u].w;
                if (c_lo <= c_hi) {
                    vec4 c_occ = nodes[NODE_VEC4S * g + 3u];
                    // Each run of occupied bins of the child, as a w interval holding every w
                    // the child's map puts there (its bin edges, widened by far more than the
                    // map's rounding), mapped onto this node's bins.
                    float c_step = (c_hi - c_lo) * (1.0 / float(OCCUPANCY_BINS));
                    float slack = (abs(c_lo) + abs(c_hi)) * (1.0 / 262144.0);
                    uint m = floatBitsToUint(c_occ.x);
                    while (m != 0u) {
                        uint i = uint(findLSB(m));
                        uint rest = ~(m >> i);
                        uint j = rest == 0u ? 31u : i + uint(findLSB(rest)) - 1u;
                        float a = max(c_lo, c_lo + float(i) * c_step - slack);
                        float b = j == 31u ? c_hi : min(c_hi, c_lo + float(j + 1u) * c_step + slack);
                        occupied |= occupancy_span(a, b, w.x, scale);
                        m &= j == 31u ? 0u : ~((2u << j) - 1u);
                    }
                }
            }
        }
    }
    nodes[NODE_VEC4S * node_index(level, node) + 3u] = vec4(uintBitsToFloat(occupied), scale, 0.0, 0.0);
#endif
    uint g = node_index(level, node);
    nodes[NODE_VEC4S * g] = vec4(lo, w.x);
    nodes[NODE_VEC4S * g + 1u] = vec4(hi, w.y);
#if LIFT
    nodes[NODE_VEC4S * g + 3u] = vec4(point, 0.0);
#endif
}
