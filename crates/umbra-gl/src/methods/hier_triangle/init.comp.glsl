// hier-triangle, per light and level from the leaves up to the virtual root, one invocation per
// node: the live bitmask (live.glsl) before the first triangle: a leaf's word = its samples
// present (hier/bounds.comp.glsl's mask) that may be lit, an inner node's (and the root's) =
// its children whose word is not 0 (the level below, the dispatch before). A sample whose seen side certainly faces away from
// the light starts cleared: the lighting pass never lights it, whatever the stencil says
// (docs/exactness.md), so no triangle is tested against it, and a node all of whose samples
// face away is never entered. Invocation 0 also resets the job counter and list, and every
// workgroup's slot (traverse.comp.glsl). At most 32 iterations per loop. Prepended: hier/hierarchy.glsl, hier/region.glsl, frustum.glsl,
// live.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
// The level this dispatch initialises (u_levels: the virtual root).
uniform uint u_init_level;
// The job buffer (traverse.comp.glsl): where the slots begin, how many.
uniform uint u_slots_offset;
uniform uint u_workgroups;

layout(std430, binding = 8) buffer Jobs { uint jobs[]; };

// Whether the sample (world position p, on triangle t) certainly faces away from the light as
// the lighting pass decides it (shaders/lighting.frag.glsl: the seen side's flat normal dotted
// with the direction to the light, > 0 to be lit): the eye and the light lie on opposite sides
// of t's plane, each by a wide margin (the cosines beyond 2^-6 towards the eye, so that the
// rasterizer's gl_FrontFacing from snapped vertices agrees, and 2^-10 towards the light; the
// lighting pass computes from a normal and a position that differ from these by rounding
// only). The plane decides, not the winding: a coincident duplicate of opposite winding gets
// the same answer. Otherwise the sample is kept.
bool faces_away(vec3 p, uint t) {
    vec3 a = vec3(positions[3u * indices[3u * t]], positions[3u * indices[3u * t] + 1u],
                  positions[3u * indices[3u * t] + 2u]);
    vec3 b = vec3(positions[3u * indices[3u * t + 1u]], positions[3u * indices[3u * t + 1u] + 1u],
                  positions[3u * indices[3u * t + 1u] + 2u]);
    vec3 c = vec3(positions[3u * indices[3u * t + 2u]], positions[3u * indices[3u * t + 2u] + 1u],
                  positions[3u * indices[3u * t + 2u] + 2u]);
    vec3 n = cross(b - a, c - a);
    vec3 e = u_eye_rel + u_origin - p;
    vec3 l = u_light.w != 0.0 ? u_light.xyz / u_light.w - p : u_light.xyz;
    float nn = length(n);
    float ee = length(e);
    float ll = length(l);
    if (!(nn > 0.0 && ee > 0.0 && ll > 0.0)) {
        return false;
    }
    float eye_cos = dot(n, e) / (nn * ee);
    float light_cos = dot(n, l) / (nn * ll);
    return (eye_cos > 1.0 / 64.0 && light_cos < -1.0 / 1024.0) || (eye_cos < -1.0 / 64.0 && light_cos > 1.0 / 1024.0);
}

void main() {
    uint i = u_first + gl_GlobalInvocationID.x;
    uint level = u_init_level;
    if (level == 0u) {
        if (i == 0u) {
            jobs[0] = 0u;
            jobs[1] = 0u;
            jobs[2] = 0u;
        }
        if (i < u_workgroups) {
            jobs[u_slots_offset + i * SLOT_WORDS] = 0u;
            jobs[u_slots_offset + i * SLOT_WORDS + 1u] = 0u;
        }
    }
    uint count = level >= u_levels ? 1u : u_level[level].x * u_level[level].y;
    if (i >= count) {
        return;
    }
    uint mask = 0u;
    if (level == 0u) {
        uint valid = state[u_valid_offset + i];
        for (uint k = 0u; k < LEAF_SAMPLES; ++k) {
            uint pixel;
            if ((valid & (1u << k)) != 0u && leaf_pixel(i, k, pixel)) {
                uvec4 s = samples[pixel];
                if (!faces_away(uintBitsToFloat(s.xyz), s.w)) {
                    mask |= 1u << k;
                }
            }
        }
    } else {
        for (uint k = 0u; k < 32u; ++k) {
            uint child;
            if (live_child(level, i, k, child) && state[live_word(level - 1u, child)] != 0u) {
                mask |= 1u << k;
            }
        }
    }
    state[live_word(level, i)] = mask;
}
