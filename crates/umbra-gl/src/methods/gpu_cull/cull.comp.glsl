// The GPU cull of cs-silhouette's volume: which pieces of the caster (triangles joined across
// shared edges, umbra_geom::silhouette::caster_pieces) may shadow a visible sample of this
// frame. The GLSL twin of umbra-wgpu's shaders/cull.wgsl (the proof and every bound:
// docs/exactness.md, "Volumes culled on the GPU"): the light's receiver map (scattered by
// receivers/scatter.frag.glsl into level 0 of `cells`) holds per light-space cell the largest
// distance (point light) or depth (directional) of a visible sample there, rounded up; a
// triangle none of whose cells holds a value beyond its least value shadows no visible
// sample, and a piece none of whose triangles does is dropped whole.
//
// One program per entry, chosen by the Rust side's #define:
//   UMBRA_CULL_RAISE:  under z-pass, the cells of the eye's near pyramid raised to its
//                      farthest value (ReceiverGrid::hull_raise), one invocation per cell;
//   UMBRA_CULL_REDUCE: one level of the max pyramid, one invocation per cell written;
//   UMBRA_CULL_NEED:   one invocation per triangle: its piece marked needed;
//   UMBRA_CULL_COUNT:  one invocation per triangle: the triangles of needed pieces counted.
// Prepended by the Rust side: "#version 450 core", the entry's #define, receiver_cell.glsl.

layout(local_size_x = 256) in;

// The pyramid: level 0 is the receiver map (ReceiverGrid's cells, encoded, 0 empty), then each
// coarser level, all faces of a level together, face-major.
layout(std430, binding = 9) coherent buffer Cells { uint cells[]; };
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
// The scene's index buffer: 3 vertex indices per triangle.
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
// Per triangle, its piece.
layout(std430, binding = 3) readonly buffer Pieces { uint piece[]; };
// Word 0: the triangles kept; word 1 + p: piece p is needed.
layout(std430, binding = 4) coherent buffer Needed { uint needed[]; };

uniform uint u_first;  // several dispatches when the items exceed one dispatch's groups
uniform uint u_count;  // items of this dispatch's entry
uniform vec4 u_light;
// ReceiverGrid::Flat (directional): origin, u, v, travel, lo (xy) and scale (zw), and the
// widening of a rectangle along u and v.
uniform vec3 u_origin;
uniform vec3 u_u;
uniform vec3 u_v;
uniform vec3 u_travel;
uniform vec4 u_lo_scale;
uniform vec2 u_margin;
// The rectangle raised under z-pass (i0, i1, j0, j1), its face and value (encoded).
uniform uvec4 u_raise_rect;
uniform uint u_raise_face;
uniform uint u_raise_word;
// Cells along a side of level 0, faces, the coarsest level's number.
uniform uint u_side;
uniform uint u_faces;
uniform uint u_top;
// Word offset of each level in `cells`.
uniform uint u_level_offset[16];
// UMBRA_CULL_REDUCE: the level written.
uniform uint u_level;

vec3 cull_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

uint cull_cell(float x, float lo, float scale) {
    return receiver_cell(x, lo, scale, u_side);
}

// The largest word of face `face`'s cells r.x..=r.y x r.z..=r.w, read at the finest level where
// the rectangle spans at most 4 x 4 cells (ReceiverMap::max_over).
uint cull_max_over(uint face, uvec4 r) {
    uint k = 0u;
    while (k < u_top && ((r.y >> k) - (r.x >> k) >= 4u || (r.w >> k) - (r.z >> k) >= 4u)) {
        k++;
    }
    uint s = u_side >> k;
    uint base = u_level_offset[k] + face * s * s;
    uint m = 0u;
    for (uint j = r.z >> k; j <= (r.w >> k); j++) {
        for (uint i = r.x >> k; i <= (r.y >> k); i++) {
            m = max(m, cells[base + j * s + i]);
        }
    }
    return m;
}

// The largest word of the whole map (the coarsest level's cells).
uint cull_max_all() {
    uint m = 0u;
    for (uint f = 0u; f < u_faces; f++) {
        m = max(m, cells[u_level_offset[u_top] + f]);
    }
    return m;
}

// A point light: the largest word of the cells the triangle's cone (d[k]: its corners less the
// light) may cover (ReceiverGrid::cells_of), or of the whole map.
uint cull_cube_bound(vec3 d[3]) {
    vec3 sum = d[0] + d[1] + d[2];
    vec3 c = abs(sum);
    uint m = c.x >= c.y && c.x >= c.z ? 0u : (c.y >= c.z ? 1u : 2u);
    float s = sum[m] < 0.0 ? -1.0 : 1.0;
    vec2 lo = vec2(2.0);
    vec2 hi = vec2(-2.0);
    for (int k = 0; k < 3; k++) {
        float den = s * d[k][m];
        if (!(den > 0.0)) {
            return cull_max_all();
        }
        vec2 uv = vec2(d[k][(m + 1u) % 3u], d[k][(m + 2u) % 3u]) / den;
        lo = min(lo, uv);
        hi = max(hi, uv);
    }
    float limit = 1.0 - 4.0 / float(u_side);
    if (lo.x < -limit || lo.y < -limit || hi.x > limit || hi.y > limit) {
        return cull_max_all();
    }
    // Twice ReceiverMap's 2 * RECEIVER_MARGIN (1 / 16384 of the grid's extent 2).
    const float margin = 4.0 / 16384.0;
    float scale = 0.5 * float(u_side);
    uvec4 r = uvec4(cull_cell(lo.x - margin, -1.0, scale), cull_cell(hi.x + margin, -1.0, scale),
                    cull_cell(lo.y - margin, -1.0, scale), cull_cell(hi.y + margin, -1.0, scale));
    return cull_max_over(2u * m + (s < 0.0 ? 1u : 0u), r);
}

// A lower bound of the distance from the light to the triangle a, b, c (d[k]: corners less
// the light): the larger of the box's and the plane's, each less its worst rounding.
float cull_point_least(vec3 a, vec3 b, vec3 c, vec3 d[3]) {
    vec3 lo = min(d[0], min(d[1], d[2]));
    vec3 hi = max(d[0], max(d[1], d[2]));
    vec3 gap = max(max(lo, -hi), vec3(0.0));
    float least = sqrt(dot(gap, gap));
    vec3 e1 = b - a;
    vec3 e2 = c - a;
    vec3 n = cross(e1, e2);
    float n_len = sqrt(dot(n, n));
    if (n_len > 0.0) {
        float d_len = sqrt(dot(d[0], d[0]));
        float e_len = sqrt(dot(e1, e1)) * sqrt(dot(e2, e2));
        float plane = abs(dot(n, d[0])) / n_len;
        least = max(least, plane - d_len * (e_len / n_len + 1.0) / 131072.0);
    }
    return least * (1.0 - 1.0 / 65536.0);
}

void main() {
    uint k = u_first + gl_GlobalInvocationID.x;
    if (k >= u_count) {
        return;
    }
#if defined(UMBRA_CULL_RAISE)
    uvec4 r = u_raise_rect;
    uint width = r.y - r.x + 1u;
    uint i = r.x + k % width;
    uint j = r.z + k / width;
    atomicMax(cells[(u_raise_face * u_side + j) * u_side + i], u_raise_word);
#elif defined(UMBRA_CULL_REDUCE)
    uint s = u_side >> u_level;
    uint f = k / (s * s);
    uint j = (k % (s * s)) / s;
    uint i = k % s;
    uint fine = 2u * s;
    uint base = u_level_offset[u_level - 1u] + f * fine * fine + 2u * j * fine + 2u * i;
    cells[u_level_offset[u_level] + k] =
        max(max(cells[base], cells[base + 1u]), max(cells[base + fine], cells[base + fine + 1u]));
#elif defined(UMBRA_CULL_NEED)
    vec3 a = cull_position(indices[3u * k]);
    vec3 b = cull_position(indices[3u * k + 1u]);
    vec3 c = cull_position(indices[3u * k + 2u]);
    uint word;
    float least;
    if (u_light.w != 0.0) {
        vec3 d[3] = vec3[3](a - u_light.xyz, b - u_light.xyz, c - u_light.xyz);
        word = cull_cube_bound(d);
        least = cull_point_least(a, b, c, d);
    } else {
        vec3 r0 = a - u_origin;
        vec3 r1 = b - u_origin;
        vec3 r2 = c - u_origin;
        vec3 cu = vec3(dot(r0, u_u), dot(r1, u_u), dot(r2, u_u));
        vec3 cv = vec3(dot(r0, u_v), dot(r1, u_v), dot(r2, u_v));
        vec2 lo = vec2(min(cu.x, min(cu.y, cu.z)), min(cv.x, min(cv.y, cv.z))) - u_margin;
        vec2 hi = vec2(max(cu.x, max(cu.y, cu.z)), max(cv.x, max(cv.y, cv.z))) + u_margin;
        uvec4 r = uvec4(cull_cell(lo.x, u_lo_scale.x, u_lo_scale.z), cull_cell(hi.x, u_lo_scale.x, u_lo_scale.z),
                        cull_cell(lo.y, u_lo_scale.y, u_lo_scale.w), cull_cell(hi.y, u_lo_scale.y, u_lo_scale.w));
        word = cull_max_over(0u, r);
        vec3 depth = vec3(dot(r0, u_travel), dot(r1, u_travel), dot(r2, u_travel));
        vec3 a0 = abs(r0);
        vec3 a1 = abs(r1);
        vec3 a2 = abs(r2);
        float magnitude = max(a0.x + a0.y + a0.z, max(a1.x + a1.y + a1.z, a2.x + a2.y + a2.z));
        least = min(depth.x, min(depth.y, depth.z)) - magnitude / 262144.0;
    }
    if (word > receiver_encode(least)) {
        atomicOr(needed[1u + piece[k]], 1u);
    }
#elif defined(UMBRA_CULL_COUNT)
    if (needed[1u + piece[k]] != 0u) {
        atomicAdd(needed[0], 1u);
    }
#endif
}
