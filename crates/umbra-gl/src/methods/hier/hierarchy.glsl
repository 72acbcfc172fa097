// The view-sample hierarchy shared by hier-triangle and hier-silhouette: the buffers every
// pass binds, the hierarchy's uniforms, the node and level helpers and the queues of
// (item, node) pairs (hier-silhouette's; hier-triangle walks the hierarchy in its own persistent
// traversal, hier_triangle/traverse.comp.glsl) — an item is a triangle's shadow frustum or a shadow
// volume face (hier-silhouette). Sintorn, Kämpe, Olsson, Assarsson, "Per-Triangle Shadow
// Volumes Using a View-Sample Cluster Hierarchy" (I3D 2014), Section 4: the hierarchy of the
// depth buffer's samples with 3-D bounds, traversed breadth-first. Prepended by hier/mod.rs:
// "#version 450 core" and the defines LEAF_SIDE, LEAF_SAMPLES, BRANCH_SIDE, CHILDREN,
// MAX_LEVELS, NO_TRIANGLE, NODE_VEC4S (vec4 per node) and LIFT (1: the nodes bound the lifted
// points too, hier-silhouette; see lifted() below).

// Scene positions (3 floats per vertex) and indices (3 per triangle): the scene's own buffers.
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
// Per pixel (row-major from the bottom-left, GL window coordinates): world position as f32
// bits, triangle id (NO_TRIANGLE = no sample).
layout(std430, binding = 3) buffer Samples { uvec4 samples[]; };
// Per node of every level, NODE_VEC4S vec4: the box of its samples' world positions, min (xyz)
// and max (xyz), with the range of their clip w (view depth) in the two w components: (lo,
// w_min), (hi, w_max), empty when w_min > w_max (per frame, bounds.comp.glsl); the bound of
// their directions from the light (per light, light_bounds.comp.glsl): a point light's unit
// axis a and radius h, every |(S - L) / |S - L| - a| <= h; a directional light's box
// [u0, u1] x [v0, v1] of (S - origin) along u_light_u, u_light_v (perpendicular to the
// light's direction); with LIFT, the bounds hold the samples' lifted points too, and a fourth
// vec4 holds the node's own point (xyz: the lifted point of one of its samples, per frame).
layout(std430, binding = 4) buffer Nodes { vec4 nodes[]; };
// [0, 4 * MAX_LEVELS): per level the queue's entry count and a DispatchIndirectCommand; then
// the same for the list of active leaves (ACTIVE_CONTROL) and the two redo lists
// (REDO_CONTROL + 4 * list);
// [u_covered_offset, +nodes): one word per node (hier-triangle's live bitmask,
// hier_triangle/live.glsl);
// [u_bits_offset, +leaves): per leaf, one word (unused by both methods; LEAF_SAMPLES <= 32);
// [u_heads_offset, +leaves): per leaf, the head of its list of pairs (index + 1, 0 = empty);
// [u_active_offset, +leaves): the leaves whose list is not empty (this batch);
// [u_redo_flags_offset, +items / 32): 1 = the item is in the output redo list;
// (per frame, not cleared per light) [u_valid_offset, +leaves): per leaf, the bits of the
// samples present; (per scene, hier-triangle) [u_order_offset, +items): the triangles, largest
// first.
layout(std430, binding = 5) coherent buffer State { uint state[]; };
// Pairs per level, at u_level[l].w: (item, node) above the leaves; at the leaves
// (item, next pair of the same leaf + 1, 0 = last): one list per leaf. Then, at
// u_redo_offset, the two redo lists of u_triangles entries each: (item, 0) for each
// item a full queue turned away.
layout(std430, binding = 7) buffer Queues { uvec2 queue[]; };

// Work counts (methods/work_counts.rs), summed over the frame's lights when u_count_work is 1:
// [WORK_NODES_TESTED] (item, node) tests, [WORK_LEAVES_TESTED] (item, leaf) pairs tested
// sample by sample, [WORK_NODES_PRUNED] node tests that ended the descent. Compute stages only:
// the resolve's fragment shader gets the no-op (WORK_STUB, hier/programs.rs), so it declares no
// storage block beyond its own.
const uint WORK_NODES_TESTED = 0u;
const uint WORK_LEAVES_TESTED = 1u;
const uint WORK_NODES_PRUNED = 2u;
#ifdef WORK_STUB
void count_work(uint what, uint n) {}
#else
layout(std430, binding = 9) buffer Work { uint work[]; };
uniform uint u_count_work;
void count_work(uint what, uint n) {
    // Reason for the branch: no atomic traffic in frames that do not count.
    if (u_count_work != 0u && n != 0u) {
        atomicAdd(work[what], n);
    }
}
#endif

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
// Items (triangles or faces): the redo lists' length.
uniform uint u_triangles;
// The redo list a turned-away item goes to (0 or 1), and the one a redo round reads.
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

#if LIFT
// The eye in world space (f32) for lifted().
uniform vec3 u_eye_world;

// A sample's lifted point (hier-silhouette): S moved towards the eye by a fraction mu of the way,
// mu = 2^-12 plus 128 units in the last place of S's largest coordinate over |E - S| (so that
// the move is far above the rounding of S even where the coordinates are large), at most
// 2^-6. On the view ray of S's pixel, between the eye and S: off S's own surface, in the
// empty space in front of it. Computed once per use with one fixed order of operations
// (precise): every pass gets the same f32 point.
// The fraction mu of the way to the eye (to_eye = u_eye_world - s) a lifted point moves.
float lift_fraction(vec3 s, vec3 to_eye) {
    precise float dist = length(to_eye);
    precise float big = max(max(abs(s.x), abs(s.y)), abs(s.z));
    precise float mu = dist > 0.0 ? min(1.0 / 4096.0 + big * (1.0 / 131072.0) / dist, 1.0 / 64.0) : 0.0;
    return mu;
}

vec3 lifted(vec3 s) {
    precise vec3 to_eye = u_eye_world - s;
    float mu = lift_fraction(s, to_eye);
    precise vec3 p = s + mu * to_eye;
    return p;
}
#endif

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

// The pixel (row-major from the bottom-left) of sample k (0 .. LEAF_SAMPLES-1) of leaf `leaf`;
// false where it lies beyond the frame (the last tile of a row or column may be cut).
bool leaf_pixel(uint leaf, uint k, out uint pixel) {
    uint x = (leaf % u_level[0].x) * LEAF_SIDE + k % LEAF_SIDE;
    uint y = (leaf / u_level[0].x) * LEAF_SIDE + k / LEAF_SIDE;
    pixel = y * u_frame.x + x;
    return x < u_frame.x && y < u_frame.y;
}

// Child k (0 .. CHILDREN-1) of inner node `node` at `level` (>= 1), as an index at level - 1;
// false where the child lies beyond the grid.
bool child_of(uint level, uint node, uint k, out uint child) {
    uint x = (node % u_level[level].x) * BRANCH_SIDE + k % BRANCH_SIDE;
    uint y = (node / u_level[level].x) * BRANCH_SIDE + k / BRANCH_SIDE;
    child = y * u_level[level - 1u].x + x;
    return x < u_level[level - 1u].x && y < u_level[level - 1u].y;
}

// A pair (item, node) whose node the item's test cuts, queued for the next pass: above the leaves in the
// level's queue, at the leaves in the leaf's list. When the queue is full the pair is turned
// away and its item goes to the output redo list, which the next redo round processes
// with the same passes, and the method's fallback pass whole after the last round:
// slower, never wrong. No fallback code here: llvmpipe runs a shader's
// branches under a mask even when no invocation takes them, so unused code costs time.
void descend_into(uint item, uint level, uint node) {
    uint slot = atomicAdd(state[4u * level], 1u);
    if (slot < u_queue_capacity[level]) {
        if (level == 0u) {
            count_work(WORK_LEAVES_TESTED, 1u);
            uint next = atomicExchange(state[u_heads_offset + node], slot + 1u);
            queue[u_level[0].w + slot] = uvec2(item, next);
            if (next == 0u) {
                // The leaf's first pair: the leaf pass will visit it.
                state[u_active_offset + atomicAdd(state[ACTIVE_CONTROL], 1u)] = node;
            }
        } else {
            queue[u_level[level].w + slot] = uvec2(item, node);
        }
    } else {
        uint bit = 1u << (item % 32u);
        if ((atomicOr(state[u_redo_flags_offset + item / 32u], bit) & bit) == 0u) {
            uint i = atomicAdd(state[REDO_CONTROL + 4u * u_redo_out], 1u);
            queue[u_redo_offset + u_redo_out * u_triangles + i] = uvec2(item, 0u);
        }
    }
}
