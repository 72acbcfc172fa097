// vs-silhouette: shadow-volume sides evaluated in the vertex shader from sides-data.
// Paper 003 (Milet et al., WebGL 1.0 shadows), Section 2.4, Algorithm 1, Eq. 1-5, Fig. 2-3;
// compact instanced layout of Section 2.6 (Eq. 8); multiplicity by paper 001 Alg. 3-4 through
// the shared multiplicity.glsl (umbra_opposite_contribution), extrusion Eq. 1 (= 001 Eq. 2).
//
// Common subset of GLSL 4.50 core and GLSL ES 3.00 (the basis of a WebGL 2 build): no
// #version here; the Rust side (vs_silhouette/mod.rs) prepends "#version 450 core" or
// "#version 300 es" + precision statements, multiplicity.glsl, depth.glsl and the generated
// record access:
//   UMBRA_MAX_MULT        opposite slots per edge record (maxMult);
//   UMBRA_RECORDS         edge records per instance;
//   UmbraEdgeRecord umbra_edge_record(int r)
//                         record r of this instance: a = (A, opposites in this record),
//                         b = (B, 1 if the edge is split into several records), o[i] = (O_i, 1),
//                         read from UMBRA_RECORDS * (2 + UMBRA_MAX_MULT) vec4 attributes that
//                         advance once per instance (divisor 1). ES 3.00 has no vertex-input
//                         arrays, hence generated names; several records per instance because
//                         instances are expensive on some implementations (llvmpipe runs its
//                         vertex pipeline once per instance).
//
// The draw has UMBRA_RECORDS * 6 * UMBRA_MAX_MULT vertices per instance: record
// r = gl_VertexID / (6 * maxMult), potential side s (Alg. 1 "s") and vertex v of the side's
// two triangles (Eq. 4-5 "v") from the rest. Every vertex recomputes its record's multiplicity
// curMult (Alg. 1, line 2): a vertex of a side s >= |curMult| is useless and goes to (0,0,0,0),
// so its whole side degenerates (all six vertices of a side share s and curMult) and is not
// rasterized.

#ifdef GL_ES
uniform mat4 u_clip_from_world;
#else
// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body in GLSL 4.50).
// The face's window depth function for the fragment shader, which writes
// it as every fragment's depth (shared/face_depth.frag.glsl).
// GLSL 4.50 only (doubles).
flat out dvec3 face_window_depth;
#endif
uniform vec4 u_light;

// w = 1 vertices must land exactly where the scene's vertex shader puts the same point
// (same expression, invariant), so the sides meet the caster surface without cracks.
invariant gl_Position;

// Eq. 3-5 tables (see main()).
const int UMBRA_ID_CCW[6] = int[6](1, 0, 2, 1, 2, 3);
const int UMBRA_ID_CW[6] = int[6](0, 1, 3, 0, 3, 2);
const int UMBRA_ID_CW_SPLIT[6] = int[6](1, 2, 0, 1, 3, 2);

void main() {
    // Never clipped: only light caps are clipped at the near plane (shared/depth.glsl).
    UMBRA_NEAR_CLIP(1.0);
#ifndef GL_ES
    face_window_depth = dvec3(0.0LF); // read from the provoking vertices only (below)
#endif
    int per_record = 6 * UMBRA_MAX_MULT;
    int r = gl_VertexID / per_record;          // record of this instance
    int within = gl_VertexID - per_record * r;
    int s = within / 6;                         // potential side of the record (Alg. 1 "s")
    int v = within - 6 * s;                     // vertex of the side, 0..5 (Eq. 4-5 "v")
    UmbraEdgeRecord rec = umbra_edge_record(r);
    vec3 a = rec.a.xyz;
    vec3 b = rec.b.xyz;
    int count = int(rec.a.w);
    // Alg. 1, line 2: the record's (sub-)multiplicity, Alg. 3 summed over its opposites.
    int cur_mult = 0;
    for (int i = 0; i < UMBRA_MAX_MULT; ++i) {
        if (i < count) {
            cur_mult += umbra_opposite_contribution(a, b, rec.o[i].xyz, u_light);
        }
    }
    if (s >= abs(cur_mult)) {
        // Alg. 1, line 7: useless vertex, degenerate side.
        gl_Position = UMBRA_CULLED;
        return;
    }
    // Eq. 3-5: which of P0 = A, P1 = B, P2 = A_inf, P3 = B_inf vertex v of the side is. The
    // paper's tables up to the rotation of each triangle, chosen so that the triangles are
    // exactly cpu-silhouette's (umbra_geom::silhouette), vertex for vertex:
    //   curMult > 0 (id_CCW): (B, A, A_inf), (B, A_inf, B_inf) = quad B A A_inf B_inf;
    //   curMult < 0 (id_CW):  (A, B, B_inf), (A, B_inf, A_inf) = quad A B B_inf A_inf.
    // Records of a SPLIT edge (b.w = 1) may have opposite signs that must cancel in the
    // stencil: their curMult < 0 sides are the curMult > 0 triangles with the last two
    // vertices swapped, (B, A_inf, A), (B, B_inf, A_inf): the same first vertex and the same
    // edges, so the rasterizer sets up the same coverage and depth plane, only the facing
    // differs (measured: exact cancellation except rare samples on a grazing side, where
    // clipping the triangle at w = 0 rounds differently for the reversed order).
    int id;
    if (cur_mult > 0) {
        id = UMBRA_ID_CCW[v];
    } else if (rec.b.w != 0.0) {
        id = UMBRA_ID_CW_SPLIT[v];
    } else {
        id = UMBRA_ID_CW[v];
    }
    // Eq. 1-2: P2, P3 extruded to infinity (w = 0); P0, P1 the edge itself (w = 1).
    if (id < 2) {
        vec3 p = id == 0 ? a : b;
        gl_Position = u_clip_from_world * vec4(p, 1.0);
    } else {
        gl_Position = u_clip_from_world * umbra_extrude(id == 2 ? a : b, u_light);
    }
#ifndef GL_ES
    // A flat output comes from the provoking vertex, the LAST of each triangle
    // (GL_LAST_VERTEX_CONVENTION, GL's default, which umbra never changes): only v = 2 and 5
    // compute the side's plane (every table's quad lies in the plane of A, B, A_inf; computed
    // from the edge in canonical order, shared/side_plane.glsl).
    if (v == 2 || v == 5) {
        face_window_depth = umbra_face_depth_of_plane(umbra_side_depth_plane(a, b, u_light));
    }
#endif
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
