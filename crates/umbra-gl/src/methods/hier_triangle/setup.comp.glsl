// hier-triangle, per light, one invocation per triangle, in the largest-first order: the
// triangle's shadow frustum as four planes (Sintorn et al. 2014, Section 3: the triangle's
// plane and the three planes through the light and an edge; for a directional light, through
// the edge along the light's direction) and the bound of its directions from the light; then
// its test against the top nodes (live.glsl, test_child: a top node inside its shadow is
// cleared): a triangle whose frustum cuts one is appended to the job list with the mask of
// those it cuts, for the traversal (traverse.comp.glsl). Prepended: hier/hierarchy.glsl,
// hier/region.glsl, frustum.glsl, live.glsl.
//
// The planes are computed in double precision from the f32 vertices (differences and products
// exact, one rounding per sum), normalised, and rounded to f32 once. An edge plane is computed
// from the edge's endpoints in lexicographic order of their positions and only then oriented
// towards the third vertex (the triangle's interior): two triangles sharing an edge — welded or
// not — store the same plane up to its sign (see frustum.glsl). A triangle of zero area, or one
// whose plane holds the light, has no shadow frustum (the reference's watertight test never
// reports a hit on it either) and is skipped.
//
// Each plane is also stored over the view's rays for the nodes' frustum slabs (hier/region.glsl):
// with the point eye + w D(x, y), D = x u_ray_x + y u_ray_y + u_ray_c, a plane (n, w_p) at the
// origin takes the value E + w (a x + b y + c) with E = n.(eye - origin) + w_p, a = n.u_ray_x,
// b = n.u_ray_y, c = n.u_ray_c — computed in double too, rounded once.

layout(local_size_x = 64) in;

uniform uint u_first;
// Triangles, and the job buffer's order and list (hier_triangle/layout.rs Jobs).
uniform uint u_jobs_triangles;
uniform uint u_jobs_order;
uniform uint u_jobs_list;

layout(std430, binding = 8) coherent buffer Jobs { uint jobs[]; };

dvec3 position(uint i) {
    return dvec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

bool lex_less(dvec3 a, dvec3 b) {
    if (a.x != b.x) {
        return a.x < b.x;
    }
    if (a.y != b.y) {
        return a.y < b.y;
    }
    return a.z < b.z;
}

// The least distance from p to the triangle (a, b, c): Ericson, "Real-Time Collision
// Detection", 5.1.5 (the closest point by the Voronoi region it lies in).
double distance_to_triangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    dvec3 ab = b - a;
    dvec3 ac = c - a;
    dvec3 ap = p - a;
    double d1 = dot(ab, ap);
    double d2 = dot(ac, ap);
    if (d1 <= 0.0lf && d2 <= 0.0lf) {
        return length(ap);
    }
    dvec3 bp = p - b;
    double d3 = dot(ab, bp);
    double d4 = dot(ac, bp);
    if (d3 >= 0.0lf && d4 <= d3) {
        return length(bp);
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0lf && d1 >= 0.0lf && d3 <= 0.0lf) {
        return length(p - (a + ab * (d1 / (d1 - d3))));
    }
    dvec3 cp = p - c;
    double d5 = dot(ab, cp);
    double d6 = dot(ac, cp);
    if (d6 >= 0.0lf && d5 <= d6) {
        return length(cp);
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0lf && d2 >= 0.0lf && d6 <= 0.0lf) {
        return length(p - (a + ac * (d2 / (d2 - d6))));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0lf && d4 - d3 >= 0.0lf && d5 - d6 >= 0.0lf) {
        return length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    }
    double denom = 1.0lf / (va + vb + vc);
    return length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

// Whether a live sample may lie in the triangle's shadow frustum, by the receiver map
// (receivers.glsl): some cell of its cone holds a sample farther from the light than the
// triangle. Kept (true) whenever the test does not apply: a point light's cone not within one
// cube face by 4 cells, or more than RECEIVER_MAX_CELLS cells to read.
const uint RECEIVER_MAX_CELLS = 256u;

bool receivers_behind(dvec3 q[3], dvec3 light, bool point) {
    uvec4 cells;
    uint row;
    uint offset;
    double least;
    if (point) {
        dvec3 d[3] = dvec3[3](q[0] - light, q[1] - light, q[2] - light);
        dvec3 c = abs(d[0] + d[1] + d[2]);
        uint m = c.x >= c.y && c.x >= c.z ? 0u : (c.y >= c.z ? 1u : 2u);
        double s = (d[0] + d[1] + d[2])[m] < 0.0lf ? -1.0lf : 1.0lf;
        dvec2 lo = dvec2(1.0e300LF);
        dvec2 hi = dvec2(-1.0e300LF);
        for (int i = 0; i < 3; ++i) {
            double den = s * d[i][m];
            if (!(den > 0.0lf)) {
                return true;
            }
            dvec2 uv = dvec2(d[i][(m + 1u) % 3u], d[i][(m + 2u) % 3u]) / den;
            lo = min(lo, uv);
            hi = max(hi, uv);
        }
        // Strictly inside the face by 4 cells: every direction of the cone has coordinate m as
        // its largest by far more than a sample's rounding, so the samples in it lie on this face.
        double limit = 1.0lf - 4.0lf / double(RECEIVER_SIDE);
        if (lo.x < -limit || lo.y < -limit || hi.x > limit || hi.y > limit) {
            return true;
        }
        float scale = 0.5 * float(RECEIVER_SIDE);
        float margin = 2.0 * RECEIVER_MARGIN;
        cells = uvec4(receiver_cell(float(lo.x) - margin, -1.0, scale, RECEIVER_SIDE),
                      receiver_cell(float(hi.x) + margin, -1.0, scale, RECEIVER_SIDE),
                      receiver_cell(float(lo.y) - margin, -1.0, scale, RECEIVER_SIDE),
                      receiver_cell(float(hi.y) + margin, -1.0, scale, RECEIVER_SIDE));
        row = RECEIVER_SIDE;
        offset = (2u * m + (s < 0.0lf ? 1u : 0u)) * RECEIVER_SIDE * RECEIVER_SIDE;
        least = distance_to_triangle(light, q[0], q[1], q[2]);
    } else {
        vec4 box;
        if (!receiver_box(box)) {
            // No sample at all.
            return false;
        }
        dvec3 u = dvec3(u_light_u);
        dvec3 v = dvec3(u_light_v);
        dvec3 dir = dvec3(u_dir);
        dvec3 origin = dvec3(u_origin);
        dvec2 lo = dvec2(1.0e300LF);
        dvec2 hi = dvec2(-1.0e300LF);
        least = 1.0e300LF;
        for (int i = 0; i < 3; ++i) {
            dvec2 uv = dvec2(dot(u, q[i] - origin), dot(v, q[i] - origin));
            lo = min(lo, uv);
            hi = max(hi, uv);
            least = min(least, -dot(q[i] - origin, dir));
        }
        vec2 extent = vec2(box.y - box.x, box.w - box.z);
        vec2 scale = float(RECEIVER_FLAT) / max(extent, vec2(1.0e-30));
        vec2 margin = (extent + vec2(abs(box.x) + abs(box.y), abs(box.z) + abs(box.w))) * RECEIVER_MARGIN;
        cells = uvec4(receiver_cell(float(lo.x) - margin.x, box.x, scale.x, RECEIVER_FLAT),
                      receiver_cell(float(hi.x) + margin.x, box.x, scale.x, RECEIVER_FLAT),
                      receiver_cell(float(lo.y) - margin.y, box.z, scale.y, RECEIVER_FLAT),
                      receiver_cell(float(hi.y) + margin.y, box.z, scale.y, RECEIVER_FLAT));
        row = RECEIVER_FLAT;
        offset = 0u;
    }
    uint w = cells.y - cells.x + 1u;
    uint count = w * (cells.w - cells.z + 1u);
    if (count > RECEIVER_MAX_CELLS) {
        return true;
    }
    for (uint k = 0u; k < count; ++k) {
        uint e = receivers[offset + (cells.z + k / w) * row + cells.x + k % w];
        if (e != 0u && double(receiver_decode(e)) > least) {
            return true;
        }
    }
    return false;
}

void main() {
    uint rank = u_first + gl_GlobalInvocationID.x;
    if (rank >= u_jobs_triangles) {
        return;
    }
    uint tri = jobs[u_jobs_order + rank];
    dvec3 q[3] = dvec3[3](position(indices[3u * tri]), position(indices[3u * tri + 1u]),
                          position(indices[3u * tri + 2u]));
    bool point = u_light.w != 0.0;
    dvec3 light = dvec3(u_light.xyz) / (point ? double(u_light.w) : 1.0lf);
    dvec3 origin = dvec3(u_origin);
    dvec3 n = cross(q[1] - q[0], q[2] - q[0]);
    double side = point ? dot(n, light - q[0]) : dot(n, light);
    double n_len = length(n);
    if (side == 0.0lf || !(n_len > 0.0lf)) {
        return;
    }
    // Oriented towards the light; w = the light's distance to the plane (point), or the offset
    // at the origin (directional).
    dvec3 n0 = (side > 0.0lf ? n : -n) / n_len;
    double w0 = point ? abs(side) / n_len : dot(n0, origin - q[0]);
    dvec4 e_world[3];
    for (int i = 0; i < 3; ++i) {
        dvec3 a = q[i];
        dvec3 b = q[(i + 1) % 3];
        dvec3 third = q[(i + 2) % 3];
        bool swap = lex_less(b, a);
        dvec3 s0 = swap ? b : a;
        dvec3 s1 = swap ? a : b;
        dvec3 e = point ? cross(s0 - light, s1 - light) : cross(s1 - s0, light);
        double e_len = length(e);
        if (!(e_len > 0.0lf)) {
            return;
        }
        e /= e_len;
        double towards_third = point ? dot(e, third - light) : dot(e, third - s0);
        if (towards_third == 0.0lf) {
            return;
        }
        if (towards_third < 0.0lf) {
            e = -e;
        }
        double w = point ? 0.0lf : dot(e, origin - s0);
        e_world[i] = dvec4(e, w);
    }
    dvec4 world[4] = dvec4[4](dvec4(n0, w0), dvec4(0.0lf), dvec4(0.0lf), dvec4(0.0lf));
    for (int i = 0; i < 3; ++i) {
        world[i + 1] = dvec4(e_world[i]);
    }
    dvec3 eye_rel = dvec3(u_eye_rel);
    for (int k = 0; k < 4; ++k) {
        dvec3 nk = world[k].xyz;
        planes[9u * tri + uint(k)] = vec4(world[k]);
        planes[9u * tri + 4u + uint(k)] = vec4(dot(nk, eye_rel) + world[k].w, dot(nk, dvec3(u_ray_x)),
                                               dot(nk, dvec3(u_ray_y)), dot(nk, dvec3(u_ray_c)));
    }

    // The bound of the triangle's directions from the light (hier/region.glsl, directions_meet).
    vec4 bound;
    if (point) {
        dvec3 t[3];
        for (int i = 0; i < 3; ++i) {
            t[i] = normalize(q[i] - light);
        }
        dvec3 axis = normalize(t[0] + t[1] + t[2]);
        double g = max(max(length(t[0] - axis), length(t[1] - axis)), length(t[2] - axis));
        // A cap of chord radius sqrt 2 or more is a hemisphere or more: not convex, so it need
        // not hold the spherical triangle; say "all directions" then.
        bound = g < 1.4lf ? vec4(vec3(axis), float(g) * (1.0 + 1.0 / 1048576.0) + 1.0e-6) : vec4(1.0, 0.0, 0.0, 4.0);
    } else {
        dvec3 u = dvec3(u_light_u);
        dvec3 v = dvec3(u_light_v);
        dvec2 lo = dvec2(1.0e300LF);
        dvec2 hi = dvec2(-1.0e300LF);
        for (int i = 0; i < 3; ++i) {
            dvec2 uv = dvec2(dot(u, q[i] - origin), dot(v, q[i] - origin));
            lo = min(lo, uv);
            hi = max(hi, uv);
        }
        bound = vec4(float(lo.x), float(hi.x), float(lo.y), float(hi.y));
    }
    planes[9u * tri + 8u] = bound;

    // No live sample can lie in its frustum: no job (receivers.glsl).
    if (!receivers_behind(q, light, point)) {
        return;
    }

    // The top nodes (the virtual root's children; at most 16, hier_triangle/mod.rs).
    Frustum f = load_frustum(tri);
    uint mask = 0u;
    for (uint k = 0u; k < CHILDREN; ++k) {
        if (test_child(f, u_levels, 0u, k)) {
            mask |= 1u << k;
        }
    }
    if (mask != 0u) {
        uint job = atomicAdd(jobs[2], 1u);
        jobs[u_jobs_list + 2u * job] = tri;
        jobs[u_jobs_list + 2u * job + 1u] = mask;
    }
}
