// Shadow-map depth pass, vertex stage (Williams 1978 shadow mapping; omnidirectional cube map
// as compared against in paper 003, Section 3.1, Tables 1-2, and paper 001, Tables 6 and 8).
// Two variants, chosen with a define:
//   UMBRA_SM_LAYERED: pass the world position through; the geometry shader (depth.geom.glsl)
//                     projects each triangle into the cube faces it touches (one pass, gl_Layer).
//   otherwise:        project with the face's (or the directional map's) light-clip matrix here;
//                     one draw per face (six passes) or one draw for a directional light.
// No #version here: mod.rs prepends it.

layout(location = 0) in vec3 a_world_pos;

#ifdef UMBRA_SM_LAYERED
void main() {
    gl_Position = vec4(a_world_pos, 1.0);
}
#else
// Light clip space from world space of the face / orthographic map being rendered.
uniform mat4 u_light_clip_from_world;

void main() {
    gl_Position = u_light_clip_from_world * vec4(a_world_pos, 1.0);
}
#endif
