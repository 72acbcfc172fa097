// ray-bvh, per light: one shadow ray per view sample through the scene's BVH (built on the CPU,
// umbra_geom::ray_bvh, whose RayBvh::occluded is this traversal and test in Rust). Prepended:
// "#version 450 core" and the defines NODE_VEC4S, TRIANGLE_VEC4S, LEAF_COUNT_BITS, TINY.
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
// The walk is stackless: the nodes are in depth-first preorder, each with the index of the node
// after its subtree (skip), so a ray's whole state is one node index and every step moves it
// forward. llvmpipe gives a shader invocation 65,535 loop iterations in all (gallivm's loop
// limiter; hier-triangle's measurement in docs/exactness.md): a walk stops after u_budget steps
// (each at most 1 + 4 loop iterations), parks its node index in its result word (2 + node) and
// joins list u_list_out; a resume pass (u_resume = 1, one invocation per entry of list
// u_list_in) continues it from there. Each step moves the index forward, so a walk ends within
// node count / u_budget passes (ray_bvh/mod.rs dispatches that many).
//
// Mode u_resume = 0: one invocation per pixel (8 x 8 workgroups), its result written whatever
// it is (0 lit or background, 1 shadowed, 2 + node unfinished).

layout(local_size_x = 8, local_size_y = 8) in;

// The scene's positions (3 floats per vertex) and indices (3 per triangle).
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
// Per pixel (row-major from the bottom-left): world position as f32 bits, triangle id
// (0xFFFFFFFF = no sample); samples.frag.glsl.
layout(std430, binding = 3) readonly buffer Samples { uvec4 samples[]; };
// NODE_VEC4S per node: (lo.xyz, skip bits), (hi.xyz, leaf bits): leaf 0 = inner node (its
// first child next), else first record << LEAF_COUNT_BITS | count.
layout(std430, binding = 4) readonly buffer Nodes { vec4 nodes[]; };
// TRIANGLE_VEC4S per record: (a.xyz, id bits), (b.xyz, edge-order bits), (c.xyz, 0).
layout(std430, binding = 5) readonly buffer Triangles { vec4 tris[]; };
// Per pixel: 0 lit or no sample, 1 shadowed, 2 + node: the walk continues at node.
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
uniform uint u_node_count;
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
    // The shear's axes (Woop, Benthin, Wald, JCGT 2013): kz the largest |d| component.
    uint kx;
    uint ky;
    uint kz;
    vec3 shear;
};

Ray make_ray(vec3 o, vec3 d) {
    Ray r;
    r.o = o;
    // Tiny components as +-TINY: 1 / d stays finite, the ray moves by < TINY t.
    vec3 safe;
    for (int k = 0; k < 3; ++k) {
        safe[k] = abs(d[k]) < TINY ? (d[k] < 0.0 ? -TINY : TINY) : d[k];
    }
    r.inv = 1.0 / safe;
    vec3 a = abs(d);
    r.kz = a.x > a.y ? (a.x > a.z ? 0u : 2u) : (a.y > a.z ? 1u : 2u);
    r.kx = (r.kz + 1u) % 3u;
    r.ky = (r.kz + 2u) % 3u;
    if (d[r.kz] < 0.0) {
        uint k = r.kx;
        r.kx = r.ky;
        r.ky = k;
    }
    r.shear = vec3(d[r.kx] / d[r.kz], d[r.ky] / d[r.kz], 1.0 / d[r.kz]);
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
    precise float x = a[r.kx] - r.shear.x * a[r.kz];
    precise float y = a[r.ky] - r.shear.y * a[r.kz];
    precise float z = r.shear.z * a[r.kz];
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

// Walks from `node` for at most u_budget steps: 1 hit (within the eps limits, not triangle
// `own`), 0 no hit anywhere, 2 unfinished (`node` then holds where to continue).
uint walk(Ray r, float t_end, float len, bool point, uint own, inout uint node) {
    for (uint step = 0u; step < u_budget; ++step) {
        if (node >= u_node_count) {
            return 0u;
        }
        vec4 lo = nodes[NODE_VEC4S * node];
        vec4 hi = nodes[NODE_VEC4S * node + 1u];
        uint skip = floatBitsToUint(lo.w);
        uint leaf = floatBitsToUint(hi.w);
        if (!hits_box(r, lo.xyz, hi.xyz, t_end)) {
            node = skip;
            continue;
        }
        if (leaf == 0u) {
            node += 1u;
            continue;
        }
        uint first = leaf >> LEAF_COUNT_BITS;
        uint count = leaf & ((1u << LEAF_COUNT_BITS) - 1u);
        // A constant bound (MAX_LEAF): unrolled, no loop of its own under the budget.
        for (uint k = 0u; k < 4u; ++k) {
            uint rec = first + k;
            float t;
            if (k < count && floatBitsToUint(tris[TRIANGLE_VEC4S * rec].w) != own && hit_triangle(r, rec, t)) {
                float d = t * len;
                bool beyond_sample = d > u_eps_near;
                bool before_light = point ? (1.0 - t) * len > u_eps : true;
                if (beyond_sample && before_light) {
                    return 1u;
                }
            }
        }
        node = skip;
    }
    return node >= u_node_count ? 0u : 2u;
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
    uint node = u_resume == 0u ? 0u : results[pixel] - 2u;
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
            result = walk(r, t_end, len, point, s.w, node);
        }
    }
    if (result == 2u) {
        results[pixel] = 2u + node;
        uint slot = atomicAdd(lists[4u * u_list_out], 1u);
        lists[8u + u_list_out * u_pixels + slot] = pixel;
    } else {
        results[pixel] = result;
    }
}
