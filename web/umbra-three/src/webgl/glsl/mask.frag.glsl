#version 300 es
// umbra's mask pass (drawer.js), run where stencil == 0 (outside every shadow volume of the
// light) with depth func EQUAL on the depth pass's surface, into the light's channel of the
// mask target (the channel cleared to 0 = shadowed first): 1 where the seen side faces the
// light. The facing test of crates/umbra-gl/src/shaders/lighting.frag.glsl — the flat normal
// flipped by gl_FrontFacing (and by u_flip for a mirroring world transform, whose winding
// three.js turns with frontFaceCW) and L = light.xyz - p * light.w, in the mesh's own space —
// so a pixel is lit exactly when the native lit mask says so.
precision highp float;

in vec3 v_world_pos;
flat in vec3 v_normal;

uniform vec4 u_light;
uniform float u_flip;

out vec4 o_color;

void main() {
    vec3 n = (gl_FrontFacing ? u_flip : -u_flip) * v_normal;
    vec3 l = normalize(u_light.xyz - v_world_pos * u_light.w);
    bool faces_light = dot(n, l) > 0.0;
    o_color = vec4(faces_light ? 1.0 : 0.0);
}
