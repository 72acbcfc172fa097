// Silhouette caps, geometry stage: paper 001, Section 2.3 ("for caps generation in
// silhouette-based method, we used geometry shader and multiplicity calculation, using which we
// calculated triangle's orientation towards light source via reference edge"), the same test as
// the sides (Alg. 3-4, or the 3-edge test with UMBRA_THREE_EDGE; see determinism.glsl), so a
// triangle discarded or flipped by the sides is discarded or flipped here too.
//
// Per scene triangle p0 p1 p2 with orientation o != 0, wound c0 c1 c2 to face the light:
// * light cap c0 c1 c2, pushed to the far plane (paper 003, Eq. 6, umbra_push_to_far);
// * dark cap at infinity, extruded with Eq. 2 (umbra_extrude) and wound c0 c2 c1 so that it
//   faces out of the volume - point lights only: for a directional light every vertex
//   extrudes to the same point -L.xyz and the dark cap has zero area.
// Edge-on triangles (o == 0) cast no side quads and get no caps.
// Prepended: "#version 450 core", shared/multiplicity.glsl, shared/depth.glsl,
// silhouette_caps/determinism.glsl.

layout(triangles) in;
// Two separate triangles of 3 vertices (4 components each): 24 components, far below the
// GL minimums of GL_MAX_GEOMETRY_OUTPUT_VERTICES (256) and ..._TOTAL_OUTPUT_COMPONENTS (1024).
layout(triangle_strip, max_vertices = 6) out;

in vec3 v_world_pos[];

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

// The face's window depth function for the fragment shader, which writes it as every
// fragment's depth (shared/face_depth.frag.glsl): both caps lie at the far plane (the light cap pushed there, the
// dark cap at infinity, clamped). Written with every vertex: outputs are undefined after
// EmitVertex.
flat out dvec3 face_window_depth;

void main() {
    vec3 p0 = v_world_pos[0];
    vec3 p1 = v_world_pos[1];
    vec3 p2 = v_world_pos[2];
    int o = umbra_cap_orientation(p0, p1, p2, u_light);
    if (o == 0) {
        return;
    }
    vec3 c1 = o > 0 ? p1 : p2;
    vec3 c2 = o > 0 ? p2 : p1;

    // Light cap: the triangle facing the light, at the far plane (z-fail counts it always).
    // Clipped at the near plane before the push (shared/depth.glsl).
    vec4 l0 = umbra_clip_from_world_point(u_clip_from_world, vec4(p0, 1.0));
    vec4 l1 = umbra_clip_from_world_point(u_clip_from_world, vec4(c1, 1.0));
    vec4 l2 = umbra_clip_from_world_point(u_clip_from_world, vec4(c2, 1.0));
    dvec3 far = umbra_face_depth_far();
    face_window_depth = far;
    UMBRA_NEAR_CLIP(umbra_near_distance(l0));
    gl_Position = umbra_push_to_far(l0);
    UMBRA_SCENE_CLIP(gl_Position);
    EmitVertex();
    face_window_depth = far;
    UMBRA_NEAR_CLIP(umbra_near_distance(l1));
    gl_Position = umbra_push_to_far(l1);
    UMBRA_SCENE_CLIP(gl_Position);
    EmitVertex();
    face_window_depth = far;
    UMBRA_NEAR_CLIP(umbra_near_distance(l2));
    gl_Position = umbra_push_to_far(l2);
    UMBRA_SCENE_CLIP(gl_Position);
    EmitVertex();
    EndPrimitive();

    if (u_light.w != 0.0) {
        // Dark cap at infinity, reversed winding (outward = away from the light).
        face_window_depth = far;
        UMBRA_NEAR_CLIP(1.0); // the dark cap: never clipped
        gl_Position = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(p0, u_light));
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        face_window_depth = far;
        UMBRA_NEAR_CLIP(1.0); // the dark cap: never clipped
        gl_Position = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(c2, u_light));
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        face_window_depth = far;
        UMBRA_NEAR_CLIP(1.0); // the dark cap: never clipped
        gl_Position = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(c1, u_light));
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        EndPrimitive();
    }
}
