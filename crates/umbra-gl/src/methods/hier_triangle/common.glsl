// hier-triangle, shared by every pass: the buffers, the hierarchy's uniforms, and the exact
// tests of one triangle's shadow frustum against a box of samples and against one sample.
// Sintorn, Kämpe, Olsson, Assarsson, "Per-Triangle Shadow Volumes Using a View-Sample Cluster
// Hierarchy" (I3D 2014), Sections 3-4. Prepended by mod.rs: "#version 450 core" and the
// defines LEAF_SIDE, LEAF_SAMPLES, BRANCH_SIDE, CHILDREN, MAX_LEVELS, NO_TRIANGLE.
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

// Scene positions (3 floats per vertex) and indices (3 per triangle): the scene's own buffers.
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
// Per pixel (row-major from the bottom-left, GL window coordinates): world position as f32
// bits, triangle id (NO_TRIANGLE = no sample).
layout(std430, binding = 3) buffer Samples { uvec4 samples[]; };
// Per node of every level, 3 vec4: the box of its samples' world positions, min (xyz) and max
// (xyz), with the range of their clip w (view depth) in the two w components: (lo, w_min),
// (hi, w_max), empty when w_min > w_max (per frame, bounds.comp.glsl); and the bound of their
// directions from the light (per light, light_bounds.comp.glsl): a point light's unit axis a and
// radius h, every |(S - L) / |S - L| - a| <= h; a directional light's box [u0, u1] x [v0, v1] of
// (S - origin) along u_light_u, u_light_v (perpendicular to the light's direction).
layout(std430, binding = 4) buffer Nodes { vec4 nodes[]; };
// [0, 4 * MAX_LEVELS): per level the queue's entry count and a DispatchIndirectCommand; then
// the same for the list of active leaves (ACTIVE_CONTROL) and the two redo lists
// (REDO_CONTROL + 4 * list);
// [u_covered_offset, +nodes): 1 = every sample of the node is shadowed;
// [u_bits_offset, +leaves): per leaf, its samples' "shadowed" bits (LEAF_SAMPLES <= 32);
// [u_heads_offset, +leaves): per leaf, the head of its list of pairs (index + 1, 0 = empty);
// [u_active_offset, +leaves): the leaves whose list is not empty (this batch);
// [u_redo_flags_offset, +triangles / 32): 1 = the triangle is in the output redo list;
// (per frame, not cleared per light) [u_valid_offset, +leaves): per leaf, the bits of the
// samples present; (per scene) [u_order_offset, +triangles): the triangles, largest first.
layout(std430, binding = 5) coherent buffer State { uint state[]; };
// Per triangle, 9 vec4 (written by setup.comp.glsl for this light): [0, 4) the four planes
// above; [4, 8) the same planes over the view's rays, (E, a, b, c): at the point eye + w D(x, y)
// of NDC (x, y) and clip w, the plane's value is E + w (a x + b y + c) (see classify_node);
// [8] the bound of its directions from the light: a point light's unit axis and chord radius
// (every direction from the light through the triangle lies within it), a directional light's
// box of its vertices along u_light_u, u_light_v.
layout(std430, binding = 6) buffer Planes { vec4 planes[]; };
// Pairs per level, at u_level[l].w: (triangle, node) above the leaves; at the leaves
// (triangle, next pair of the same leaf + 1, 0 = last): one list per leaf. Then, at
// u_redo_offset, the two redo lists of u_triangles entries each: (triangle, 0) for each
// triangle a full queue turned away.
layout(std430, binding = 7) buffer Queues { uvec2 queue[]; };

// Frame size in pixels.
uniform uvec2 u_frame;
// Levels in use (leaves included); per level: grid width, height, first node, first pair.
uniform uint u_levels;
uniform uvec4 u_level[MAX_LEVELS];
uniform uint u_queue_capacity[MAX_LEVELS];
uniform uint u_covered_offset;
uniform uint u_bits_offset;
uniform uint u_heads_offset;
uniform uint u_redo_flags_offset;
uniform uint u_redo_offset;
uniform uint u_active_offset;
uniform uint u_triangles;
// The redo list a turned-away triangle goes to (0 or 1), and the one a redo round reads.
uniform uint u_redo_out;
uniform uint u_redo_in;
uniform uint u_valid_offset;
uniform uint u_order_offset;
// The light (w = 1 point at xyz, w = 0 directional coming from xyz), the unit direction
// towards a directional light, the origin of the plane offsets, the reference's eps and the
// sample end's eps (half of it).
uniform vec4 u_light;
uniform vec3 u_dir;
uniform vec3 u_origin;
uniform float u_eps;
uniform float u_eps_near;
// A directional light's basis of the plane perpendicular to it.
uniform vec3 u_light_u;
uniform vec3 u_light_v;
// The view: row 3 of clip_from_world (clip w of a world point), the eye relative to u_origin,
// and the rays: the point of NDC (x, y) at clip w is eye + w (x u_ray_x + y u_ray_y + u_ray_c).
uniform vec4 u_view_w;
uniform vec3 u_eye_rel;
uniform vec3 u_ray_x;
uniform vec3 u_ray_y;
uniform vec3 u_ray_c;

// The control words of the active-leaf list and of redo list 0 (list 1's 4 words later):
// count, then a DispatchIndirectCommand.
const uint ACTIVE_CONTROL = 4u * uint(MAX_LEVELS);
const uint REDO_CONTROL = ACTIVE_CONTROL + 4u;

// One triangle's data for this light (the 9 vec4 of Planes), loaded once per pair.
struct Frustum {
    vec4 p[9];
};

Frustum load_frustum(uint tri) {
    Frustum f;
    for (uint i = 0u; i < 9u; ++i) {
        f.p[i] = planes[9u * tri + i];
    }
    return f;
}

const int OUTSIDE = 0;
const int PARTIAL = 1;
const int INSIDE = 2;

// The plane's value at a point given relative to u_origin; one fixed order of operations,
// no contraction (precise), so every triangle sharing the plane gets the same value.
float plane_at(vec4 p, vec3 rel) {
    precise float v = p.x * rel.x + p.y * rel.y + p.z * rel.z + p.w;
    return v;
}

uint node_index(uint level, uint node) {
    return u_level[level].z + node;
}

bool is_covered(uint level, uint node) {
    return state[u_covered_offset + node_index(level, node)] != 0u;
}

// Whether the node or one of its ancestors is covered (all its samples shadowed already).
bool covered_from_above(uint level, uint node) {
    uint x = node % u_level[level].x;
    uint y = node / u_level[level].x;
    for (uint l = level; l < u_levels; ++l) {
        if (is_covered(l, y * u_level[l].x + x)) {
            return true;
        }
        x /= BRANCH_SIDE;
        y /= BRANCH_SIDE;
    }
    return false;
}

// Child k (0 .. CHILDREN-1) of inner node `node` at `level` (>= 1), as an index at level - 1;
// false where the child lies beyond the grid.
bool child_of(uint level, uint node, uint k, out uint child) {
    uint x = (node % u_level[level].x) * BRANCH_SIDE + k % BRANCH_SIDE;
    uint y = (node / u_level[level].x) * BRANCH_SIDE + k / BRANCH_SIDE;
    child = y * u_level[level - 1u].x + x;
    return x < u_level[level - 1u].x && y < u_level[level - 1u].y;
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
    float g_min = min(q.y * tile.x, q.y * tile.y) + min(q.z * tile.z, q.z * tile.w) + q.w;
    float g_max = max(q.y * tile.x, q.y * tile.y) + max(q.z * tile.z, q.z * tile.w) + q.w;
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

// Triangle `tri`'s shadow frustum against node `node` at `level` (bounds lo, hi with the w
// range in their w components): OUTSIDE (no sample of the node can be shadowed by it), INSIDE
// (every sample is, with both eps margins), or PARTIAL. Cheapest and most selective first:
// the direction bounds (the triangle's against the node's), then the edge planes over the
// node's directions (an edge plane holds the light or its direction, so the direction bound is
// the tight one for it), then the triangle's plane over the world box and the frustum slab.
int classify_node(Frustum f, uint level, uint node, vec4 lo, vec4 hi) {
    vec4 lb = nodes[3u * node_index(level, node) + 2u];
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
    uint side = LEAF_SIDE << (2u * level);
    uvec2 t0 = uvec2(node % u_level[level].x, node / u_level[level].x) * side;
    uvec2 t1 = min(t0 + side, u_frame);
    vec2 ndc_scale = 2.0 / vec2(u_frame);
    vec4 tile = vec4(vec2(t0.x, t1.x) * ndc_scale.x - 1.0, vec2(t0.y, t1.y) * ndc_scale.y - 1.0);
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
    return inside ? INSIDE : PARTIAL;
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

// Sample k (0 .. LEAF_SAMPLES-1) of leaf `leaf` against triangle `tri`: sets its bit when
// shadowed. Background, samples of `tri` itself and samples already shadowed are skipped; a
// sample within 2 eps of a point light is lit (the reference's segment is empty there).
void test_sample(uint tri, uint leaf, uint k) {
    uint x = (leaf % u_level[0].x) * LEAF_SIDE + k % LEAF_SIDE;
    uint y = (leaf / u_level[0].x) * LEAF_SIDE + k / LEAF_SIDE;
    if (x >= u_frame.x || y >= u_frame.y) {
        return;
    }
    uint word = u_bits_offset + leaf;
    uint bit = 1u << k;
    if ((state[word] & bit) != 0u) {
        return;
    }
    uvec4 s = samples[y * u_frame.x + x];
    if (s.w == NO_TRIANGLE || s.w == tri) {
        return;
    }
    vec3 rel = uintBitsToFloat(s.xyz) - u_origin;
    float r = length(rel);
    if (u_light.w != 0.0 && !(r > 2.0 * u_eps)) {
        return;
    }
    if (shadows_sample(tri, rel, r)) {
        atomicOr(state[word], bit);
    }
}

// The test of frustum `f` against node `node` at `level`, marking the node covered when
// INSIDE. Empty nodes and nodes already covered count as OUTSIDE: nothing left to do (a
// covered ancestor is checked where the pair is taken from its queue).
int visit(Frustum f, uint level, uint node) {
    uint g = node_index(level, node);
    vec4 lo = nodes[3u * g];
    vec4 hi = nodes[3u * g + 1u];
    if (lo.w > hi.w || state[u_covered_offset + g] != 0u) {
        return OUTSIDE;
    }
    int c = classify_node(f, level, node, lo, hi);
    if (c == INSIDE) {
        state[u_covered_offset + g] = 1u;
    }
    return c;
}

// A pair whose node the frustum cuts, queued for the next pass: above the leaves in the
// level's queue, at the leaves in the leaf's list. When the queue is full the pair is turned
// away and its triangle goes to the output redo list, which the next redo round processes
// with the same passes, and the fallback pass (fallback.comp.glsl) whole after the last round:
// slower, never wrong. No fallback code here: llvmpipe runs a shader's
// branches under a mask even when no invocation takes them, so unused code costs time.
void descend_into(uint tri, uint level, uint node) {
    uint slot = atomicAdd(state[4u * level], 1u);
    if (slot < u_queue_capacity[level]) {
        if (level == 0u) {
            uint next = atomicExchange(state[u_heads_offset + node], slot + 1u);
            queue[u_level[0].w + slot] = uvec2(tri, next);
            if (next == 0u) {
                // The leaf's first pair: the leaf pass will visit it.
                state[u_active_offset + atomicAdd(state[ACTIVE_CONTROL], 1u)] = node;
            }
        } else {
            queue[u_level[level].w + slot] = uvec2(tri, node);
        }
    } else {
        uint bit = 1u << (tri % 32u);
        if ((atomicOr(state[u_redo_flags_offset + tri / 32u], bit) & bit) == 0u) {
            uint i = atomicAdd(state[REDO_CONTROL + 4u * u_redo_out], 1u);
            queue[u_redo_offset + u_redo_out * u_triangles + i] = uvec2(tri, 0u);
        }
    }
}
