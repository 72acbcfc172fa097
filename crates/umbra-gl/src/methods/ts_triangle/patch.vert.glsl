// ts-triangle / ts-triangle-1pass: vertex shader. Paper 001, Section 2.1 (per-triangle
// methods): "input patch has 3 points, which are original points of the triangle". Stage
// reason: the tessellation control shader needs world-space positions; this stage only
// forwards the scene's positions (the scene's own vertex array and index buffer, drawn as
// GL_PATCHES of 3 vertices).
#version 450 core

layout(location = 0) in vec3 a_position;

out vec3 v_world;

void main() {
    v_world = a_position;
}
