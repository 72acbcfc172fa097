// cpu-silhouette shadow volumes: vertex shader for sides, dark caps and light caps.
// Algorithm: silhouette shadow volumes from deterministic edge multiplicities, computed on the
// CPU by umbra_geom::silhouette::extract (paper 001, Sections 2.2-2.3, extrusion Eq. 2:
// C = (A * l_w - L.xyz, 0)); this shader only transforms the world-space homogeneous vertices.
// Sides and dark caps carry w = 0 vertices (points at infinity); with the infinite far plane
// they land exactly on the far plane (clip z = u_far_clip_z * w: depth 1 under the standard
// convention, exactly 0 under reversed-Z) and, with GL_DEPTH_CLAMP on, are never clipped.
//
// Light caps (u_push_to_far): paper 003, Eq. 6, through shared/depth.glsl umbra_push_to_far:
// the cap keeps its screen footprint but moves to the far plane, so it FAILS the strict
// depth test of the counting pass (LESS, resp. GREATER under reversed-Z) at every sample and
// is always counted by z-fail. For samples in front of the caster triangle that is what the
// unmoved cap did anyway; it changes the count only for samples strictly behind the triangle
// in view, which the triangle itself hides, so no visible sample changes. The one sample set
// where the unmoved cap was ambiguous is the triangle's own surface (cap and surface have
// equal depth and z-fight): now the triangle is consistently outside its own volume when seen
// from its lit side (the cap's front face, -1, cancels the side or dark cap the ray leaves
// through, +1) and inside it when seen from its dark side (the cap's back face, +1), which
// the two-sided lighting pass shades without diffuse or specular anyway.
//
// Prepended by mod.rs: "#version 450 core" and shared/depth.glsl (uniform u_far_clip_z).

layout(location = 0) in vec4 a_world_pos;

uniform mat4 u_clip_from_world;
uniform bool u_push_to_far;

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

void main() {
    vec4 clip = u_clip_from_world * a_world_pos;
    if (u_push_to_far) {
        clip = umbra_push_to_far(clip); // paper 003, Eq. 6
    }
    gl_Position = clip;
}
