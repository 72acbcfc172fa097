// hier-triangle, per light, one invocation per triangle: the triangle's shadow frustum as four
// planes (Sintorn et al. 2014, Section 3: the triangle's plane and the three planes through the
// light and an edge; for a directional light, through the edge along the light's direction),
// then its test against every top node of the hierarchy. Prepended: the header and
// common.glsl, then the generated fallback chain (descend_into).
//
// The planes are computed in double precision from the f32 vertices (differences and products
// exact, one rounding per sum), normalised, and rounded to f32 once. An edge plane is computed
// from the edge's endpoints in lexicographic order of their positions and only then oriented
// towards the third vertex (the triangle's interior): two triangles sharing an edge — welded or
// not — store the same plane up to its sign (see common.glsl). A triangle of zero area, or one
// whose plane holds the light, has no shadow frustum (the reference's watertight test never
// reports a hit on it either) and is skipped.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_triangle_count;

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

void main() {
    uint tri = u_first + gl_GlobalInvocationID.x;
    if (tri >= u_triangle_count) {
        return;
    }
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
    vec4 edge[3];
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
        edge[i] = vec4(vec3(e), float(w));
    }
    planes[4u * tri] = vec4(vec3(n0), float(w0));
    planes[4u * tri + 1u] = edge[0];
    planes[4u * tri + 2u] = edge[1];
    planes[4u * tri + 3u] = edge[2];

    uint top = u_levels - 1u;
    uint top_nodes = u_level[top].x * u_level[top].y;
    for (uint node = 0u; node < top_nodes; ++node) {
        if (visit(tri, top, node) == PARTIAL) {
            descend_into(tri, top, node);
        }
    }
}
