// ray-bvh, per light: the decision into the stencil (Classification::StencilZero: lit where
// 0). Full-screen; a pixel whose ray hit (result 1) survives and the stencil state writes 1
// (REPLACE); the others (lit, background) are discarded and keep the cleared 0. No colour, no
// depth.

#version 450 core

layout(std430, binding = 6) readonly buffer Results { uint results[]; };

uniform uint u_width;

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    if (results[p.y * u_width + p.x] != 1u) {
        discard;
    }
}
