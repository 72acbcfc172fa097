// hier-silhouette, shared by every pass: the shadow-volume faces (light caps and silhouette side
// quads with their multiplicity), their bounds for the hierarchy's node tests, and the exact
// count of the faces a bridge crosses. The idea of the seed authors' RSSV (dormon/Shadows:
// reference-edge silhouettes tested against the view-sample hierarchy, counted along
// "bridges"); the faces are paper 001's (Milet, Kobrtek, Zemcik: deterministic multiplicity
// with a reference edge, Alg. 2-4, multiplicity.glsl), the counting is the winding number of
// the volumes' surface. Prepended after hier/hierarchy.glsl, hier/region.glsl and
// shared/multiplicity.glsl.
//
// The faces are exactly those cpu-silhouette rasterizes (umbra_geom::silhouette): every
// triangle T with orientation o = umbra_triangle_orientation != 0 is a light cap, wound so
// that it faces the light (outward normal o * (V1 - V0) x (V2 - V0)); every edge record
// A -> B (A < B in the vertex order) with multiplicity m != 0 casts m copies of the side quad
// B A A_inf B_inf (A_inf = A extruded away from the light), outward normal
// s = (B - A) x (L.xyz - A L.w). Faces are counter-clockwise seen from outside, the surface
// is closed (every directed edge cancels: the deterministic multiplicity), so its winding
// number W(p) — the z-fail count of cpu-silhouette at p — changes along any segment by the
// signed crossings: +1 (m for a side) when the segment goes from a face's outer side to its
// inner side. W is 0 at the light, and a segment from the light crosses no side quad (its
// plane holds the light; the quad lies beyond its edge), so W(c) = the light caps crossed
// from the light to c.
//
// Predicates. Every decision is the sign of a 3 x 3 determinant det[r0, r1, r2] whose rows are
// differences of f32 inputs (scene positions, the light, node points, samples, the eye):
// computed in f32 first, then in f64, each with a bound on its rounding error (Shewchuk's
// orient3d filter: error <= about 13 eps * permanent for rows carrying two roundings; we use
// 32 eps), so a sign returned is the exact sign. Where both are unsure (|det| within the
// bound: a point on, or within 2^-48 relative of, a face's plane, or a bridge through an
// edge's line) a fixed rule decides, the same for every face sharing the element:
// * a point on a face's plane is moved towards the eye (its side is the eye's side): points
//   are samples and lifted samples, which lie between the eye and the surface, and a sample's
//   count is the count just in front of its surface, which is what the stencil counts (taken
//   at a point moved clear of its surface: count_point);
// * a bridge through an edge's line passes on the edge's positive side for its canonical
//   orientation (endpoints in the vertex order; a ray from a vertex away from the light), the
//   same value for both faces sharing the edge, which see it with opposite signs.
// Those rules are consistent where the exact value is 0; where it is not 0 but unsure they can
// miscount one bridge: such events are counted (counters below) and reported.

// Edge records (A, B, first opposite, opposite count) and then, at u_opposites_offset, the
// opposite vertices (the mesh's EdgeAdjacency, split into records of at most 16,384 opposites
// as cs-silhouette does).
layout(std430, binding = 6) readonly buffer Edges { uint edges[]; };
// Per light: [0, COUNTERS) the counters of unsure events; [u_counts_bridges, +nodes) the
// crossings of the bridge into each node (from its parent's point to its own); [u_counts_partial,
// +pixels) per sample the crossings from its leaf's point to it (the final count W after
// sum.comp.glsl); [u_counts_top, +top nodes) W at each top node's point; [u_counts_orient,
// +triangles) each triangle's orientation o; [u_counts_mult, +records) each edge record's
// multiplicity m.
layout(std430, binding = 8) coherent buffer Counts { int counts[]; };

// Faces [0, u_caps) are the light caps of triangles 0 .. u_caps - 1, faces u_caps + r the side
// quads of edge record r.
uniform uint u_caps;
uniform uint u_opposites_offset;
uniform uint u_counts_bridges;
uniform uint u_counts_partial;
uniform uint u_counts_top;
uniform uint u_counts_orient;
uniform uint u_counts_mult;

// Counters of unsure decisions that the rules above resolved (for tests and statistics):
// a bridge between node points (its subtree's count could be off), a bridge to a sample
// through an edge's line (that sample only), a light-to-top-node segment.
const uint COUNTER_INNER = 0u;
const uint COUNTER_LEAF = 1u;
const uint COUNTER_TOP = 2u;
const uint COUNTERS = 4u;

const int UNSURE = 2;

vec3 position(uint v) {
    return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

// One face: a cap (v = the triangle's vertices in index order) or a side quad (v[0] = A,
// v[1] = B), its weight (o or m) and, for a cap, the triangle (the sample's own-triangle rule).
struct Face {
    vec3 v[3];
    bool quad;
    int weight;
    uint tri;
};

// Face f with its weight as stored by this light's setup (0: no face).
Face load_face(uint f) {
    Face F;
    if (f < u_caps) {
        F.quad = false;
        F.tri = f;
        F.v[0] = position(indices[3u * f]);
        F.v[1] = position(indices[3u * f + 1u]);
        F.v[2] = position(indices[3u * f + 2u]);
        F.weight = counts[u_counts_orient + f];
    } else {
        uint r = f - u_caps;
        F.quad = true;
        F.tri = NO_TRIANGLE;
        F.v[0] = position(edges[4u * r]);
        F.v[1] = position(edges[4u * r + 1u]);
        F.v[2] = F.v[1];
        F.weight = counts[u_counts_mult + r];
    }
    return F;
}

// The sign of det[r0, r1, r2] in f32, rows carrying at most two roundings each: -1, +1, or
// UNSURE when |det| is within 2^-19 of the permanent (32 units of f32 rounding).
int sign_f32(vec3 r0, vec3 r1, vec3 r2) {
    precise float d = r0.x * (r1.y * r2.z - r1.z * r2.y) + r0.y * (r1.z * r2.x - r1.x * r2.z)
        + r0.z * (r1.x * r2.y - r1.y * r2.x);
    vec3 a = abs(r0);
    vec3 b = abs(r1);
    vec3 c = abs(r2);
    float perm = a.x * (b.y * c.z + b.z * c.y) + a.y * (b.z * c.x + b.x * c.z) + a.z * (b.x * c.y + b.y * c.x);
    float bound = perm * (1.0 / 524288.0);
    return d > bound ? 1 : (d < -bound ? -1 : UNSURE);
}

// The same in f64, rows carrying at most one rounding each: 2^-48 (32 units of f64 rounding).
int sign_f64(dvec3 r0, dvec3 r1, dvec3 r2) {
    precise double d = r0.x * (r1.y * r2.z - r1.z * r2.y) + r0.y * (r1.z * r2.x - r1.x * r2.z)
        + r0.z * (r1.x * r2.y - r1.y * r2.x);
    dvec3 a = abs(r0);
    dvec3 b = abs(r1);
    dvec3 c = abs(r2);
    double perm = a.x * (b.y * c.z + b.z * c.y) + a.y * (b.z * c.x + b.x * c.z) + a.z * (b.x * c.y + b.y * c.x);
    double bound = perm * (1.0lf / 281474976710656.0lf);
    return d > bound ? 1 : (d < -bound ? -1 : UNSURE);
}

// The exact sign of det[p0 - s0 q0, p1 - s1 q1, p2 - s2 q2] (f32 inputs; s = 1, or the light's
// w), or UNSURE: f32 first, f64 where f32 is unsure (each f32 product s q is exact in f64,
// so every f64 row carries one rounding).
int sign_rows(vec3 p0, float s0, vec3 q0, vec3 p1, float s1, vec3 q1, vec3 p2, float s2, vec3 q2) {
    precise vec3 a = p0 - s0 * q0;
    precise vec3 b = p1 - s1 * q1;
    precise vec3 c = p2 - s2 * q2;
    int s = sign_f32(a, b, c);
    if (s != UNSURE) {
        return s;
    }
    precise dvec3 da = dvec3(p0) - double(s0) * dvec3(q0);
    precise dvec3 db = dvec3(p1) - double(s1) * dvec3(q1);
    precise dvec3 dc = dvec3(p2) - double(s2) * dvec3(q2);
    return sign_f64(da, db, dc);
}

// The face's plane at point x (f32): det[V1 - V0, V2 - V0, x - V0] for a cap (the sign of
// n . (x - V0), n the index winding's normal), det[B - A, L.xyz - L.w A, x - A] for a side
// (the sign of s . (x - A)); UNSURE on or very near the plane.
int plane_sign(Face F, vec3 x) {
    if (F.quad) {
        return sign_rows(F.v[1], 1.0, F.v[0], u_light.xyz, u_light.w, F.v[0], x, 1.0, F.v[0]);
    }
    return sign_rows(F.v[1], 1.0, F.v[0], F.v[2], 1.0, F.v[0], x, 1.0, F.v[0]);
}

// The face's plane at the eye (u_eye_world, f32, in f64), UNSURE when the eye lies on it.
int eye_sign(Face F) {
    dvec3 e = dvec3(u_eye_world) - dvec3(F.v[0]);
    dvec3 r0 = dvec3(F.v[1]) - dvec3(F.v[0]);
    dvec3 r1 = F.quad ? dvec3(u_light.xyz) - double(u_light.w) * dvec3(F.v[0]) : dvec3(F.v[2]) - dvec3(F.v[0]);
    return sign_f64(r0, r1, e);
}

// The side of point x, x moved towards the eye where it lies on the plane (see the top);
// `counter` counts a decision still unsure (the eye on the plane too: +1).
int side_towards_eye(Face F, vec3 x, uint counter) {
    int s = plane_sign(F, x);
    if (s != UNSURE) {
        return s;
    }
    s = eye_sign(F);
    if (s == UNSURE) {
        atomicAdd(counts[counter], 1);
        return 1;
    }
    return s;
}

// D4(p, q, X, Y): the 4 x 4 determinant of the homogeneous rows p, q, X, Y (all w = 1), or
// D4(p, q, X, L) with the light's row (`to_light`), = -det[q - p, X - p, Y - w_Y p]: the side
// on which the line p -> q passes the line X -> Y. The canonical orientation of a shared line
// (X < Y in the vertex order; X a vertex and Y the light) is the caller's; UNSURE resolves to
// +1 there, and `counter` counts it.
int line_sign(vec3 p, vec3 q, vec3 x, vec3 y, bool to_light, uint counter) {
    int s = to_light ? sign_rows(q, 1.0, p, x, 1.0, p, u_light.xyz, u_light.w, p) : sign_rows(q, 1.0, p, x, 1.0, p, y, 1.0, p);
    if (s == UNSURE) {
        atomicAdd(counts[counter], 1);
        return 1;
    }
    return -s;
}

// D4(p, q, V_k, V_k+1) of a cap's edge k through its canonical orientation.
int cap_edge_sign(vec3 p, vec3 q, vec3 a, vec3 b, uint counter) {
    return umbra_greater(a, b) < 0 ? line_sign(p, q, a, b, false, counter) : -line_sign(p, q, b, a, false, counter);
}

// Whether the line p -> q (crossing the face's plane between p and q) passes through the face:
// the three edges of a cap, or the edges B -> A, A -> A_inf, A_inf -> B_inf and B_inf -> B of
// a side quad, all on the same side. The edge at infinity matters: for a point light the rays
// from the light through A and B also bound the reflected wedge behind the light, where the
// other three signs all flip together (a directional light's rays are parallel: no such
// wedge, and A_inf = B_inf). Edges shared with other faces are evaluated through their
// canonical orientation.
bool line_through(Face F, vec3 p, vec3 q, uint counter) {
    if (F.quad) {
        int s_ab = -line_sign(p, q, F.v[0], F.v[1], false, counter);
        int s_a = -line_sign(p, q, F.v[0], F.v[0], true, counter);
        int s_b = line_sign(p, q, F.v[1], F.v[1], true, counter);
        if (!(s_ab == s_a && s_a == s_b)) {
            return false;
        }
        if (u_light.w == 0.0) {
            return true;
        }
        // D4(p, q, A_inf, B_inf) = -det[q - p, L.xyz - L.w A, L.xyz - L.w B]: this quad's own
        // edge, shared with no other face.
        int s_far = sign_rows(q, 1.0, p, u_light.xyz, u_light.w, F.v[0], u_light.xyz, u_light.w, F.v[1]);
        if (s_far == UNSURE) {
            atomicAdd(counts[counter], 1);
            s_far = 1;
        }
        return -s_far == s_ab;
    }
    int s0 = cap_edge_sign(p, q, F.v[0], F.v[1], counter);
    int s1 = cap_edge_sign(p, q, F.v[1], F.v[2], counter);
    int s2 = cap_edge_sign(p, q, F.v[2], F.v[0], counter);
    return s0 == s1 && s1 == s2;
}

// The signed crossings of face F by the bridge p -> q between two node points:
// W(q) - W(p) contributed by F.
int bridge_crossings(Face F, vec3 p, vec3 q) {
    if (F.weight == 0 || p == q) {
        return 0;
    }
    int sp = side_towards_eye(F, p, COUNTER_INNER);
    int sq = side_towards_eye(F, q, COUNTER_INNER);
    if (sp == sq || !line_through(F, p, q, COUNTER_INNER)) {
        return 0;
    }
    // From the outer side to the inner one: +weight (sp - sq = 2 with the outer side sign +1
    // for a side quad with m > 0, o for a cap; see the top).
    return F.weight * (sp - sq) / 2;
}

// The point a sample's count W is taken at: the sample S moved along its pixel's ray towards
// the eye until it lies 2^-21 of its largest coordinate in front of its own triangle's plane
// (at most as far as its lifted point, hierarchy.glsl lifted(): so it lies within every bound
// that holds S's lifted point and S, and in its leaf's frustum slab), in f32. The count is
// "just in front of the surface", what the stencil counts, and every predicate is then exact
// on one point, the same for every face: the sample, an f32 rounding of a point on its
// triangle, may lie behind its own plane or a coplanar neighbour's by that rounding, and is
// moved clear of both. A face passing within the move of S is within the sample's envelope
// (umbra_oracle::envelope, its position part is 2^-20 of the coordinates and more): band.
// (Moving S only for the faces whose plane passes within 2^-22 of it is not enough: on Crytek
// Sponza's default view at 320 x 180, pixels (270, 63) and (278, 161) come out one count off
// where a bridge's line passes through such a face.)
vec3 count_point(vec3 s, uint own) {
    dvec3 a = dvec3(position(indices[3u * own]));
    dvec3 n = cross(dvec3(position(indices[3u * own + 1u])) - a, dvec3(position(indices[3u * own + 2u])) - a);
    precise vec3 to_eye = u_eye_world - s;
    float mu = lift_fraction(s, to_eye);
    double ln = length(n);
    double along = ln > 0.0lf ? abs(dot(n, dvec3(to_eye))) / ln : 0.0lf;
    float big = max(max(abs(s.x), abs(s.y)), abs(s.z));
    double want = double(big) * (1.0lf / 2097152.0lf);
    float t = along > 0.0lf && want < along * double(mu) ? float(want / along) : mu;
    precise vec3 p = s + min(t, mu) * to_eye;
    return p;
}

// The signed crossings of face F by the bridge from a leaf's point p to a sample's count point
// q (count_point): the sample's count minus the leaf's, contributed by F.
int sample_crossings(Face F, vec3 p, vec3 q) {
    if (F.weight == 0 || p == q) {
        return 0;
    }
    int sp = side_towards_eye(F, p, COUNTER_LEAF);
    int sq = side_towards_eye(F, q, COUNTER_LEAF);
    if (sp == sq || !line_through(F, p, q, COUNTER_LEAF)) {
        return 0;
    }
    return F.weight * (sp - sq) / 2;
}

// The signed crossings of cap F by the segment from the light to point c (a top node's point):
// W(c), contributed by F. For a directional light the segment is the ray from c towards it.
int light_crossings(Face F, vec3 c) {
    if (F.quad || F.weight == 0) {
        return 0;
    }
    int sl = sign_rows(F.v[1], 1.0, F.v[0], F.v[2], 1.0, F.v[0], u_light.xyz, u_light.w, F.v[0]);
    int sc = side_towards_eye(F, c, COUNTER_TOP);
    if (sl == UNSURE) {
        // The light on (or within rounding of) the cap's plane: the segment meets the plane
        // only at the light, inside the cap only if the light lies on it.
        atomicAdd(counts[COUNTER_TOP], 1);
        return 0;
    }
    if (sl == sc) {
        return 0;
    }
    // D4(L, c, X, Y) = det[L.xyz - L.w c, X - c, Y - c], through each edge's canonical
    // orientation.
    int s[3];
    for (int k = 0; k < 3; ++k) {
        vec3 a = F.v[k];
        vec3 b = F.v[(k + 1) % 3];
        bool canonical = umbra_greater(a, b) < 0;
        vec3 x = canonical ? a : b;
        vec3 y = canonical ? b : a;
        int v = sign_rows(u_light.xyz, u_light.w, c, x, 1.0, c, y, 1.0, c);
        if (v == UNSURE) {
            atomicAdd(counts[COUNTER_TOP], 1);
            v = 1;
        }
        s[k] = canonical ? v : -v;
    }
    if (!(s[0] == s[1] && s[1] == s[2])) {
        return 0;
    }
    return F.weight * (sl - sc) / 2;
}

// Face F's bounds for the node tests (region.glsl), computed in f64 and rounded once: four
// planes (unit normal, offset at u_origin) with their forms over the view's rays, and the
// bound of its directions from the light. A cap: its plane (the node must straddle it) and the
// three planes through the light and an edge (its shadow frustum's sides; the cap lies on
// their inner sides). A side quad: its plane (straddled; it holds the light), the plane through
// A B perpendicular to it (the quad lies beyond A B from the light) and the planes through the
// light and A, resp. B, perpendicular to it (the wedge between the rays). A plane whose normal
// is ill-conditioned (its cross product below 2^-24 of the product of its factors: an edge
// pointing at the light, a sliver) is left out (all zeros: it culls nothing), as is the
// direction bound of a face spanning a hemisphere or more.
Frustum face_frustum(Face F) {
    bool point = u_light.w != 0.0;
    dvec3 light = dvec3(u_light.xyz) / (point ? double(u_light.w) : 1.0lf);
    dvec3 origin = dvec3(u_origin);
    dvec4 world[4];
    dvec3 a = dvec3(F.v[0]);
    dvec3 b = dvec3(F.v[1]);
    if (F.quad) {
        dvec3 to_light = point ? light - a : light;
        dvec3 n0 = cross(b - a, to_light);
        double c0 = length(b - a) * length(to_light);
        bool ok0 = length(n0) > c0 * (1.0lf / 16777216.0lf);
        n0 = ok0 ? normalize(n0) : dvec3(0.0lf);
        world[0] = dvec4(n0, -dot(n0, a - origin));
        dvec3 n1 = cross(n0, b - a);
        // The quad lies beyond A B, away from the light.
        double lside = point ? dot(n1, light - a) : dot(n1, light);
        n1 = ok0 && lside != 0.0lf ? normalize(lside > 0.0lf ? -n1 : n1) : dvec3(0.0lf);
        world[1] = dvec4(n1, -dot(n1, a - origin));
        dvec3 n2 = cross(n0, point ? a - light : light);
        n2 = ok0 && length(n2) > 0.0lf ? normalize(dot(n2, b - a) < 0.0lf ? -n2 : n2) : dvec3(0.0lf);
        world[2] = dvec4(n2, -dot(n2, a - origin));
        dvec3 n3 = cross(n0, point ? b - light : light);
        n3 = ok0 && length(n3) > 0.0lf ? normalize(dot(n3, a - b) < 0.0lf ? -n3 : n3) : dvec3(0.0lf);
        world[3] = dvec4(n3, -dot(n3, b - origin));
    } else {
        dvec3 c = dvec3(F.v[2]);
        dvec3 q[3] = dvec3[3](a, b, c);
        dvec3 n = cross(b - a, c - a);
        bool ok = length(n) > length(b - a) * length(c - a) * (1.0lf / 16777216.0lf);
        n = ok ? normalize(n) : dvec3(0.0lf);
        world[0] = dvec4(n, -dot(n, a - origin));
        for (int i = 0; i < 3; ++i) {
            dvec3 s0 = q[i];
            dvec3 s1 = q[(i + 1) % 3];
            dvec3 third = q[(i + 2) % 3];
            dvec3 e = point ? cross(s0 - light, s1 - light) : cross(s1 - s0, light);
            double scale = point ? length(s0 - light) * length(s1 - light) : length(s1 - s0) * length(light);
            double inward = point ? dot(e, third - light) : dot(e, third - s0);
            bool ok_e = length(e) > scale * (1.0lf / 16777216.0lf) && inward != 0.0lf;
            e = ok_e ? normalize(inward < 0.0lf ? -e : e) : dvec3(0.0lf);
            world[i + 1] = dvec4(e, point ? -dot(e, light - origin) : -dot(e, s0 - origin));
        }
    }
    Frustum f;
    dvec3 eye_rel = dvec3(u_eye_rel);
    for (int k = 0; k < 4; ++k) {
        dvec3 nk = world[k].xyz;
        f.p[k] = vec4(world[k]);
        f.p[4 + k] = vec4(dot(nk, eye_rel) + world[k].w, dot(nk, dvec3(u_ray_x)), dot(nk, dvec3(u_ray_y)),
                          dot(nk, dvec3(u_ray_c)));
    }
    // The bound of the face's directions from the light (region.glsl, directions_meet): a cap's
    // three vertices, a side quad's A and B (its points beyond A B have their directions).
    int count = F.quad ? 2 : 3;
    if (point) {
        dvec3 t[3];
        dvec3 sum = dvec3(0.0lf);
        for (int i = 0; i < count; ++i) {
            dvec3 d = dvec3(F.v[i]) - light;
            t[i] = length(d) > 0.0lf ? normalize(d) : dvec3(0.0lf);
            sum += t[i];
        }
        double len = length(sum);
        dvec3 axis = len > 0.0lf ? sum / len : dvec3(1.0lf, 0.0lf, 0.0lf);
        double g = 0.0lf;
        for (int i = 0; i < count; ++i) {
            g = max(g, length(t[i] - axis));
        }
        // A face through the light, or spanning a hemisphere or more: every direction.
        bool through = false;
        for (int i = 0; i < count; ++i) {
            through = through || length(t[i]) == 0.0lf;
        }
        f.p[8] = g < 1.4lf && !through ? vec4(vec3(axis), float(g) * (1.0 + 1.0 / 1048576.0) + 1.0e-6)
                                       : vec4(1.0, 0.0, 0.0, 4.0);
    } else {
        dvec3 u = dvec3(u_light_u);
        dvec3 v = dvec3(u_light_v);
        dvec2 lo = dvec2(1.0e300LF);
        dvec2 hi = dvec2(-1.0e300LF);
        for (int i = 0; i < count; ++i) {
            dvec2 uv = dvec2(dot(u, dvec3(F.v[i]) - origin), dot(v, dvec3(F.v[i]) - origin));
            lo = min(lo, uv);
            hi = max(hi, uv);
        }
        f.p[8] = vec4(float(lo.x), float(hi.x), float(lo.y), float(hi.y));
    }
    return f;
}

// classify_face's tests of a non-empty node (bounds lo, hi): the direction bounds first, then
// the planes through the light over the node's directions, then every plane over the world
// box and the frustum slab. The face's own plane must be straddled, the others must not have
// the whole node on their outer side.
int classify_face_bounds(Frustum f, bool quad, uint level, uint node, vec4 lo, vec4 hi) {
    uint g = node_index(level, node);
    vec4 lb = nodes[NODE_VEC4S * g + 2u];
    if (!directions_meet(f.p[8], lb)) {
        return OUTSIDE;
    }
    // Planes through the light (a directional light: along it): a quad's own plane (0) and
    // its wedge (2, 3); a cap's frustum sides (1-3).
    if (quad) {
        vec2 r0 = light_range(f.p[0], lb);
        vec2 r2 = light_range(f.p[2], lb);
        vec2 r3 = light_range(f.p[3], lb);
        if (r0.y < 0.0 || r0.x > 0.0 || r2.y < 0.0 || r3.y < 0.0) {
            return OUTSIDE;
        }
    } else {
        vec2 r1 = light_range(f.p[1], lb);
        vec2 r2 = light_range(f.p[2], lb);
        vec2 r3 = light_range(f.p[3], lb);
        if (r1.y < 0.0 || r2.y < 0.0 || r3.y < 0.0) {
            return OUTSIDE;
        }
    }
    vec3 c = 0.5 * (lo.xyz + hi.xyz) - u_origin;
    vec3 h = 0.5 * (hi.xyz - lo.xyz);
    vec4 tile = node_tile(level, node);
    vec2 w = vec2(lo.w, hi.w);
    vec2 b0 = plane_range(f, 0u, c, h, tile, w);
    if (b0.y < 0.0 || b0.x > 0.0) {
        return OUTSIDE;
    }
    vec2 b1 = plane_range(f, 1u, c, h, tile, w);
    vec2 b2 = plane_range(f, 2u, c, h, tile, w);
    vec2 b3 = plane_range(f, 3u, c, h, tile, w);
    if (b1.y < 0.0 || b2.y < 0.0 || b3.y < 0.0) {
        return OUTSIDE;
    }
    return PARTIAL;
}

// Whether face F (its bounds f) may meet the region of node `node` at `level` that holds the
// node's samples, its lifted points and so every bridge below it: OUTSIDE or PARTIAL (an empty
// node is OUTSIDE untested). Counted as work when it tests.
int classify_face(Frustum f, bool quad, uint level, uint node) {
    uint g = node_index(level, node);
    vec4 lo = nodes[NODE_VEC4S * g];
    vec4 hi = nodes[NODE_VEC4S * g + 1u];
    if (lo.w > hi.w) {
        return OUTSIDE;
    }
    int c = classify_face_bounds(f, quad, level, node, lo, hi);
    count_work(WORK_NODES_TESTED, 1u);
    count_work(WORK_NODES_PRUNED, c == PARTIAL ? 0u : 1u);
    return c;
}

// A node's point (the lifted point of one of its samples; hier/bounds.comp.glsl).
vec3 node_point(uint level, uint node) {
    return nodes[NODE_VEC4S * node_index(level, node) + 3u].xyz;
}
