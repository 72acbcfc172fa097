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

void main() {
    vec3 n = (gl_FrontFacing ? u_flip : -u_flip) * v_normal;
    int away = 0;
    for (int k = 0; k < 4; ++k) {
        if (k < u_light_count) {
            vec3 l = normalize(u_lights[k].xyz - v_world_pos * u_lights[k].w);
            if (dot(n, l) < -1.0 / 1024.0) {
                away |= 1 << k;
            }
        }
    }
    o_position = vec4((u_world_from_object * vec4(v_world_pos, 1.0)).xyz, float(away));
}
