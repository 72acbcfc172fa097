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
