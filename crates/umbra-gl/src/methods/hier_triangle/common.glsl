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
// Per node of every level: min (xyz; w = number of samples, 0 = empty), max (xyz).
layout(std430, binding = 4) buffer Nodes { vec4 nodes[]; };
// [0, 4 * MAX_LEVELS): per level the queue's entry count and a DispatchIndirectCommand;
// [u_covered_offset, +nodes): 1 = every sample of the node is shadowed;
// [u_bits_offset, +2 * leaves): per leaf, 64 "shadowed" bits, one per sample.
layout(std430, binding = 5) coherent buffer State { uint state[]; };
// Per triangle: the four planes above (written by setup.comp.glsl for this light).
layout(std430, binding = 6) buffer Planes { vec4 planes[]; };
// (triangle, node) pairs per level, at u_level[l].w.
layout(std430, binding = 7) buffer Queues { uvec2 queue[]; };

// Frame size in pixels.
uniform uvec2 u_frame;
// Levels in use (leaves included); per level: grid width, height, first node, first pair.
uniform uint u_levels;
uniform uvec4 u_level[MAX_LEVELS];
uniform uint u_queue_capacity[MAX_LEVELS];
uniform uint u_covered_offset;
uniform uint u_bits_offset;
// The light (w = 1 point at xyz, w = 0 directional coming from xyz), the unit direction
// towards a directional light, the origin of the plane offsets, the reference's eps and the
// sample end's eps (half of it).
uniform vec4 u_light;
uniform vec3 u_dir;
uniform vec3 u_origin;
uniform float u_eps;
uniform float u_eps_near;

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

// Triangle `tri`'s shadow frustum against the box [lo, hi]: OUTSIDE (no sample in the box can
// be shadowed by it), INSIDE (every point of the box is, with both eps margins), or PARTIAL.
// Conservative: box corners that rounding puts on the wrong side of a plane lie within
// rounding of it, i.e. at samples the reference's band holds (near a shadow boundary, within
// eps); and the box is grown by 2^-20 of its size before the INSIDE test.
int classify_box(uint tri, vec3 lo, vec3 hi) {
    vec3 c = 0.5 * (lo + hi) - u_origin;
    vec3 h = 0.5 * (hi - lo);
    vec3 h_in = h + (abs(c) + h) * (1.0 / 1048576.0);
    vec4 p0 = planes[4u * tri];
    float v = plane_at(p0, c);
    // d = -plane0: the depth behind the triangle's plane, seen from the light.
    float d_max = dot(abs(p0.xyz), h) - v;
    float d_min = -dot(abs(p0.xyz), h_in) - v;
    if (!(d_max > 0.0)) {
        return OUTSIDE;
    }
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
    // end, |S - L| >= d + w): beyond both eps for every point once d_min and w are.
    bool inside = d_min > u_eps && (!point || p0.w > u_eps);
    for (uint i = 1u; i <= 3u; ++i) {
        vec4 e = planes[4u * tri + i];
        float ve = plane_at(e, c);
        if (ve + dot(abs(e.xyz), h) < 0.0) {
            return OUTSIDE;
        }
        inside = inside && ve - dot(abs(e.xyz), h_in) > 0.0;
    }
    return inside ? INSIDE : PARTIAL;
}

// Whether triangle `tri` shadows the sample at `rel` (= S - u_origin; |S - L| = r for a point
// light), the sample not lying on `tri` itself. The reference's rule, see the top of the file.
bool shadows_sample(uint tri, vec3 rel, float r) {
    vec4 p0 = planes[4u * tri];
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
    return plane_at(planes[4u * tri + 1u], rel) >= 0.0 && plane_at(planes[4u * tri + 2u], rel) >= 0.0
        && plane_at(planes[4u * tri + 3u], rel) >= 0.0;
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
    uint word = u_bits_offset + 2u * leaf + k / 32u;
    uint bit = 1u << (k % 32u);
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

// The box test of `tri` against node `node` at `level`, marking the node covered when INSIDE.
// Empty nodes and nodes already covered (here or above) count as OUTSIDE: nothing left to do.
int visit(uint tri, uint level, uint node) {
    uint g = node_index(level, node);
    vec4 lo = nodes[2u * g];
    if (lo.w == 0.0 || covered_from_above(level, node)) {
        return OUTSIDE;
    }
    int c = classify_box(tri, lo.xyz, nodes[2u * g + 1u].xyz);
    if (c == INSIDE) {
        state[u_covered_offset + g] = 1u;
    }
    return c;
}
