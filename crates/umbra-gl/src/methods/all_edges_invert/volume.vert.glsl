// all-edges-invert: every triangle's full shadow volume, no silhouette, extruded in the vertex
// shader. Paper 002 ("real-time shadow method based on the shadow volume", for highly concave
// casters such as trees), Section 3: "For every triangle casting the shadow, seven additional
// shadow volume triangles has to be drawn" - 3 side quads (6 triangles) and the back (dark)
// cap - "then, a shadowing triangle is redrawn once more" (the light cap). Extrusion of paper
// 001 Eq. 2 (umbra_extrude); the light cap is pushed to the far plane (paper 003, Eq. 6,
// umbra_push_to_far) where paper 002 relies on its own depth failing the LESS test against
// the caster: at the far plane it fails at every sample, the same outcome without depending on
// identical rasterization.
//
// No orientation: paper 002's stencil operations treat front and back faces alike (face
// culling off), so winding does not matter and nothing is computed per triangle but the
// extrusion. Winding being free, every side is emitted in one canonical vertex order (edge
// endpoints A < B in umbra_greater order: (B, A, A_inf) (B, A_inf, B_inf)), so the copies
// that neighbouring triangles put on their shared edge rasterize identically and agree on
// which samples lie beyond the edge (no pinholes where a receiver meets the side's plane). Each triangle's 8 triangles are consecutive vertices of one non-indexed draw, so
// the stencil sees one closed volume after another (in primitive order).
//
// Draw: glDrawArrays(GL_TRIANGLES, 0, N * u_vertices_per_triangle); vertex
// k = gl_VertexID mod u_vertices_per_triangle of triangle t = gl_VertexID / ...:
//   k  0..17  side quads of edges p0p1, p1p2, p2p0: (B, A, A_inf) (B, A_inf, B_inf), A < B
//   k 18..20  light cap (the triangle), pushed to the far plane
//   k 21..23  dark cap at infinity (skipped for a directional light: zero area)
// Inputs: the scene's own buffers as shader storage (positions as floats, 3 indices each).

layout(std430, binding = UMBRA_POSITIONS_BINDING) readonly buffer Positions {
    float positions[];
};
layout(std430, binding = UMBRA_TRIANGLES_BINDING) readonly buffer Triangles {
    uint triangles[];
};

uniform mat4 u_clip_from_world;
uniform vec4 u_light;
uniform int u_vertices_per_triangle;

invariant gl_Position;

vec3 umbra_fetch(uint v) {
    return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

void main() {
    int t = gl_VertexID / u_vertices_per_triangle;
    int k = gl_VertexID - t * u_vertices_per_triangle;
    uint first = 3u * uint(t);
    vec3 p0 = umbra_fetch(triangles[first]);
    vec3 p1 = umbra_fetch(triangles[first + 1u]);
    vec3 p2 = umbra_fetch(triangles[first + 2u]);

    vec4 world;
    bool push_to_far = false;
    if (k < 18) {
        int e = k / 6;
        int j = k - 6 * e;
        vec3 p = e == 0 ? p0 : (e == 1 ? p1 : p2);
        vec3 q = e == 0 ? p1 : (e == 1 ? p2 : p0);
        bool forward = umbra_greater(p, q) < 0;
        vec3 a = forward ? p : q;
        vec3 b = forward ? q : p;
        world = j == 0 || j == 3 ? vec4(b, 1.0)
              : j == 1 ? vec4(a, 1.0)
              : j == 2 || j == 4 ? umbra_extrude(a, u_light)
              : umbra_extrude(b, u_light);
    } else if (k < 21) {
        world = vec4(k == 18 ? p0 : (k == 19 ? p1 : p2), 1.0);
        push_to_far = true;
    } else {
        world = umbra_extrude(k == 21 ? p0 : (k == 22 ? p2 : p1), u_light);
    }
    vec4 clip = u_clip_from_world * world;
    // Light caps: clipped at the near plane, then pushed (shared/depth.glsl); the rest never.
    UMBRA_NEAR_CLIP(push_to_far ? umbra_near_distance(clip) : 1.0);
    gl_Position = push_to_far ? umbra_push_to_far(clip) : clip;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
