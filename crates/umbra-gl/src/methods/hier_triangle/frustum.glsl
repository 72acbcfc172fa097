// hier-triangle: the exact tests of one triangle's shadow frustum against a node of samples
// and against one sample.
// Sintorn, Kämpe, Olsson, Assarsson, "Per-Triangle Shadow Volumes Using a View-Sample Cluster
// Hierarchy" (I3D 2014), Sections 3-4. Prepended after hier/hierarchy.glsl and
// hier/region.glsl.
//
// A sample S on triangle T is shadowed by triangle T' != T iff the segment from S to the light
// meets T' (closed, two-sided) farther than u_eps_near from S and farther than u_eps from the
// light: the ray-traced reference's rule (crates/umbra-oracle, docs/exactness.md), whose eps is
// u_eps (1e-5 of the scene), with the sample end at half of it so that a hit the rounding puts
// on the other side of eps lies in the reference's "within eps" band class, never outside the
// band. As planes, with S relative to u_origin (the point light itself, or the scene's centre
// for a directional light) and every plane stored as (unit normal, offset at u_origin):
//   plane 0 (T' oriented towards the light, w = the light's distance to it for a point light):
//     S strictly behind it, d = -plane0(S) > 0, and the eps conditions on the hit distance
//     t |S - L| = d |S - L| / (d + w) (point) or d / cos (directional);
//   planes 1-3 (through the light and an edge, or through the edge along the light's
//     direction, oriented towards T's interior): plane_i(S) >= 0 (closed edges, as the
//     reference's watertight test).
// The edge planes are computed (setup.comp.glsl) from the edge's endpoints in lexicographic
// order and only then oriented, so two triangles sharing an edge store bit-identical planes up
// to the sign, and plane_at below is evaluated identically for both (precise): a ray through a
// shared edge gives v and -v, one of which is >= 0 — the test is watertight like the reference.

// Per triangle, 9 vec4 (written by setup.comp.glsl for this light): [0, 4) the four planes
// above; [4, 8) the same planes over the view's rays, (E, a, b, c): at the point eye + w D(x, y)
// of NDC (x, y) and clip w, the plane's value is E + w (a x + b y + c) (see classify_node);
// [8] the bound of its directions from the light: a point light's unit axis and chord radius
// (every direction from the light through the triangle lies within it), a directional light's
// box of its vertices along u_light_u, u_light_v.
layout(std430, binding = 6) buffer Planes { vec4 planes[]; };

Frustum load_frustum(uint tri) {
    Frustum f;
    for (uint i = 0u; i < 9u; ++i) {
        f.p[i] = planes[9u * tri + i];
    }
    return f;
}


// The clip depths w within `span` at which plane k of the frustum can hold a point of the
// tile's pyramid (NDC tile x [w.x, w.y] of clip w, as plane_range's slab): for an edge plane
// (k >= 1) where its value can be >= 0, for the triangle's plane (k = 0) where it can be < 0
// (behind the triangle, seen from the light). Over the tile the value at depth w lies within
// E + w [g_min, g_max], up to the slab's tolerance at w.y; each condition is one linear
// inequality A + w G >= 0, whose root is widened by 2^-20 of itself (the division's rounding is
// a few units in the last place). Returns an empty span (x > y) when no depth qualifies.
vec2 frustum_depths(Frustum f, uint k, vec4 tile, vec2 w, vec2 span) {
    vec4 q = f.p[4u + k];
    vec2 g_range = ray_factor_range(q, tile);
    float g_min = g_range.x;
    float g_max = g_range.y;
    float q_tol = (abs(q.x) + w.y * (abs(q.y) + abs(q.z) + abs(q.w))) * (1.0 / 1048576.0);
    // Edge plane: its largest value, q.x + w g_max (+ tolerance), >= 0. The triangle's plane:
    // its least value, q.x + w g_min (- tolerance), < 0, as -(least) >= 0.
    float a = k == 0u ? q_tol - q.x : q.x + q_tol;
    float g = k == 0u ? -g_min : g_max;
    if (g > 0.0) {
        float root = -a / g;
        span.x = max(span.x, root - abs(root) * (1.0 / 1048576.0));
    } else if (g < 0.0) {
        float root = a / -g;
        span.y = min(span.y, root + abs(root) * (1.0 / 1048576.0));
    } else if (a < 0.0) {
        span = vec2(1.0, 0.0);
    }
    return span;
}

// Triangle `tri`'s shadow frustum against node `node` at `level` (bounds lo, hi with the w
// range in their w components): OUTSIDE (no sample of the node can be shadowed by it), INSIDE
// (every sample is, with both eps margins), or PARTIAL. Cheapest and most selective first:
// the direction bounds (the triangle's against the node's), then the edge planes over the
// node's directions (an edge plane holds the light or its direction, so the direction bound is
// the tight one for it), then the triangle's plane over the world box and the frustum slab;
// last, for a node not inside, the depths at which the frustum meets the node's pyramid against
// the node's depth occupancy (region.glsl).
int classify_node(Frustum f, uint level, uint node, vec4 lo, vec4 hi) {
    vec4 lb = nodes[NODE_VEC4S * node_index(level, node) + 2u];
    if (!directions_meet(f.p[8], lb)) {
        return OUTSIDE;
    }
    vec2 e1 = light_range(f.p[1], lb);
    vec2 e2 = light_range(f.p[2], lb);
    vec2 e3 = light_range(f.p[3], lb);
    if (e1.y < 0.0 || e2.y < 0.0 || e3.y < 0.0) {
        return OUTSIDE;
    }
    vec3 c = 0.5 * (lo.xyz + hi.xyz) - u_origin;
    vec3 h = 0.5 * (hi.xyz - lo.xyz);
    vec4 tile = node_tile(level, node);
    // The edge planes over the world box and the slab too: the direction bound of a node
    // across a depth discontinuity is wide where these are not.
    vec2 w = vec2(lo.w, hi.w);
    vec2 b1 = plane_range(f, 1u, c, h, tile, w);
    vec2 b2 = plane_range(f, 2u, c, h, tile, w);
    vec2 b3 = plane_range(f, 3u, c, h, tile, w);
    if (b1.y < 0.0 || b2.y < 0.0 || b3.y < 0.0) {
        return OUTSIDE;
    }
    // Plane 0: d = -value is the depth behind the triangle's plane, seen from the light.
    vec2 v0 = plane_range(f, 0u, c, h, tile, w);
    float d_max = -v0.x;
    float d_min = -v0.y;
    if (!(d_max > 0.0)) {
        return OUTSIDE;
    }
    vec4 p0 = f.p[0];
    bool point = u_light.w != 0.0;
    if (point) {
        // The hit distance d |S - L| / (d + w) grows with d and |S - L|: at most this.
        float r_max = length(c) + length(h);
        if (d_max * r_max <= u_eps_near * (d_max + p0.w)) {
            return OUTSIDE;
        }
    } else if (d_max <= u_eps_near * dot(p0.xyz, u_dir)) {
        return OUTSIDE;
    }
    // The hit distance is at least d (and at least the light's distance w from the light's
    // end, |S - L| >= d + w): beyond both eps for every sample once d_min and w are.
    bool inside = d_min > u_eps && (!point || p0.w > u_eps) && max(e1.x, b1.x) > 0.0 && max(e2.x, b2.x) > 0.0
        && max(e3.x, b3.x) > 0.0;
    if (inside) {
        return INSIDE;
    }
    // The depths at which the frustum meets the node's pyramid (its tile between w_min and
    // w_max), against the depths its samples occupy: a node across a depth discontinuity is
    // outside when the frustum passes only through the empty depth between its surfaces.
    // (Four calls, not a loop: llvmpipe counts every loop iteration against its limit, and the
    // traversal's budget counts none here.)
    vec2 span = frustum_depths(f, 0u, tile, w, w);
    span = frustum_depths(f, 1u, tile, w, span);
    span = frustum_depths(f, 2u, tile, w, span);
    span = frustum_depths(f, 3u, tile, w, span);
    if (!(span.x <= span.y)) {
        return OUTSIDE;
    }
    vec4 occ = nodes[NODE_VEC4S * node_index(level, node) + 3u];
    return (floatBitsToUint(occ.x) & occupancy_span(span.x, span.y, w.x, occ.y)) == 0u ? OUTSIDE : PARTIAL;
}

// Whether triangle `tri` shadows the sample at `rel` (= S - u_origin; |S - L| = r for a point
// light), the sample not lying on `tri` itself. The reference's rule, see the top of the file.
bool shadows_sample(uint tri, vec3 rel, float r) {
    vec4 p0 = planes[9u * tri];
    float d = -plane_at(p0, rel);
    if (!(d > 0.0)) {
        return false;
    }
    if (u_light.w != 0.0) {
        if (!(d * r > u_eps_near * (d + p0.w)) || !(p0.w * r > u_eps * (d + p0.w))) {
            return false;
        }
    } else if (!(d > u_eps_near * dot(p0.xyz, u_dir))) {
        return false;
    }
    return plane_at(planes[9u * tri + 1u], rel) >= 0.0 && plane_at(planes[9u * tri + 2u], rel) >= 0.0
        && plane_at(planes[9u * tri + 3u], rel) >= 0.0;
}
