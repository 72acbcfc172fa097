// vs-triangle: the naive per-triangle shadow volume of EVERY triangle, extruded in the vertex
// shader, without any silhouette: the baseline every silhouette method is measured against.
//
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.1: a per-triangle volume needs no
// preprocessing and works on any triangle soup; Section 2.2-2.3: the triangle is oriented
// towards the light through its reference edge (Alg. 2 order, Alg. 4 CompMultiplicity, via
// umbra_triangle_orientation), so its caps and sides agree with every other method bit for
// bit; Eq. 2 extrusion (umbra_extrude). Vertex-shader extrusion as in McGuire 2004 (GPU Gems)
// and paper 002, here with no extra vertex data: the triangle is fetched by gl_VertexID.
// Light caps pushed to the far plane: paper 003, Eq. 6 (umbra_push_to_far).
//
// Draw: glDrawArrays(GL_TRIANGLES, 0, N * u_vertices_per_triangle), non-indexed. Vertex
// k = gl_VertexID mod u_vertices_per_triangle of triangle t = gl_VertexID / ...:
//   k  0..17  three side quads, one per edge P -> Q of the light-facing winding, 2 triangles each
//             (u_pass 0: the +1 sides only; u_pass 1: the -1 sides only, and nothing else)
//   k 18..20  light cap (the triangle wound to face the light), pushed to the far plane
//   k 21..23  dark cap (the extruded triangle, reversed winding) - point lights only
// u_vertices_per_triangle = 24 (z-fail, point light), 21 (z-fail, directional light: the dark
// cap has zero area, every vertex extrudes to -L), 18 (z-pass: no caps; and always for u_pass 1).
//
// Side quads, and why there are two draws. A side quad lies on the edge it was cast from; the
// two light-facing neighbours of an edge cast it with opposite windings, +1 and -1, which must
// cancel at EVERY sample - also where a receiver (or the caster itself) is at the quad's depth
// up to rounding. That needs the two copies to rasterize bit-identically: same clipped polygon,
// same triangulation, same interpolated depth. A reversed vertex order does not give that (the
// clipper walks the polygon from the first vertex and triangulates it as a fan from there), so
// every side is emitted in ONE canonical vertex order, whichever triangle casts it: with A < B
// the edge's endpoints in umbra_greater order, the quad B A A_inf B_inf as the triangles
// (B, A, A_inf) (B, A_inf, B_inf). Its winding is right for a triangle traversing A -> B
// (multiplicity +1). The sides of triangles traversing B -> A (multiplicity -1) are drawn in a
// second draw (u_pass = 1) with glFrontFace(GL_CW): the same primitives, counted as the
// opposite face. In each draw the sides of the other sign collapse to a point (zero area).
//
// An edge-on triangle (orientation 0) casts nothing: all its vertices collapse to one point,
// so its primitives have zero area and produce no fragments.
//
// Face depth: every primitive carries its face's window-space depth function, flat
// (face_window_depth, shared/side_plane.glsl), which the fragment shader writes as every
// fragment's depth (shared/face_depth.frag.glsl). Vertex pulling lets each vertex know its face. A flat output is taken from the
// primitive's provoking vertex, the LAST one (GL_LAST_VERTEX_CONVENTION, GL's default, which
// umbra never changes), so only those compute it: a side's plane (in double, from the edge's
// endpoints in canonical order, identical for both copies of a shared side) at j = 2 and 5 of
// its 6 vertices, the far plane at the caps' k = 20 and 23; the 4 other side vertices skip the
// double-precision plane.
//
// Inputs: the scene's own buffers as shader storage (no copy): positions (vec3, tightly
// packed, read as floats) and triangles (3 uints each).

layout(std430, binding = UMBRA_POSITIONS_BINDING) readonly buffer Positions {
    float positions[];
};
layout(std430, binding = UMBRA_TRIANGLES_BINDING) readonly buffer Triangles {
    uint triangles[];
};

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;
uniform int u_vertices_per_triangle;
// 0: +1 sides and caps (glFrontFace CCW); 1: -1 sides (glFrontFace CW).
uniform int u_pass;

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

// The face's window depth function, read from the provoking vertex (see the header).
flat out dvec3 face_window_depth;

vec3 umbra_fetch(uint v) {
    return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

void main() {
    UMBRA_NEAR_CLIP(1.0);
    // Only provoking vertices' values are read (see the header).
    face_window_depth = dvec3(0.0LF);
    int t = gl_VertexID / u_vertices_per_triangle;
    int k = gl_VertexID - t * u_vertices_per_triangle;
    uint first = 3u * uint(t);
    vec3 p0 = umbra_fetch(triangles[first]);
    vec3 p1 = umbra_fetch(triangles[first + 1u]);
    vec3 p2 = umbra_fetch(triangles[first + 2u]);

    int o = umbra_triangle_orientation(p0, p1, p2, u_light);
    if (o == 0) {
        // Edge-on or degenerate: no volume (all 24 vertices at one point).
        gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    if (o < 0) {
        // Wind the triangle to face the light: it is the light cap of its own volume.
        vec3 s = p1;
        p1 = p2;
        p2 = s;
    }

    vec4 world;
    bool push_to_far = false;
    if (k < 18) {
        int e = k / 6;
        int j = k - 6 * e;
        vec3 p = e == 0 ? p0 : (e == 1 ? p1 : p2);
        vec3 q = e == 0 ? p1 : (e == 1 ? p2 : p0);
        bool forward = umbra_greater(p, q) < 0; // p < q: the triangle traverses A -> B, +1
        if (forward != (u_pass == 0)) {
            gl_Position = vec4(0.0, 0.0, 0.0, 1.0); // the other draw's side: zero area
            return;
        }
        vec3 a = forward ? p : q;
        vec3 b = forward ? q : p;
        // (B, A, A_inf) (B, A_inf, B_inf) in both draws.
        world = j == 0 || j == 3 ? vec4(b, 1.0)
              : j == 1 ? vec4(a, 1.0)
              : j == 2 || j == 4 ? umbra_extrude(a, u_light)
              : umbra_extrude(b, u_light);
        if (j == 2 || j == 5) {
            face_window_depth = umbra_face_depth_of_plane(umbra_side_depth_plane(a, b, u_light));
        }
    } else if (k < 21) {
        vec3 p = k == 18 ? p0 : (k == 19 ? p1 : p2);
        world = vec4(p, 1.0);
        push_to_far = true;
        face_window_depth = umbra_face_depth_far();
    } else {
        vec3 p = k == 21 ? p0 : (k == 22 ? p2 : p1);
        world = umbra_extrude(p, u_light);
        face_window_depth = umbra_face_depth_far();
    }
    vec4 clip = u_clip_from_world * world;
    // Light caps: clipped at the near plane, then pushed (shared/depth.glsl); the rest never.
    UMBRA_NEAR_CLIP(push_to_far ? umbra_near_distance(clip) : 1.0);
    gl_Position = push_to_far ? umbra_push_to_far(clip) : clip;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
