// gs-triangle shadow volumes: vertex shader. Paper 001, Section 2.1 / 3 (per-triangle volumes,
// here built in a geometry shader, the variant the paper's two-pass tessellation method is
// compared against). Stage reason: the geometry shader needs the world-space triangle; this
// stage only forwards the scene's positions (the scene's own vertex array and index buffer).
#version 450 core

layout(location = 0) in vec3 a_position;

out vec3 v_world;

void main() {
    v_world = a_position;
}
