// Deterministic multiplicity with a reference edge, shared by every GPU silhouette method.
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.2: vertex order Eq. 1 / Alg. 2, edge
// multiplicity Alg. 3, CompMultiplicity Alg. 4. The GLSL twin of umbra_geom::order and
// umbra_geom::multiplicity: same operations in the same order, so the same triangle gets the
// same orientation from every edge, every stage (sides in a tessellation/vertex/compute/
// geometry shader, caps in a geometry shader) and every program.
//
// `precise` (GLSL 4.00) forbids the compiler from contracting a * b + c into an fma or
// reassociating: without it, two call sites of the same function could round differently and
// a triangle could be lit through one edge and unlit through another (an open volume).
// GLSL ES 3.00 has no `precise`; there vs-silhouette's ES build relies on the driver not
// contracting (SwiftShader and llvmpipe, measured, do not), which is why it is a separate,
// tested target. The WebGL viewer does not rely on it: its wasm orients each triangle once per
// light and the sides and the caps read that value (crates/umbra-wasm/src/silhouette.rs).
//
// This file has no #version line: a method splices it after its own #version / #define lines.

#ifdef GL_ES
#define UMBRA_PRECISE
#else
#define UMBRA_PRECISE precise
#endif

// sgn(a - b) by comparison: exact for every pair of floats (Alg. 2 without the subtraction,
// which could underflow to 0 for distinct a, b).
int umbra_sign_of_difference(float a, float b) {
    return int(a > b) - int(a < b);
}

// Alg. 2: > 0 when a > b, < 0 when a < b, 0 when equal (lexicographic on x, y, z).
int umbra_greater(vec3 a, vec3 b) {
    return 4 * umbra_sign_of_difference(a.x, b.x) + 2 * umbra_sign_of_difference(a.y, b.y)
        + umbra_sign_of_difference(a.z, b.z);
}

// Alg. 4, CompMultiplicity(A, B, C, L) for A < B < C: sgn(((C - A) x (L.xyz - A * L.w)) . (B - A)).
// +1 when triangle A -> B -> C (counter-clockwise) faces the light.
int umbra_comp_multiplicity(vec3 a, vec3 b, vec3 c, vec4 l) {
    UMBRA_PRECISE vec3 x = c - a;
    UMBRA_PRECISE vec3 y = vec3(l.x - a.x * l.w, l.y - a.y * l.w, l.z - a.z * l.w);
    UMBRA_PRECISE vec3 n = vec3(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
    UMBRA_PRECISE vec3 d = b - a;
    UMBRA_PRECISE float dot_nd = n.x * d.x + n.y * d.y + n.z * d.z;
    return int(dot_nd > 0.0) - int(dot_nd < 0.0);
}

// Alg. 3, one opposite vertex o of edge a -> b (a < b): the orientation of triangle a -> b -> o
// towards the light, computed through the triangle's reference edge.
int umbra_opposite_contribution(vec3 a, vec3 b, vec3 o, vec4 l) {
    if (umbra_greater(a, o) > 0) {
        return umbra_comp_multiplicity(o, a, b, l);   // o < a < b: even permutation
    } else if (umbra_greater(b, o) > 0) {
        return -umbra_comp_multiplicity(a, o, b, l);  // a < o < b: odd permutation
    }
    return umbra_comp_multiplicity(a, b, o, l);       // a < b < o: sorted
}

// Orientation of triangle p0 -> p1 -> p2 towards the light through its reference edge (the
// sorting network of umbra_geom::multiplicity::triangle_orientation): +1 faces the light,
// -1 faces away, 0 edge-on. Used to orient caps consistently with the sides.
int umbra_triangle_orientation(vec3 p0, vec3 p1, vec3 p2, vec4 l) {
    vec3 a = p0;
    vec3 b = p1;
    vec3 c = p2;
    vec3 t;
    int parity = 1;
    if (umbra_greater(a, b) > 0) { t = a; a = b; b = t; parity = -parity; }
    if (umbra_greater(b, c) > 0) { t = b; b = c; c = t; parity = -parity; }
    if (umbra_greater(a, b) > 0) { t = a; a = b; b = t; parity = -parity; }
    return parity * umbra_comp_multiplicity(a, b, c, l);
}

// Pecina et al. 2013, the older determinism paper 001 compares against: the orientation through
// each of the three edges' planes with the light; the triangle is discarded (0) when they
// disagree. Twin of umbra_geom::multiplicity::triangle_orientation_3edge.
int umbra_triangle_orientation_3edge(vec3 p0, vec3 p1, vec3 p2, vec4 l) {
    int s0 = -umbra_comp_multiplicity(p0, p2, p1, l);
    int s1 = -umbra_comp_multiplicity(p1, p0, p2, l);
    int s2 = -umbra_comp_multiplicity(p2, p1, p0, l);
    return (s0 == s1 && s1 == s2) ? s0 : 0;
}

// P extruded away from the light to infinity: (P * l.w - L.xyz, 0) (001 Eq. 2).
vec4 umbra_extrude(vec3 p, vec4 l) {
    return vec4(p * l.w - l.xyz, 0.0);
}
