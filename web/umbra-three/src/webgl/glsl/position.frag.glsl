#version 300 es
// umbra's position pass when volumes are culled to their receivers (drawer.js, `volumeCull`),
// drawn after the depth pass over its depth with depth EQUAL (the visible fragments only):
// every visible sample's world position into an RGBA32F target, which the
// scatter (scatter.vert.glsl) turns into each light's receiver map (umbra_geom::receivers; the
// CC shadow volumes of Lloyd, Wendt, Govindaraju & Manocha, EGSR 2004, with the receivers
// taken from the frame itself). Why a fragment shader of its own: the vertex shader
// (depth.vert.glsl) is shared verbatim with the mask pass for its invariant gl_Position, so
// the world position is made here from the interpolated object-space position.
//
// w: a bit per light k whose mask the sample can never light, because its seen side clearly
// faces away from the light — the mask pass's facing test (mask.frag.glsl: the flat normal
// flipped by gl_FrontFacing and u_flip, L = light.xyz - p * light.w, in the mesh's own space)
// with its cosine below -2^-10, far beyond the rounding by which two programs may compute the
// mask pass's `> 0` differently; the scatter leaves such a sample out of that light's map, as
// native umbra's (crates/umbra-gl/src/methods/receivers/scatter.frag.glsl). A zero or NaN
// normal never sets a bit. Where no surface is seen the target keeps its clear value, w = -1.
precision highp float;

in vec3 v_world_pos;
flat in vec3 v_normal;

uniform mat4 u_world_from_object;
uniform vec4 u_lights[4];
uniform int u_light_count;
uniform float u_flip;

out vec4 o_position;

// Whether the seen side (unit normal n) clearly faces away from light l: its cosine with the
// direction to the light below -2^-10, without a square root or a division:
// dot(n, v) < 0 and dot(n, v)^2 > 2^-20 |v|^2 (n is a unit normal; a zero one never counts).
float away(vec3 n, vec4 l, float bit) {
    vec3 v = l.xyz - v_world_pos * l.w;
    float d = dot(n, v);
    return d < 0.0 && d * d * 1048576.0 > dot(v, v) ? bit : 0.0;
}

void main() {
    vec3 n = (gl_FrontFacing ? u_flip : -u_flip) * v_normal;
    // Unrolled over the at most 4 lights (constant indices).
    float bits = 0.0;
    if (u_light_count > 0) bits += away(n, u_lights[0], 1.0);
    if (u_light_count > 1) bits += away(n, u_lights[1], 2.0);
    if (u_light_count > 2) bits += away(n, u_lights[2], 4.0);
    if (u_light_count > 3) bits += away(n, u_lights[3], 8.0);
    o_position = vec4((u_world_from_object * vec4(v_world_pos, 1.0)).xyz, bits);
}
