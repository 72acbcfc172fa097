// Silhouette caps, vertex stage: paper 001, Section 2.3 (caps of the silhouette method drawn
// in a geometry shader). Passes the scene's welded world positions through UNCHANGED, so the
// geometry shader's orientation test sees exactly the bits the side patches see (same welded
// positions, different buffers). Prepended: "#version 450 core" + shared GLSL.

layout(location = 0) in vec3 a_world_pos;

out vec3 v_world_pos;

void main() {
    v_world_pos = a_world_pos;
}
