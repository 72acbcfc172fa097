// Scene vertex shader, shared VERBATIM by pass 1 (depth + ambient) and pass 3 (lighting).
// Algorithm: multi-pass stencil shadow volumes (Heidmann 1991; Everitt & Kilgard 2002), the
// lighting pass uses depth func EQUAL against the depth written by pass 1.
// `invariant gl_Position` plus the identical expression in both programs guarantees
// bit-identical depths (GLSL 4.50 §4.8.1), so EQUAL selects exactly the visible surface.
// Camera: infinite far plane (Everitt & Kilgard 2002; paper 003 [MHE*03]).
#version 450 core

layout(location = 0) in vec3 a_world_pos;

uniform mat4 u_clip_from_world;

out vec3 v_world_pos;

invariant gl_Position;

void main() {
    v_world_pos = a_world_pos;
    gl_Position = u_clip_from_world * vec4(a_world_pos, 1.0);
}
