// One triangle covering the whole viewport (vertex ids 0, 1, 2 -> (-1,-1), (3,-1), (-1,3); no
// attributes, an empty vertex array), for the full-screen passes that resolve a per-sample
// decision into the stencil (counter.rs, the hier methods' resolve.frag.glsl). z = 0 lies
// inside the clip volume of both depth conventions; those passes do not depth-test.
#version 450 core

void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
