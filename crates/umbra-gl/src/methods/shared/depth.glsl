// Pushing light caps to the far plane (paper 003, Section 2.5, Eq. 6: B = (a_x, a_y, a_w, a_w)),
// shared by every shadow-volume method. No #version line: spliced after a method's own.
//
// The cap keeps its screen footprint but moves to the far plane, so it fails the strict depth
// test of the counting pass at every sample (background included) and z-fail always counts it.
// That changes the count only for samples strictly behind the caster triangle in view, which the
// triangle itself hides; on the triangle's own surface (where an unmoved cap would z-fight with
// it) the triangle is now consistently outside its own volume seen from its lit side and inside
// it seen from its dark side.
//
// u_far_clip_z is the far plane's clip z as a multiple of clip w (set from
// VolumeFrame::far_clip_z, never hard-coded):
//   standard convention (clip z in [-w, w], depth func LESS):   1 -> depth 1;
//   reversed-Z (glClipControl ZERO_TO_ONE, depth func GREATER):  0 -> depth exactly 0 (0 * w
//   is exact, so the cap sits exactly on the cleared far depth, and GREATER fails there).

uniform float u_far_clip_z;

vec4 umbra_push_to_far(vec4 clip) {
    return vec4(clip.xy, u_far_clip_z * clip.w, clip.w);
}

// Light caps of casters the camera's near plane cuts. The scene's own depth pass clips at the
// near plane, so a sample seen through a caster cut away there is visible, and the cap pushed
// to the far plane would be counted behind it although the caster lies in front of it (found
// with the eye 0.01 units outside a wall of Crytek Sponza, 0.028 near plane: every sample
// seen through the wall was shadowed). A light cap is therefore clipped by that same near
// plane before it is pushed: gl_ClipDistance[0] = its clip-space distance from the near
// plane (GL_CLIP_DISTANCE0 is enabled by the renderer for the counting methods' volume
// pass); every other volume vertex writes a positive constant. A cut-away cap is in front of
// every visible sample there, where z-fail does not count it anyway.
//
// umbra_near_distance: z + w under the standard convention (near plane z = -w) and w - z under
// reversed-Z (near plane z = w), told apart by u_far_clip_z (1 standard, 0 reversed-Z).
float umbra_near_distance(vec4 clip) {
    return clip.w + (2.0 * u_far_clip_z - 1.0) * clip.z;
}

// GLSL ES 3.00 (vs-silhouette's WebGL2 build) has no gl_ClipDistance: there the near-plane
// cut is not handled (docs/web.md).
#ifdef GL_ES
#define UMBRA_NEAR_CLIP(d)
#else
#define UMBRA_NEAR_CLIP(d) gl_ClipDistance[0] = (d)
#endif
