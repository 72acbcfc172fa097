// cs-silhouette: draws the side quads the compute pass (sides.comp.glsl) compacted, with
// glDrawArraysIndirect (vertex count written by the compute shader: no CPU round trip).
// Paper 001, Section 2.2: a quad per unit of multiplicity, extruded to infinity with Eq. 2
// (umbra_extrude from the shared multiplicity.glsl). Prepended: "#version 450 core",
// multiplicity.glsl, shared/depth.glsl (UMBRA_SCENE_CLIP), shared/side_plane.glsl.
//
// No vertex attributes: quad q = gl_VertexID / 6 reads its record (X, Y) and the positions
// from shader storage. Triangles (Y, X, X_inf) and (Y, X_inf, Y_inf): exactly the vertices and
// the order cpu-silhouette uploads (umbra_geom::silhouette).
//
// Face depth: every triangle carries its side's window depth function, flat
// (face_window_depth: the plane through Y, X, X_inf, or u_edge_on_depth seen edge-on;
// shared/side_plane.glsl), which the fragment shader writes as every fragment's depth
// (shared/face_depth.frag.glsl). A flat output comes from the provoking vertex, the LAST of each
// triangle (GL_LAST_VERTEX_CONVENTION, GL's default, which umbra never changes), so only
// v = 2 and v = 5 compute it.

layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 5) readonly buffer Quads { uvec2 quads[]; };

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

// w = 1 vertices land exactly where the scene's vertex shader puts them.
invariant gl_Position;

flat out dvec3 face_window_depth;

vec3 umbra_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

void main() {
    // Never clipped: only light caps are clipped at the near plane (shared/depth.glsl).
    gl_ClipDistance[0] = 1.0;
    uint q = uint(gl_VertexID) / 6u;
    uint v = uint(gl_VertexID) % 6u;
    uvec2 xy = quads[q];
    // v: 0 Y, 1 X, 2 X_inf, 3 Y, 4 X_inf, 5 Y_inf.
    bool is_x = v == 1u || v == 2u || v == 4u;
    bool at_infinity = v == 2u || v == 4u || v == 5u;
    vec3 p = umbra_position(is_x ? xy.x : xy.y);
    face_window_depth = dvec3(0.0LF); // read from the provoking vertices only
    if (v == 2u || v == 5u) {
        vec3 x = umbra_position(xy.x);
        vec4 y_clip = u_clip_from_world * vec4(umbra_position(xy.y), 1.0);
        vec4 x_clip = u_clip_from_world * vec4(x, 1.0);
        vec4 x_inf_clip = u_clip_from_world * umbra_extrude(x, u_light);
        face_window_depth = umbra_face_depth_of_plane(umbra_window_depth_plane(y_clip, x_clip, x_inf_clip));
    }
    if (at_infinity) {
        gl_Position = u_clip_from_world * umbra_extrude(p, u_light);
    } else {
        gl_Position = u_clip_from_world * vec4(p, 1.0);
    }
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
