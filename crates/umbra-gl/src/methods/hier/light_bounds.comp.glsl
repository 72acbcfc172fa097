// The view-sample hierarchy, per light, bottom-up: each node's bound of its samples' directions from the
// light (hierarchy.glsl, Nodes), which decides the edge planes tightly where the world box and the
// frustum slab hold much empty space: an edge plane passes through the light (point) or along
// it (directional), so only a sample's direction from the light, not its distance, says on
// which side it lies. Point light: the axis a = the normalised sum of the unit directions and
// h = the largest distance of one from a (chord lengths stay accurate for small angles, where
// 1 - cos would not); above the leaves, the children's axes summed and h = the largest
// |a - a_child| + h_child. Directional light: the box of (S - origin) along u_light_u,
// u_light_v, united over the children. Widened by 2^-20 (rounding). A sample at the light
// itself (no direction) is skipped: it is lit (hier-triangle's frustum.glsl; hier-silhouette's
// faces never separate it). With LIFT, every sample's lifted point is bounded as well (the
// lifted points are hier-silhouette's bridge ends). Prepended: hierarchy.glsl, region.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_bounds_level;

#if LIFT
const uint POINTS_PER_SAMPLE = 2u;
#else
const uint POINTS_PER_SAMPLE = 1u;
#endif

// Point j of a sample: the sample itself (j = 0) or its lifted point (j = 1, LIFT only).
vec3 sample_point(uvec4 s, uint j) {
    vec3 p = uintBitsToFloat(s.xyz);
#if LIFT
    if (j == 1u) {
        return lifted(p);
    }
#endif
    return p;
}

void main() {
    uint level = u_bounds_level;
    uint node = u_first + gl_GlobalInvocationID.x;
    if (node >= u_level[level].x * u_level[level].y) {
        return;
    }
    uint g = node_index(level, node);
    if (nodes[NODE_VEC4S * g].w > nodes[NODE_VEC4S * g + 1u].w) {
        return;
    }
    bool point = u_light.w != 0.0;
    vec4 bound;
    if (level == 0u) {
        vec3 sum = vec3(0.0);
        vec4 box = vec4(3.0e38, -3.0e38, 3.0e38, -3.0e38);
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint pixel;
            if (leaf_pixel(node, k, pixel)) {
                uvec4 s = samples[pixel];
                for (uint j = 0u; j < POINTS_PER_SAMPLE && s.w != NO_TRIANGLE; ++j) {
                    vec3 rel = sample_point(s, j) - u_origin;
                    if (point) {
                        float r = length(rel);
                        if (r > 0.0) {
                            sum += rel / r;
                        }
                    } else {
                        vec2 uv = vec2(dot(rel, u_light_u), dot(rel, u_light_v));
                        box = vec4(min(box.x, uv.x), max(box.y, uv.x), min(box.z, uv.y), max(box.w, uv.y));
                    }
                }
            }
        }
        if (point) {
            float len = length(sum);
            vec3 axis = len > 0.0 ? sum / len : vec3(1.0, 0.0, 0.0);
            float h = len > 0.0 ? 0.0 : 2.0;
            for (uint k = 0u; k < LEAF_SAMPLES && len > 0.0; ++k) {
                uint pixel;
                if (leaf_pixel(node, k, pixel)) {
                    uvec4 s = samples[pixel];
                    for (uint j = 0u; j < POINTS_PER_SAMPLE && s.w != NO_TRIANGLE; ++j) {
                        vec3 rel = sample_point(s, j) - u_origin;
                        float r = length(rel);
                        if (r > 0.0) {
                            h = max(h, length(rel / r - axis));
                        }
                    }
                }
            }
            bound = vec4(axis, h * (1.0 + 1.0 / 1048576.0));
        } else {
            vec4 pad = vec4(-1.0, 1.0, -1.0, 1.0) * (max(abs(box.x), abs(box.y)) + max(abs(box.z), abs(box.w)))
                * (1.0 / 1048576.0);
            bound = box + pad;
        }
    } else {
        vec3 sum = vec3(0.0);
        vec4 box = vec4(3.0e38, -3.0e38, 3.0e38, -3.0e38);
        for (uint k = 0u; k < CHILDREN; ++k) {
            uint child;
            if (child_of(level, node, k, child)) {
                uint c = node_index(level - 1u, child);
                if (nodes[NODE_VEC4S * c].w <= nodes[NODE_VEC4S * c + 1u].w) {
                    vec4 b = nodes[NODE_VEC4S * c + 2u];
                    sum += b.xyz;
                    box = vec4(min(box.x, b.x), max(box.y, b.y), min(box.z, b.z), max(box.w, b.w));
                }
            }
        }
        if (point) {
            float len = length(sum);
            vec3 axis = len > 0.0 ? sum / len : vec3(1.0, 0.0, 0.0);
            float h = len > 0.0 ? 0.0 : 2.0;
            for (uint k = 0u; k < CHILDREN && len > 0.0; ++k) {
                uint child;
                if (child_of(level, node, k, child)) {
                    uint c = node_index(level - 1u, child);
                    if (nodes[NODE_VEC4S * c].w <= nodes[NODE_VEC4S * c + 1u].w) {
                        vec4 b = nodes[NODE_VEC4S * c + 2u];
                        h = max(h, length(b.xyz - axis) + b.w);
                    }
                }
            }
            bound = vec4(axis, h * (1.0 + 1.0 / 1048576.0));
        } else {
            bound = box;
        }
    }
    nodes[NODE_VEC4S * g + 2u] = bound;
}
