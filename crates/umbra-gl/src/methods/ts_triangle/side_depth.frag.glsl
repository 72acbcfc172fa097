// ts-triangle (volume pass) and ts-triangle-1pass: fragment shader with fragment depths.
// Paper 001, Section 2.3: "We had to manually push the front cap's fragments into depth of
// 1.0f, so they would fail the depth test" (single-pass method); Section 2.1 (per-triangle
// volumes). Stage reason: in a tessellated per-triangle volume neither the light cap (1-pass:
// it shares its tessellated vertices with two sides) nor the sides (both methods: their
// triangulation and vertex order are the tessellator's, different in the two patches that cast
// the same side) can be given a consistent depth in the evaluation stage; here they can.
//
// Which face a fragment belongs to: every tessellated vertex carries e_corner, the one-hot
// vector of the patch point (0, 1, 2) it was placed at. A side of the edge between points i and
// i + 1 only has vertices of those two points, so its fragments interpolate component i + 2 to
// exactly 0; caps (light or dark) have all three points and all three components > 0 inside.
// (Perspective-correct interpolation: every cap vertex is finite, and a component that is 0 at
// all three vertices stays 0 - or NaN next to a point at infinity, which also fails "> 0".)
//
//   UMBRA_CAPS_TO_FAR        cap fragments get the far plane's depth (the 1-pass light cap;
//                            the dark cap is there already)
//   UMBRA_CANONICAL_SIDES    side fragments get the depth of their canonical plane
//                            (e_planes, from side_plane.glsl), identical for both copies
// Without either define the shader writes no depth (early depth testing stays on): the
// paper's rasterized depths, kept only to measure what the depth writes cost.
//
// Window depth: z_window = u_depth_from_ndc.x * z_ndc + u_depth_from_ndc.y, (0.5, 0.5) for the
// standard -1..1 clip range with glDepthRange(0, 1); the far plane is u_far_clip_z as a window
// depth too (1 standard; 0 with a reversed zero-to-one range).
#version 450 core

in vec3 e_corner;
flat in vec4 e_planes[3];

uniform float u_far_clip_z;
uniform vec2 u_viewport_size;
uniform vec2 u_depth_from_ndc;

void main() {
#if defined(UMBRA_CAPS_TO_FAR) || defined(UMBRA_CANONICAL_SIDES)
    bool cap = e_corner.x > 0.0 && e_corner.y > 0.0 && e_corner.z > 0.0;
    float depth = gl_FragCoord.z;
#ifdef UMBRA_CAPS_TO_FAR
    if (cap) {
        depth = u_far_clip_z;
    }
#endif
#ifdef UMBRA_CANONICAL_SIDES
    if (!cap) {
        // Component i + 2 == 0 <=> side of edge (i, i + 1) <=> plane i.
        vec4 p = !(e_corner.z > 0.0) ? e_planes[0] : (!(e_corner.x > 0.0) ? e_planes[1] : e_planes[2]);
        vec2 ndc = gl_FragCoord.xy / u_viewport_size * 2.0 - 1.0;
        float z_ndc = -(p.x * ndc.x + p.y * ndc.y + p.w) / p.z;
        depth = u_depth_from_ndc.x * z_ndc + u_depth_from_ndc.y;
    }
#endif
    gl_FragDepth = depth;
#endif
}
