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

// GLSL ES 3.00 has no gl_ClipDistance: vs-silhouette's ES build does not cut light caps; the
// WebGL drawer (web/umbra-three) clips its volume polygons itself, light caps at this same near plane
// (web/umbra-three/src/webgl/glsl/clip.glsl, docs/web.md).
#ifdef GL_ES
#define UMBRA_NEAR_CLIP(d)
#else
#define UMBRA_NEAR_CLIP(d) gl_ClipDistance[0] = (d)
#endif

// The scene box clip of z-pass volumes (renderer.rs, volume_pass; umbra_geom::clearance).
// z-pass counts only the volume faces on the segment from the eye to a visible sample. When
// the eye is clear of every volume (the only case the renderer counts z-pass in, unless the
// caller forces it), both ends of that segment lie in the box B around the scene's triangles
// and the eye (enlarged by a margin), and B is convex, so the whole segment does: clipping
// the volumes to B removes no counted crossing. What it removes is the volumes' parts beyond
// the scene, out to infinity, which on a CPU rasteriser cost as much as the rest (long thin
// side quads binned into every tile they cross: -33 % sides time on the Sponza fly-through).
// u_scene_planes are B's six planes in clip space ((clip_from_world)^-T times the world
// plane), so dot(plane, gl_Position) is the world distance to the plane scaled by the vertex's
// homogeneous w (positive inside), exactly linear as GL interpolates clip distances. The
// renderer binds the block at UMBRA_SCENE_CLIP_BINDING for every counting method's volume
// pass and enables GL_CLIP_DISTANCE1..6 only for a z-pass light; under z-fail (faces BEHIND
// the sample count, out to infinity) the distances are written and ignored.
#ifdef GL_ES
#define UMBRA_SCENE_CLIP(clip)
#else
layout(std140, binding = 14) uniform UmbraSceneClip {
    vec4 u_scene_planes[6];
};
// Constant indices: gl_ClipDistance is implicitly sized, so a loop index is not allowed.
#define UMBRA_SCENE_CLIP(clip) \
    gl_ClipDistance[1] = dot(u_scene_planes[0], (clip)); \
    gl_ClipDistance[2] = dot(u_scene_planes[1], (clip)); \
    gl_ClipDistance[3] = dot(u_scene_planes[2], (clip)); \
    gl_ClipDistance[4] = dot(u_scene_planes[3], (clip)); \
    gl_ClipDistance[5] = dot(u_scene_planes[4], (clip)); \
    gl_ClipDistance[6] = dot(u_scene_planes[5], (clip))
#endif
