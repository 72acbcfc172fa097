#version 300 es
// The receiver map's scatter (scatter.vert.glsl): the sample's value into its cell; MAX
// blending keeps the largest.
precision highp float;

flat in float v_value;

out vec4 o_value;

void main() {
    o_value = vec4(v_value, 0.0, 0.0, 0.0);
}
