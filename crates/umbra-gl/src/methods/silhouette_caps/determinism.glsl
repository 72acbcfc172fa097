// The triangle-orientation test shared by the sides and the caps of the GPU silhouette methods
// (ts-silhouette, gs-silhouette and their -3edge variants). No #version line: spliced after
// shared/multiplicity.glsl, which it calls.
//
// Default: paper 001 (Milet, Kobrtek, Zemcik), Section 2.2, the reference edge: Alg. 3 per
// opposite vertex (umbra_opposite_contribution, calling Alg. 4 on the sorted triangle) and, for
// the caps (Section 2.3), the same Alg. 4 on the same sorted triangle
// (umbra_triangle_orientation).
//
// UMBRA_THREE_EDGE: the older determinism of Peciva et al. 2013 that paper 001 compares against
// (Section 2.2, "calculating multiplicity per triangle ... if the 3 results throughout all 3
// edges were not consistent, we discarded the triangle"; Tables 1-4, first column): the
// triangle is tested against the planes through each of its three edges and the light
// (umbra_triangle_orientation_3edge) and discarded (0) when the three disagree. What makes it
// deterministic is that every occurrence of the triangle (its three edges' patches and its
// cap) evaluates those planes on the SAME vertex order: the triangle sorted by Alg. 2
// (umbra_greater), the wanted winding's sign being the parity of the permutation - exactly the
// branches of Alg. 3 and the sorting network of umbra_triangle_orientation, with the 3-edge
// test in place of Alg. 4. (Evaluated on the triangle's own winding instead, the plane through
// edge A-B would be computed from A by one triangle occurrence and from B by another, with
// different rounding, and the volume could open.)

#ifdef UMBRA_THREE_EDGE

// Orientation of triangle a -> b -> o (a < b) through its three edge planes.
int umbra_side_contribution(vec3 a, vec3 b, vec3 o, vec4 l) {
    if (umbra_greater(a, o) > 0) {
        return umbra_triangle_orientation_3edge(o, a, b, l);   // o < a < b: even permutation
    } else if (umbra_greater(b, o) > 0) {
        return -umbra_triangle_orientation_3edge(a, o, b, l);  // a < o < b: odd permutation
    }
    return umbra_triangle_orientation_3edge(a, b, o, l);       // a < b < o: sorted
}

// Orientation of triangle p0 -> p1 -> p2 through its three edge planes, on the sorted vertices.
int umbra_cap_orientation(vec3 p0, vec3 p1, vec3 p2, vec4 l) {
    vec3 a = p0;
    vec3 b = p1;
    vec3 c = p2;
    vec3 t;
    int parity = 1;
    if (umbra_greater(a, b) > 0) { t = a; a = b; b = t; parity = -parity; }
    if (umbra_greater(b, c) > 0) { t = b; b = c; c = t; parity = -parity; }
    if (umbra_greater(a, b) > 0) { t = a; a = b; b = t; parity = -parity; }
    return parity * umbra_triangle_orientation_3edge(a, b, c, l);
}

#else

// Orientation of triangle a -> b -> o (a < b) through its reference edge (Alg. 3, one term).
int umbra_side_contribution(vec3 a, vec3 b, vec3 o, vec4 l) {
    return umbra_opposite_contribution(a, b, o, l);
}

// Orientation of triangle p0 -> p1 -> p2 through its reference edge (Section 2.3 caps).
int umbra_cap_orientation(vec3 p0, vec3 p1, vec3 p2, vec4 l) {
    return umbra_triangle_orientation(p0, p1, p2, l);
}

#endif

// World point -> clip space. `precise`: no contraction into fused multiply-adds, so the same
// vertex gets the same clip coordinates in every stage and program (the sides' edge vertices
// and the light caps' vertices share screen edges).
vec4 umbra_clip_from_world_point(mat4 clip_from_world, vec4 p) {
    precise vec4 clip = clip_from_world * p;
    return clip;
}
