#version 300 es
// Pass 3 of the stencil shadow-volume frame, run where stencil == 0 (lit), added onto the
// colour with blend ONE, ONE and depth func EQUAL: the ES 3.00 port of crates/umbra-gl/src/
// shaders/lighting.frag.glsl — the same TWO-SIDED Lambert + Blinn-Phong with the flat normal
// flipped by gl_FrontFacing and L = normalize(light.xyz - p * light.w), so a pixel is lit
// exactly when the native lit mask says so (stencil == 0 and the seen side faces the light).
// u_mask = 1: the shadow-mask view, white where lit, nothing (black from pass 1) elsewhere.
precision highp float;

in vec3 v_world_pos;
flat in vec3 v_normal;

uniform vec4 u_light;
uniform vec3 u_light_color;
uniform vec3 u_eye;
uniform vec3 u_albedo;
uniform float u_specular;
uniform float u_shininess;
uniform int u_mask;

out vec4 o_color;

void main() {
    vec3 n = gl_FrontFacing ? v_normal : -v_normal;
    vec3 v = normalize(u_eye - v_world_pos);
    vec3 l = normalize(u_light.xyz - v_world_pos * u_light.w);
    float n_dot_l = dot(n, l);
    bool faces_light = n_dot_l > 0.0;
    vec3 color = vec3(0.0);
    if (faces_light) {
        vec3 h = normalize(l + v);
        float spec = pow(max(dot(n, h), 0.0), u_shininess);
        color = u_light_color * (u_albedo * n_dot_l + vec3(u_specular * spec));
    }
    if (u_mask != 0) {
        color = faces_light ? vec3(1.0) : vec3(0.0);
    }
    // Alpha 0: pass 1 wrote alpha 1, the additive blend keeps it.
    o_color = vec4(color, 0.0);
}
