// cpu-silhouette shadow volumes: vertex shader for sides, light caps and dark caps.
// Algorithm: silhouette shadow volumes from deterministic edge multiplicities, computed on the
// CPU by umbra_geom::silhouette::extract_indexed (paper 001, Sections 2.2-2.3, extrusion Eq. 2:
// C = (A * l_w - L.xyz, 0)).
//
// u_mode selects what a_world_pos is (mod.rs draws each part with its own vertex array):
//   0 SIDES: CPU-built homogeneous world positions (vec4), drawn as they are. Two of every
//     quad's vertices are at infinity (w = 0).
//   1 LIGHT CAPS: the scene's welded positions (vec3, w = 1 by GL's attribute default),
//     indexed by the CPU-built oriented caps; pushed to the far plane (see below).
//   2 DARK CAPS: the same positions and indices, extruded to infinity here with Eq. 2,
//     exactly the expression the CPU uses for the sides' infinite vertices
//     (umbra_geom::silhouette::extrude: P * l_w - L.xyz, then w = 0), `precise` so that no
//     fused multiply-add changes a bit: a dark-cap vertex equals the side vertex it shares.
//     The dark cap must face away from the light cap (P0∞ P2∞ P1∞), so mod.rs draws it with
//     the front face flipped (glFrontFace CW) instead of reversing the indices.
// w = 0 vertices land exactly on the far plane with the infinite far plane (clip z =
// u_far_clip_z * w: depth 1 under the standard convention, exactly 0 under reversed-Z) and,
// with GL_DEPTH_CLAMP on, are never clipped.
//
// Light caps: paper 003, Eq. 6, through shared/depth.glsl umbra_push_to_far: the cap keeps its
// screen footprint but moves to the far plane, so it FAILS the strict depth test of the
// counting pass (LESS, resp. GREATER under reversed-Z) at every sample and is always counted
// by z-fail. For samples in front of the caster triangle that is what the unmoved cap did
// anyway; it changes the count only for samples strictly behind the triangle in view, which
// the triangle itself hides, so no visible sample changes. The one sample set where the
// unmoved cap was ambiguous is the triangle's own surface (cap and surface have equal depth
// and z-fight): now the triangle is consistently outside its own volume when seen from its
// lit side (the cap's front face, -1, cancels the side or dark cap the ray leaves through,
// +1) and inside it when seen from its dark side (the cap's back face, +1), which the
// two-sided lighting pass shades without diffuse or specular anyway.
//
// 3 NEAR CAPS (orthographic z-pass only, docs/exactness.md "Orthographic views"): the light
//   caps' parts BEHIND the near plane, at the near plane's depth. An orthographic z-pass
//   counts every crossing from infinity behind the camera, where the finite volumes' winding
//   is 0, so it needs the whole closed surface there: a caster the near plane cuts away has
//   its light cap in front of every visible sample, and it must count. The part in front of
//   the near plane lies on a caster the depth pass drew, so it is never strictly in front of
//   a visible sample: clipped away (gl_ClipDistance[0] = minus the near distance).
//
// Edge-on triangles (orientation 0) come as degenerate caps (one vertex three times): zero
// area in both caps, no fragment.
//
// Face depth: every triangle carries its face's window depth function, flat
// (face_window_depth, shared/side_plane.glsl), which the fragment shader writes as every
// fragment's depth (shared/face_depth.frag.glsl). Caps: the far plane. Sides: the plane through the
// triangle's three vertices (or u_edge_on_depth seen edge-on), computed by the provoking vertex
// only, the LAST of each triangle (GL_LAST_VERTEX_CONVENTION, GL's default, which umbra never
// changes), which reads the two before it from the side buffer bound as storage too (the
// sides are drawn non-indexed from vertex 0, so gl_VertexID indexes that buffer).
//
// Prepended by mod.rs: "#version 450 core", shared/multiplicity.glsl, shared/depth.glsl
// (uniform u_far_clip_z) and shared/side_plane.glsl (uniform u_clip_from_world).

layout(location = 0) in vec4 a_world_pos;

// The side vertices (the buffer behind a_world_pos in MODE_SIDES), for the provoking vertex.
layout(std430, binding = UMBRA_SIDES_BINDING) readonly buffer Sides {
    vec4 side_vertices[];
};

flat out dvec3 face_window_depth;

uniform int u_mode;
uniform vec4 u_light;

const int MODE_SIDES = 0;
const int MODE_LIGHT_CAPS = 1;
const int MODE_DARK_CAPS = 2;
const int MODE_NEAR_CAPS = 3;

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

void main() {
    vec4 world = a_world_pos;
    if (u_mode == MODE_DARK_CAPS) {
        precise vec3 direction = a_world_pos.xyz * u_light.w - u_light.xyz; // 001 Eq. 2
        world = vec4(direction, 0.0);
    }
    // One multiplication for every mode: equal world vectors give equal clip positions.
    vec4 clip = u_clip_from_world * world;
    face_window_depth = umbra_face_depth_far();
    if (u_mode == MODE_SIDES && gl_VertexID % 3 == 2) {
        // The same product as the other two vertices' own clip positions.
        vec4 first = u_clip_from_world * side_vertices[gl_VertexID - 2];
        vec4 second = u_clip_from_world * side_vertices[gl_VertexID - 1];
        face_window_depth = umbra_face_depth_of_plane(umbra_window_depth_plane(first, second, clip));
    }
    if (u_mode == MODE_NEAR_CAPS) {
        // The near plane's window depth: 0 standard, 1 reversed-Z (u_far_clip_z 1 or 0). With
        // depth clamp the clipped-away rest would get it too.
        face_window_depth = dvec3(0.0LF, 0.0LF, 1.0LF - double(u_far_clip_z));
    }
    // Light caps: clipped at the near plane, then pushed (shared/depth.glsl); near caps: only
    // their part behind the near plane kept; the rest never clipped.
    UMBRA_NEAR_CLIP(u_mode == MODE_LIGHT_CAPS ? umbra_near_distance(clip)
                    : u_mode == MODE_NEAR_CAPS ? -umbra_near_distance(clip) : 1.0);
    if (u_mode == MODE_LIGHT_CAPS) {
        clip = umbra_push_to_far(clip); // paper 003, Eq. 6
    }
    gl_Position = clip;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
