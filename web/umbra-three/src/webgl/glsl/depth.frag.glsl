#version 300 es
// umbra's depth pass (drawer.js): depth only, colour writes are masked off; the mask target's
// channels are written by the mask pass alone (mask.frag.glsl).
precision highp float;

in vec3 v_world_pos;
flat in vec3 v_normal;

out vec4 o_color;

void main() {
    o_color = vec4(0.0);
}
