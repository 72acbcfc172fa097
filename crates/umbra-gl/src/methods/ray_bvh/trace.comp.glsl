// ray-bvh, per light: one shadow ray per view sample through the scene's BVH (built on the CPU,
// umbra_geom::ray_bvh, whose RayBvh::occluded is this traversal and test in Rust). Prepended:
// "#version 450 core" and the defines NODE_VEC4S, TRIANGLE_VEC4S, LEAF_COUNT_BITS, LEAF_BIT,
// FROM_PARENT, FROM_SIBLING, FROM_CHILD, TINY.
//
// The reference's rule (crates/umbra-oracle, docs/exactness.md): a sample S on triangle T is
// shadowed when the segment from S to the light (a directional light: the ray towards it) meets
// another triangle, closed and two-sided, farther than eps from S and farther than eps from
// the light; S is first moved onto T's plane in double precision, as the reference does, and a
// sample within 2 eps of a point light is lit (the reference's segment is empty). Here the
// sample end's margin is eps / 2 (u_eps_near): a hit that rounding could move across the
// reference's eps then lies in its REFERENCE_EPS band part, never outside the band. The first
// hit ends the walk (any hit shadows).
//
// The walk is stackless and ordered (Hapala et al., "Efficient Stack-less BVH Traversal for
// Ray Tracing", SCCG 2011): the near child first along the split axis, from the parent and
// sibling indices, so a ray's whole state is one word, node << 2 | how it was reached. llvmpipe
// gives a shader invocation 65,535 loop iterations in all (gallivm's loop limiter;
// hier-triangle's measurement in docs/exactness.md): a walk stops after u_budget steps (each at
// most 1 + 4 loop iterations), parks its state in its result word (2 + state) and joins list
// u_list_out; a resume pass (u_resume = 1, one invocation per entry of list u_list_in)
// continues it from there. A walk takes at most 3 x node count steps, so it ends within that
// over u_budget passes (ray_bvh/mod.rs dispatches that many).
//
// Mode u_resume = 0: one invocation per pixel (8 x 8 workgroups), its result written whatever
// it is (0 lit or background, 1 shadowed, 2 + state unfinished).

layout(local_size_x = 8, local_size_y = 8) in;

// The scene's positions (3 floats per vertex) and indices (3 per triangle).
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
// Per pixel (row-major from the bottom-left): world position as f32 bits, triangle id
// (0xFFFFFFFF = no sample); samples.frag.glsl.
layout(std430, binding = 3) readonly buffer Samples { uvec4 samples[]; };
// NODE_VEC4S per node, the root first: (lo.xyz, parent bits), (hi.xyz, word bits): an inner
// node's word is left << 2 | split axis (its children adjacent, left odd), a leaf's LEAF_BIT |
// first record << LEAF_COUNT_BITS | count.
layout(std430, binding = 4) readonly buffer Nodes { vec4 nodes[]; };
// TRIANGLE_VEC4S per record: (a.xyz, id bits), (b.xyz, edge-order bits), (c.xyz, 0).
layout(std430, binding = 5) readonly buffer Triangles { vec4 tris[]; };
// Per pixel: 0 lit or no sample, 1 shadowed, 2 + state: the walk continues from state.
layout(std430, binding = 6) buffer Results { uint results[]; };
// [0, 8): per list its count and a DispatchIndirectCommand (args.comp.glsl); then list 0 and
// list 1, u_pixels entries each: pixel indices.
layout(std430, binding = 7) buffer Lists { uint lists[]; };

uniform uvec2 u_frame;
uniform uint u_pixels;
// The light (w = 1 point, w = 0 directional: the direction towards it).
uniform vec4 u_light;
// The reference's eps (segment_epsilon), and its half at the sample end.
uniform float u_eps;
uniform float u_eps_near;
uniform uint u_budget;
uniform uint u_resume;
uniform uint u_list_in;
uniform uint u_list_out;

dvec3 vertex(uint i) {
    return dvec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

// The sample moved onto its own triangle's plane, in double precision (the reference's step
// before its segment test: the interpolated position lies off the plane by rounding, and where
// a neighbour meets the segment at a grazing angle that offset, over the angle, could put the
// hit beyond eps). A degenerate triangle keeps it.
vec3 on_own_plane(uvec4 s) {
    dvec3 p = dvec3(uintBitsToFloat(s.xyz));
    uint t = s.w;
    dvec3 a = vertex(indices[3u * t]);
    dvec3 b = vertex(indices[3u * t + 1u]);
    dvec3 c = vertex(indices[3u * t + 2u]);
    dvec3 n = cross(b - a, c - a);
    double nn = dot(n, n);
    return nn > 0.0lf ? vec3(p - n * (dot(n, p - a) / nn)) : vec3(p);
}

// A ray prepared for the box and triangle tests (umbra_geom::ray_bvh::Ray).
struct Ray {
    vec3 o;
    vec3 inv;
    // The shear (Woop, Benthin, Wald, JCGT 2013) as three rows: with kz the axis of the largest
    // |d| component and kx, ky the next ones cyclically (swapped when d[kz] < 0), the sheared
    // vertex is (a[kx] - Sx a[kz], a[ky] - Sy a[kz], Sz a[kz]) = (dot(a, mx), dot(a, my),
    // dot(a, mz)): the other coefficients are exact zeros and ones, so the sums round as the
    // expression does, without indexing a vector by a variable (which llvmpipe compiles into
    // per-lane memory accesses, several times slower).
    vec3 mx;
    vec3 my;
    vec3 mz;
};

Ray make_ray(vec3 o, vec3 d) {
    Ray r;
    r.o = o;
    // Tiny components as +-TINY: 1 / d stays finite, the ray moves by < TINY t.
    vec3 safe = vec3(abs(d.x) < TINY ? (d.x < 0.0 ? -TINY : TINY) : d.x,
                     abs(d.y) < TINY ? (d.y < 0.0 ? -TINY : TINY) : d.y,
                     abs(d.z) < TINY ? (d.z < 0.0 ? -TINY : TINY) : d.z);
    r.inv = 1.0 / safe;
    vec3 a = abs(d);
    // Unit vectors of kz and of kx, ky in the cyclic order after it.
    vec3 ez;
    vec3 ex;
    vec3 ey;
    float dz;
    if (a.x > a.y && a.x > a.z) {
        ez = vec3(1.0, 0.0, 0.0);
        ex = vec3(0.0, 1.0, 0.0);
        ey = vec3(0.0, 0.0, 1.0);
        dz = d.x;
    } else if (a.y > a.z) {
        ez = vec3(0.0, 1.0, 0.0);
        ex = vec3(0.0, 0.0, 1.0);
        ey = vec3(1.0, 0.0, 0.0);
        dz = d.y;
    } else {
        ez = vec3(0.0, 0.0, 1.0);
        ex = vec3(1.0, 0.0, 0.0);
        ey = vec3(0.0, 1.0, 0.0);
        dz = d.z;
    }
    if (dz < 0.0) {
        vec3 e = ex;
        ex = ey;
        ey = e;
    }
    float sx = dot(d, ex) / dz;
    float sy = dot(d, ey) / dz;
    r.mx = ex - sx * ez;
    r.my = ey - sy * ez;
    r.mz = ez / dz;
    return r;
}

// The slab test of the (padded) box lo..hi for t in [0, t_end].
bool hits_box(Ray r, vec3 lo, vec3 hi, float t_end) {
    vec3 a = (lo - r.o) * r.inv;
    vec3 b = (hi - r.o) * r.inv;
    vec3 near = min(a, b);
    vec3 far = max(a, b);
    float t0 = max(max(near.x, near.y), max(near.z, 0.0));
    float t1 = min(min(far.x, far.y), min(far.z, t_end));
    return t0 <= t1;
}

// A vertex relative to the ray's origin, sheared so that the ray is the +z axis. precise: the
// same vertex of two triangles must give the same bits (no contraction that could differ).
vec3 sheared(Ray r, vec3 v) {
    precise vec3 a = v - r.o;
    precise float x = a.x * r.mx.x + a.y * r.mx.y + a.z * r.mx.z;
    precise float y = a.x * r.my.x + a.y * r.my.y + a.z * r.my.z;
    precise float z = a.x * r.mz.x + a.y * r.mz.y + a.z * r.mz.z;
    return vec3(x, y, z);
}

// The edge function of the sheared endpoints p, q (q.x p.y - q.y p.x, Woop's sign), computed
// from the lexicographically first endpoint (swapped: q is first) and then signed: two
// triangles sharing the edge get exact negations (umbra_geom::ray_bvh::edge_function).
float edge_function(vec3 p, vec3 q, bool swapped) {
    vec3 first = swapped ? q : p;
    vec3 second = swapped ? p : q;
    precise float canonical = first.x * second.y - first.y * second.x;
    return swapped ? canonical : -canonical;
}

// Whether the ray meets record `rec` (closed, two-sided) at t; false for a zero projected area.
bool hit_triangle(Ray r, uint rec, out float t) {
    vec4 q0 = tris[TRIANGLE_VEC4S * rec];
    vec4 q1 = tris[TRIANGLE_VEC4S * rec + 1u];
    vec4 q2 = tris[TRIANGLE_VEC4S * rec + 2u];
    uint edges = floatBitsToUint(q1.w);
    vec3 a = sheared(r, q0.xyz);
    vec3 b = sheared(r, q1.xyz);
    vec3 c = sheared(r, q2.xyz);
    float w = edge_function(a, b, (edges & 1u) != 0u);
    float u = edge_function(b, c, (edges & 2u) != 0u);
    float v = edge_function(c, a, (edges & 4u) != 0u);
    t = 0.0;
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return false;
    }
    float det = u + v + w;
    if (det == 0.0) {
        return false;
    }
    t = (u * a.z + v * b.z + w * c.z) / det;
    return true;
}

// The child of inner node word `word` the ray meets first along the split axis.
uint near_child(uint word, vec3 d) {
    uint axis = word & 3u;
    float da = axis == 0u ? d.x : (axis == 1u ? d.y : d.z);
    return (word >> 2) + (da >= 0.0 ? 0u : 1u);
}

// The other child of a node's parent (children adjacent, the left one odd).
uint sibling(uint node) {
    return (node & 1u) == 1u ? node + 1u : node - 1u;
}

// Walks from `state` for at most u_budget steps (umbra_geom::ray_bvh::RayBvh::walk): 1 hit
// (within the eps limits, not triangle `own`), 0 no hit anywhere, 2 unfinished (`state` then
// holds where to continue).
uint walk(Ray r, vec3 d, float t_end, float len, bool point, uint own, inout uint state) {
    for (uint step = 0u; step < u_budget; ++step) {
        uint cur = state >> 2;
        uint how = state & 3u;
        vec4 lo = nodes[NODE_VEC4S * cur];
        uint parent = floatBitsToUint(lo.w);
        if (how == FROM_CHILD) {
            if (cur == 0u) {
                return 0u;
            }
            uint parent_word = floatBitsToUint(nodes[NODE_VEC4S * parent + 1u].w);
            state = cur == near_child(parent_word, d) ? (sibling(cur) << 2) | FROM_SIBLING : (parent << 2) | FROM_CHILD;
            continue;
        }
        vec4 hi = nodes[NODE_VEC4S * cur + 1u];
        uint word = floatBitsToUint(hi.w);
        bool leave = true;
        if (hits_box(r, lo.xyz, hi.xyz, t_end)) {
            if ((word & LEAF_BIT) != 0u) {
                uint first = (word & ~LEAF_BIT) >> LEAF_COUNT_BITS;
                uint count = word & ((1u << LEAF_COUNT_BITS) - 1u);
                // A constant bound (MAX_LEAF): unrolled, no loop of its own under the budget.
                for (uint k = 0u; k < 4u; ++k) {
                    if (k >= count) {
                        break;
                    }
                    uint rec = first + k;
                    float t;
                    if (floatBitsToUint(tris[TRIANGLE_VEC4S * rec].w) != own && hit_triangle(r, rec, t)) {
                        bool beyond_sample = t * len > u_eps_near;
                        bool before_light = point ? (1.0 - t) * len > u_eps : true;
                        if (beyond_sample && before_light) {
                            return 1u;
                        }
                    }
                }
            } else {
                state = (near_child(word, d) << 2) | FROM_PARENT;
                leave = false;
            }
        }
        if (leave) {
            if (cur == 0u) {
                return 0u;
            }
            state = how == FROM_PARENT ? (sibling(cur) << 2) | FROM_SIBLING : (parent << 2) | FROM_CHILD;
        }
    }
    return 2u;
}

void main() {
    uint pixel;
    if (u_resume == 0u) {
        uvec2 p = gl_GlobalInvocationID.xy;
        if (p.x >= u_frame.x || p.y >= u_frame.y) {
            return;
        }
        pixel = p.y * u_frame.x + p.x;
    } else {
        uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
        if (i >= lists[4u * u_list_in]) {
            return;
        }
        pixel = lists[8u + u_list_in * u_pixels + i];
    }
    uvec4 s = samples[pixel];
    uint state = u_resume == 0u ? FROM_PARENT : results[pixel] - 2u;
    uint result = 0u;
    if (s.w != 0xFFFFFFFFu) {
        vec3 o = on_own_plane(s);
        bool point = u_light.w != 0.0;
        vec3 d = point ? u_light.xyz / u_light.w - o : normalize(u_light.xyz);
        float len = point ? length(d) : 1.0;
        // A sample within 2 eps of a point light: the segment is empty, it is lit.
        if (!point || len > 2.0 * u_eps) {
            Ray r = make_ray(o, d);
            // The boxes along the segment to a point light (t <= 1), or the whole ray.
            float t_end = point ? 1.0 : 3.4e38;
            result = walk(r, d, t_end, len, point, s.w, state);
        }
    }
    if (result == 2u) {
        results[pixel] = 2u + state;
        uint slot = atomicAdd(lists[4u * u_list_out], 1u);
        lists[8u + u_list_out * u_pixels + slot] = pixel;
    } else {
        results[pixel] = result;
    }
}
