// cs-silhouette: draws the caps the compute pass (caps.comp.glsl) compacted, with
// glDrawArraysIndirect. Light cap pushed to the far plane (paper 003 Eq. 6 through the shared
// depth.glsl umbra_push_to_far), dark cap extruded to infinity and reversed (paper 003 Alg. 2,
// line 11; 001 Eq. 2). Prepended: "#version 450 core", multiplicity.glsl, depth.glsl,
// side_plane.glsl.
//
// No vertex attributes: cap c = gl_VertexID / u_vertices_per_cap, v = the remainder: 0-2 the
// light cap P0 P1 P2, 3-5 (point lights only) the dark cap P2 P1 P0 at infinity.

layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 4) readonly buffer Caps { uint caps[]; };

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;
uniform uint u_vertices_per_cap;

invariant gl_Position;

// The face's window depth function for the fragment shader, which writes it as every
// fragment's depth (shared/face_depth.frag.glsl): both caps lie at the far plane (the light cap pushed there, the
// dark cap at infinity, clamped).
flat out dvec3 face_window_depth;

vec3 umbra_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

void main() {
    // Light caps are clipped at the near plane below; the rest never (shared/depth.glsl).
    UMBRA_NEAR_CLIP(1.0);
    face_window_depth = umbra_face_depth_far();
    uint c = uint(gl_VertexID) / u_vertices_per_cap;
    uint v = uint(gl_VertexID) % u_vertices_per_cap;
    uint k = v < 3u ? v : 5u - v;
    vec3 p = umbra_position(caps[3u * c + k]);
    if (v < 3u) {
        vec4 clip = u_clip_from_world * vec4(p, 1.0);
        UMBRA_NEAR_CLIP(umbra_near_distance(clip));
        gl_Position = umbra_push_to_far(clip);
    } else {
        gl_Position = u_clip_from_world * umbra_extrude(p, u_light);
    }
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
