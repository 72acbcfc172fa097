// vs-silhouette: shadow-volume sides evaluated in the vertex shader from sides-data.
// Paper 003 (Milet et al., WebGL 1.0 shadows), Section 2.4, Algorithm 1, Eq. 1-5, Fig. 2-3;
// compact instanced layout of Section 2.6 (Eq. 8); multiplicity by paper 001 Alg. 3-4 through
// the shared multiplicity.glsl (umbra_opposite_contribution), extrusion Eq. 1 (= 001 Eq. 2).
//
// Common subset of GLSL 4.50 core and GLSL ES 3.00 (the basis of a WebGL 2 build): no
// #version here; the Rust side prepends "#version 450 core" or "#version 300 es" + precision
// statements, then "#define UMBRA_MAX_MULT n", multiplicity.glsl and depth.glsl. ES 3.00 has
// no vertex-input arrays, hence one named attribute per opposite slot.
//
// One instance = one edge record (attribute divisor 1): A, B and UMBRA_MAX_MULT opposite
// slots, A.w = the number of opposites used by this record (umbra_geom::sides_data). The draw
// has 6 * UMBRA_MAX_MULT vertices per instance: side s = gl_VertexID / 6 (the potential side
// index of Alg. 1), v = gl_VertexID % 6 (the vertex of the side's two triangles).
// Every vertex recomputes the record's multiplicity curMult (Alg. 1, line 2): a vertex of a
// side s >= |curMult| is useless and goes to (0,0,0,0), so its whole side degenerates (all six
// vertices of a side share s and curMult) and is not rasterized.

layout(location = 0) in vec4 a_edge_a;   // A.xyz, w = opposites in this record
layout(location = 1) in vec4 a_edge_b;   // B.xyz (A < B in umbra_greater order), w = 1: split edge
#if UMBRA_MAX_MULT > 0
layout(location = 2) in vec4 a_opposite_0;
#endif
#if UMBRA_MAX_MULT > 1
layout(location = 3) in vec4 a_opposite_1;
#endif
#if UMBRA_MAX_MULT > 2
layout(location = 4) in vec4 a_opposite_2;
#endif
#if UMBRA_MAX_MULT > 3
layout(location = 5) in vec4 a_opposite_3;
#endif
#if UMBRA_MAX_MULT > 4
layout(location = 6) in vec4 a_opposite_4;
#endif
#if UMBRA_MAX_MULT > 5
layout(location = 7) in vec4 a_opposite_5;
#endif
#if UMBRA_MAX_MULT > 6
layout(location = 8) in vec4 a_opposite_6;
#endif
#if UMBRA_MAX_MULT > 7
layout(location = 9) in vec4 a_opposite_7;
#endif
#if UMBRA_MAX_MULT > 8
layout(location = 10) in vec4 a_opposite_8;
#endif
#if UMBRA_MAX_MULT > 9
layout(location = 11) in vec4 a_opposite_9;
#endif
#if UMBRA_MAX_MULT > 10
layout(location = 12) in vec4 a_opposite_10;
#endif
#if UMBRA_MAX_MULT > 11
layout(location = 13) in vec4 a_opposite_11;
#endif
#if UMBRA_MAX_MULT > 12
layout(location = 14) in vec4 a_opposite_12;
#endif
#if UMBRA_MAX_MULT > 13
layout(location = 15) in vec4 a_opposite_13;
#endif

uniform mat4 u_clip_from_world;
uniform vec4 u_light;

// w = 1 vertices must land exactly where the scene's vertex shader puts the same point
// (same expression, invariant), so the sides meet the caster surface without cracks.
invariant gl_Position;

// Eq. 3-5 tables (see main()).
const int UMBRA_ID_CCW[6] = int[6](1, 0, 2, 1, 2, 3);
const int UMBRA_ID_CW[6] = int[6](0, 1, 3, 0, 3, 2);
const int UMBRA_ID_CW_SPLIT[6] = int[6](1, 2, 0, 1, 3, 2);

// Alg. 1, line 2: the record's (sub-)multiplicity, the sum of Alg. 3 over its opposites.
// Unrolled: each slot is its own attribute; `count` guards the unused slots.
int umbra_record_multiplicity(vec3 a, vec3 b, int count, vec4 l) {
    int m = 0;
#if UMBRA_MAX_MULT > 0
    if (count > 0) m += umbra_opposite_contribution(a, b, a_opposite_0.xyz, l);
#endif
#if UMBRA_MAX_MULT > 1
    if (count > 1) m += umbra_opposite_contribution(a, b, a_opposite_1.xyz, l);
#endif
#if UMBRA_MAX_MULT > 2
    if (count > 2) m += umbra_opposite_contribution(a, b, a_opposite_2.xyz, l);
#endif
#if UMBRA_MAX_MULT > 3
    if (count > 3) m += umbra_opposite_contribution(a, b, a_opposite_3.xyz, l);
#endif
#if UMBRA_MAX_MULT > 4
    if (count > 4) m += umbra_opposite_contribution(a, b, a_opposite_4.xyz, l);
#endif
#if UMBRA_MAX_MULT > 5
    if (count > 5) m += umbra_opposite_contribution(a, b, a_opposite_5.xyz, l);
#endif
#if UMBRA_MAX_MULT > 6
    if (count > 6) m += umbra_opposite_contribution(a, b, a_opposite_6.xyz, l);
#endif
#if UMBRA_MAX_MULT > 7
    if (count > 7) m += umbra_opposite_contribution(a, b, a_opposite_7.xyz, l);
#endif
#if UMBRA_MAX_MULT > 8
    if (count > 8) m += umbra_opposite_contribution(a, b, a_opposite_8.xyz, l);
#endif
#if UMBRA_MAX_MULT > 9
    if (count > 9) m += umbra_opposite_contribution(a, b, a_opposite_9.xyz, l);
#endif
#if UMBRA_MAX_MULT > 10
    if (count > 10) m += umbra_opposite_contribution(a, b, a_opposite_10.xyz, l);
#endif
#if UMBRA_MAX_MULT > 11
    if (count > 11) m += umbra_opposite_contribution(a, b, a_opposite_11.xyz, l);
#endif
#if UMBRA_MAX_MULT > 12
    if (count > 12) m += umbra_opposite_contribution(a, b, a_opposite_12.xyz, l);
#endif
#if UMBRA_MAX_MULT > 13
    if (count > 13) m += umbra_opposite_contribution(a, b, a_opposite_13.xyz, l);
#endif
    return m;
}

void main() {
    int s = gl_VertexID / 6;        // potential side of this record (Alg. 1 "s")
    int v = gl_VertexID - 6 * s;    // vertex of the side, 0..5 (Eq. 4-5 "v")
    vec3 a = a_edge_a.xyz;
    vec3 b = a_edge_b.xyz;
    int cur_mult = umbra_record_multiplicity(a, b, int(a_edge_a.w), u_light);
    if (s >= abs(cur_mult)) {
        // Alg. 1, line 7: useless vertex, degenerate side.
        gl_Position = vec4(0.0);
        return;
    }
    // Eq. 3-5: which of P0 = A, P1 = B, P2 = A_inf, P3 = B_inf vertex v of the side is. The
    // paper's tables up to the rotation of each triangle, chosen so that the triangles are
    // exactly cpu-silhouette's (umbra_geom::silhouette), vertex for vertex:
    //   curMult > 0 (id_CCW): (B, A, A_inf), (B, A_inf, B_inf) = quad B A A_inf B_inf;
    //   curMult < 0 (id_CW):  (A, B, B_inf), (A, B_inf, A_inf) = quad A B B_inf A_inf.
    // Records of a SPLIT edge (B.w = 1) may have opposite signs that must cancel exactly at
    // every sample, depth test included: their curMult < 0 sides are the curMult > 0 triangles
    // with the last two vertices swapped, (B, A_inf, A), (B, B_inf, A_inf): the same first
    // vertex and the same edges, so the rasterizer's coverage and depth plane are the same
    // and only the facing differs.
    int id;
    if (cur_mult > 0) {
        id = UMBRA_ID_CCW[v];
    } else if (a_edge_b.w != 0.0) {
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
}
