// ts-triangle (two-pass per-triangle method), pass 2: light caps, tessellation evaluation.
// Paper 001, Section 2.1: "In the second pass, light caps are rendered in order to close the
// volumes for z-fail." The control shader (two_pass.tesc.glsl with UMBRA_LIGHT_CAPS) wound the
// patch to face the light and set every level to 1: one triangle, the triangle itself, emitted
// counter-clockwise (it faces the light = out of its volume). Pushed to the far plane here in
// the evaluation stage (paper 003, Eq. 6, umbra_push_to_far): it keeps its screen footprint,
// always fails the depth test and so is always counted by z-fail, and it cannot z-fight with
// the caster triangle in the scene (the paper's Section 2.3 artefact).

layout(triangles, equal_spacing, ccw) in;

in vec3 c_world[];

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).

invariant gl_Position;

void main() {
    vec3 t = gl_TessCoord;
    int i = (t.x >= t.y && t.x >= t.z) ? 0 : (t.y >= t.z ? 1 : 2);
    vec4 clip = u_clip_from_world * vec4(c_world[i], 1.0);
    // Clipped at the near plane before the push (shared/depth.glsl).
    UMBRA_NEAR_CLIP(umbra_near_distance(clip));
    gl_Position = umbra_push_to_far(clip);
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
