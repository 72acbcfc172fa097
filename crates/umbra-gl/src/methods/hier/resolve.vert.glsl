// The view-sample hierarchy: one triangle covering the whole frame (vertex ids 0-2, no attributes), for
// the resolve of the per-sample decision into the stencil (resolve.frag.glsl).
#version 450 core

void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
