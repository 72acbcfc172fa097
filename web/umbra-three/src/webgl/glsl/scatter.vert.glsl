#version 300 es
// One light's receiver map (umbra_geom::receivers, crates/umbra-wasm/src/cull.rs): one point
// per pixel of the position pass (position.frag.glsl), sent to its light-space cell of the map
// texture with its value, which MAX blending keeps per cell: the farthest visible sample of
// every cell, what the wasm culls and clamps the shadow volumes against. WebGL 2 has no
// storage buffers or atomics, so the atomicMax of native umbra's scatter
// (crates/umbra-gl/src/methods/receivers/scatter.frag.glsl) is a point drawn into an R32F
// texture under MAX blending (EXT_float_blend). The cell and the value are its expressions,
// ReceiverGrid::sample_cell's in f32: a point light's cube face of the largest coordinate,
// the other two divided by it; a directional light's (u, v) plane over the scene's box; the
// distance from the light or the depth along it, rounded up by 2^-20 of the magnitudes. The
// map's margins (RECEIVER_MARGIN of the grid for the cells, RECEIVER_ROUND_UP and CLAMP_MARGIN
// for the values) are far larger than the roundings by which this shader's division, length
// and interpolated position may differ from the Rust expressions.
//
// The map texture is u_side wide and faces * u_side high, face f's rows from f * u_side:
// cell (face * side + j) * side + i at texel (i, face * side + j), as the wasm reads it. A
// sample with no surface (w < 0), or facing away from light u_light_bit (its bit in w), is
// culled: no fragment.
precision highp float;
precision highp int;

uniform highp sampler2D u_positions;
uniform int u_width;
uniform int u_light_bit;
uniform vec4 u_light;
uniform int u_side;
uniform int u_faces;
uniform vec3 u_origin;
uniform vec3 u_u;
uniform vec3 u_v;
uniform vec3 u_travel;
uniform vec2 u_lo;
uniform vec2 u_scale;

flat out float v_value;

const float ROUND_UP = 1.0 / 1048576.0;

int receiver_cell(float x, float lo, float scale, int n) {
    return int(clamp(floor((x - lo) * scale), 0.0, float(n - 1)));
}

void main() {
    // Culled unless a cell is found: outside the map's clip volume.
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
    v_value = 0.0;
    vec4 s = texelFetch(u_positions, ivec2(gl_VertexID % u_width, gl_VertexID / u_width), 0);
    if (!(s.w >= 0.0) || ((int(s.w) & u_light_bit) != 0)) {
        return;
    }
    vec3 p = s.xyz;
    int face = 0;
    int ci;
    int cj;
    if (u_light.w != 0.0) {
        vec3 rel = p - u_light.xyz;
        vec3 a = abs(rel);
        // A sample at the light is lit: no cell.
        if (!(a.x + a.y + a.z > 0.0)) {
            return;
        }
        int m = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
        face = 2 * m + (rel[m] < 0.0 ? 1 : 0);
        vec2 uv = vec2(rel[(m + 1) % 3], rel[(m + 2) % 3]) / a[m];
        float scale = 0.5 * float(u_side);
        ci = receiver_cell(uv.x, -1.0, scale, u_side);
        cj = receiver_cell(uv.y, -1.0, scale, u_side);
        v_value = length(rel) * (1.0 + ROUND_UP);
    } else {
        vec3 rel = p - u_origin;
        ci = receiver_cell(dot(rel, u_u), u_lo.x, u_scale.x, u_side);
        cj = receiver_cell(dot(rel, u_v), u_lo.y, u_scale.y, u_side);
        vec3 a = abs(rel);
        v_value = dot(rel, u_travel) + (a.x + a.y + a.z) * ROUND_UP;
    }
    // The texel's centre, exactly (a power-of-two side): a point of size 1 covers that one texel.
    vec2 texel = vec2(float(ci), float(face * u_side + cj)) + 0.5;
    vec2 size = vec2(float(u_side), float(u_faces * u_side));
    gl_Position = vec4(texel / size * 2.0 - 1.0, 0.0, 1.0);
}
