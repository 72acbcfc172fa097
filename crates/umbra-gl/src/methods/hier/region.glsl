// Bounds of the samples of a node (world box, frustum slab, directions from the light) against
// planes, shared by hier-triangle's shadow frusta and hier-silhouette's shadow-volume faces.
// Sintorn, Kämpe, Olsson, Assarsson, "Per-Triangle Shadow Volumes Using a View-Sample Cluster
// Hierarchy" (I3D 2014), Section 4 (a frustum against the 3-D bounds of a cluster). Every
// plane is (unit normal, offset at u_origin), with its form over the view's rays (E, a, b, c):
// at the point eye + w D(x, y) of NDC (x, y) and clip w its value is E + w (a x + b y + c).
// Prepended after hierarchy.glsl.

// An item's data for this light, loaded once per pair: [0, 4) four planes, [4, 8) the same
// planes over the view's rays, [8] the bound of its directions from the light: a point light's
// unit axis and chord radius (every direction from the light through the item lies within
// it), a directional light's box of its points along u_light_u, u_light_v.
struct Frustum {
    vec4 p[9];
};

const int OUTSIDE = 0;
const int PARTIAL = 1;
const int INSIDE = 2;

// The plane's value at a point given relative to u_origin; one fixed order of operations,
// no contraction (precise), so every triangle sharing the plane gets the same value.
float plane_at(vec4 p, vec3 rel) {
    precise float v = p.x * rel.x + p.y * rel.y + p.z * rel.z + p.w;
    return v;
}

// The screen tile of node `node` at `level`, in NDC: (x0, x1, y0, y1).
vec4 node_tile(uint level, uint node) {
    uint side = LEAF_SIDE << (2u * level);
    uvec2 t0 = uvec2(node % u_level[level].x, node / u_level[level].x) * side;
    uvec2 t1 = min(t0 + side, u_frame);
    vec2 ndc_scale = 2.0 / vec2(u_frame);
    return vec4(vec2(t0.x, t1.x) * ndc_scale.x - 1.0, vec2(t0.y, t1.y) * ndc_scale.y - 1.0);
}

// The range over a screen tile (NDC x0, x1, y0, y1) of a plane's factor of w in its form over
// the view's rays, a x + b y + c for q = (E, a, b, c): bilinear, so its extremes lie at the
// tile's corners.
vec2 ray_factor_range(vec4 q, vec4 tile) {
    return vec2(min(q.y * tile.x, q.y * tile.y) + min(q.z * tile.z, q.z * tile.w) + q.w,
                max(q.y * tile.x, q.y * tile.y) + max(q.z * tile.z, q.z * tile.w) + q.w);
}

// The range of plane k of triangle `tri` over the samples of a node, as (min, max): the intersection of two enclosures of them, each widened by a bound on its
// rounding (2^-20 of the magnitudes involved):
// * the node's world box [lo, hi]: centre value +- the plane's extent over the half-sizes;
// * the node's frustum slab, its screen tile (pixel edges, in NDC) between the nearest and
//   farthest clip w of its samples: E + w (a x + b y + c) is bilinear, so its extremes over
//   the slab lie at the tile's corners at w_min or w_max. Tight where the box is not: a
//   surface seen at a grazing angle spans a long box but a thin slab.
vec2 plane_range(Frustum f, uint k, vec3 c, vec3 h, vec4 tile, vec2 w) {
    vec4 p = f.p[k];
    float v = plane_at(p, c);
    float r = dot(abs(p.xyz), h);
    float tol = (abs(v) + r + dot(abs(p.xyz), abs(c))) * (1.0 / 1048576.0);
    vec2 box = vec2(v - r - tol, v + r + tol);
    vec4 q = f.p[4u + k];
    vec2 g = ray_factor_range(q, tile);
    float g_min = g.x;
    float g_max = g.y;
    float q_tol = (abs(q.x) + w.y * (abs(q.y) + abs(q.z) + abs(q.w))) * (1.0 / 1048576.0);
    vec2 slab = vec2(q.x + min(w.x * g_min, w.y * g_min) - q_tol, q.x + max(w.x * g_max, w.y * g_max) + q_tol);
    return vec2(max(box.x, slab.x), min(box.y, slab.y));
}

// Where the light's direction bound `lb` of a node puts edge plane `e` (through a point light,
// or along a directional light): (min, max) of the sign-deciding value over the node's samples
// — e.u over unit directions u within h of the axis (point), e.(S - origin) over the box in the
// light's perpendicular plane (directional; e has no component along the light, up to
// rounding, which the tolerance covers). The ranges of two triangles sharing an edge are exact
// negations of each other (their planes are; the operations are sign-symmetric): a node is
// never dropped by both.
vec2 light_range(vec4 e, vec4 lb) {
    if (u_light.w != 0.0) {
        float c = dot(e.xyz, lb.xyz);
        float r = lb.w + 4.0e-6;
        return vec2(c - r, c + r);
    }
    float eu = dot(e.xyz, u_light_u);
    float ev = dot(e.xyz, u_light_v);
    float lo = min(eu * lb.x, eu * lb.y) + min(ev * lb.z, ev * lb.w) + e.w;
    float hi = max(eu * lb.x, eu * lb.y) + max(ev * lb.z, ev * lb.w) + e.w;
    float tol = (abs(eu) * max(abs(lb.x), abs(lb.y)) + abs(ev) * max(abs(lb.z), abs(lb.w)) + abs(e.w)) * 4.0e-6;
    return vec2(lo - tol, hi + tol);
}

// Whether the directions from the light through the triangle (its bound tb) and those of the
// node's samples (lb) can meet: the edge planes alone cannot separate a node lying off a corner
// of the triangle's cone, which for small triangles is most nodes near it. Point light: two
// balls around unit axes are disjoint when their centres are farther apart than the radii
// (chords: the triangle inequality of R^3). Directional: the boxes along u, v overlap (with the
// edge planes, the separating-axis test of a triangle and a box in the light's plane).
bool directions_meet(vec4 tb, vec4 lb) {
    if (u_light.w != 0.0) {
        return length(tb.xyz - lb.xyz) <= tb.w + lb.w + 4.0e-6;
    }
    float tol = (max(abs(lb.x), abs(lb.y)) + max(abs(lb.z), abs(lb.w))) * 4.0e-6;
    return tb.x <= lb.y + tol && lb.x <= tb.y + tol && tb.z <= lb.w + tol && lb.z <= tb.w + tol;
}

// The depth occupancy of a node (hier-triangle's nodes, OCCUPANCY): its clip-w range [w_lo, w_hi]
// cut into OCCUPANCY_BINS equal bins, a bit set for every bin that may hold one of its samples'
// w, so that the empty depth between two surfaces of one tile (a depth discontinuity: an arch in
// front of a wall) bounds no sample. Stored in the node's fourth vec4: (mask bits, scale), the
// scale computed once (bounds.comp.glsl) and read by every test, so that build and test map a
// w to a bin with the same f32 operations. The map (w - w_lo) * scale, floored and clamped, is
// a composition of correctly rounded subtractions and multiplications by a scale >= 0, so it is
// monotone in w: an interval [a, b] of w meets only bins between occupancy_bin(a) and
// occupancy_bin(b), whatever the rounding.
const uint OCCUPANCY_BINS = 32u;

// The bin of w in a node whose range starts at w_lo, with the node's scale.
uint occupancy_bin(float w, float w_lo, float scale) {
    precise float x = (w - w_lo) * scale;
    return uint(clamp(floor(x), 0.0, float(OCCUPANCY_BINS - 1u)));
}

// The bins an interval [a, b] (a <= b) of w may meet, as a mask.
uint occupancy_span(float a, float b, float w_lo, float scale) {
    uint i = occupancy_bin(a, w_lo, scale);
    uint j = occupancy_bin(b, w_lo, scale);
    uint upto_j = j == 31u ? 0xFFFFFFFFu : (2u << j) - 1u;
    return upto_j & ~((1u << i) - 1u);
}
