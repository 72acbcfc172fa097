// ray-bvh's shadow ray, shared by native umbra-wgpu (ray_bvh_resolve.wgsl, the resolve pass of
// methods/ray_bvh.rs) and umbra-three's WebGPU path (its wgsl/ray.wgsl, read from this file by
// the package's build): one shadow ray per view sample through the scene's BVH (built on the
// CPU, umbra_geom::ray_bvh; RayBvh::walk is this walk and test in Rust), the twin of
// umbra-gl's ray_bvh/trace.comp.glsl. `sample_occluded(p, triangle)` answers for the visible
// sample `p` on triangle `triangle`.
//
// The including module declares the storage it reads (order-free in WGSL): `nodes` and `tris`
// (the BVH, array<vec4<f32>>), `positions` (array<f32>, x y z per vertex) and `indices`
// (array<u32>, 3 per triangle) of the triangles the BVH was built from, `params` (Params
// below), and the light slot `u` (volume.wgsl). Prepended: the constants NODE_VEC4S,
// TRIANGLE_VEC4S, LEAF_COUNT_BITS, LEAF_BIT, FROM_PARENT, FROM_SIBLING, FROM_CHILD, TINY,
// BUDGET (umbra_geom::ray_bvh's, written out by the host: methods/ray_bvh.rs natively, the
// wasm's umbra_ray_bvh_constants in the page).
//
// The reference's rule, as in trace.comp.glsl: the segment from the sample to the light (the
// ray towards a directional light) meets another triangle, closed and two-sided, farther than
// eps / 2 from the sample and farther than eps from the light; a sample within 2 eps of a
// point light is lit. WGSL has no double: the sample is moved onto its triangle's plane in
// f32. WGSL has no `precise` either: the watertight test relies on the same vertex of two
// triangles going through the same expression (one function, the same operands), whatever
// contraction the compiler applies to it.
//
// One fragment walks the whole hierarchy (no pass to resume in): BUDGET steps at most, each
// at most 1 + 4 loop iterations, below lavapipe's 65,535 loop iterations per invocation; a walk
// longer than that would end as lit (docs/exactness.md states the bound; the exactness grid
// and the torture suite run within it).

struct Params {
    // The reference's eps, its half at the sample end.
    eps: f32,
    eps_near: f32,
    nodes: u32,
    pad: u32,
}

fn vertex_at(i: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

// The sample moved onto its own triangle's plane (f32); a degenerate triangle keeps it.
fn on_own_plane(p: vec3<f32>, t: u32) -> vec3<f32> {
    let a = vertex_at(indices[3u * t]);
    let b = vertex_at(indices[3u * t + 1u]);
    let c = vertex_at(indices[3u * t + 2u]);
    let n = cross(b - a, c - a);
    let nn = dot(n, n);
    if nn > 0.0 {
        return p - n * (dot(n, p - a) / nn);
    }
    return p;
}

struct Ray {
    o: vec3<f32>,
    inv: vec3<f32>,
    // The shear's rows (see trace.comp.glsl).
    mx: vec3<f32>,
    my: vec3<f32>,
    mz: vec3<f32>,
}

fn safe_component(d: f32) -> f32 {
    if abs(d) < TINY {
        return select(TINY, -TINY, d < 0.0);
    }
    return d;
}

fn make_ray(o: vec3<f32>, d: vec3<f32>) -> Ray {
    var r: Ray;
    r.o = o;
    r.inv = 1.0 / vec3<f32>(safe_component(d.x), safe_component(d.y), safe_component(d.z));
    let a = abs(d);
    var ez = vec3<f32>(0.0, 0.0, 1.0);
    var ex = vec3<f32>(1.0, 0.0, 0.0);
    var ey = vec3<f32>(0.0, 1.0, 0.0);
    var dz = d.z;
    if a.x > a.y && a.x > a.z {
        ez = vec3<f32>(1.0, 0.0, 0.0);
        ex = vec3<f32>(0.0, 1.0, 0.0);
        ey = vec3<f32>(0.0, 0.0, 1.0);
        dz = d.x;
    } else if a.y > a.z {
        ez = vec3<f32>(0.0, 1.0, 0.0);
        ex = vec3<f32>(0.0, 0.0, 1.0);
        ey = vec3<f32>(1.0, 0.0, 0.0);
        dz = d.y;
    }
    if dz < 0.0 {
        let e = ex;
        ex = ey;
        ey = e;
    }
    r.mx = ex - (dot(d, ex) / dz) * ez;
    r.my = ey - (dot(d, ey) / dz) * ez;
    r.mz = ez / dz;
    return r;
}

fn hits_box(r: Ray, lo: vec3<f32>, hi: vec3<f32>, t_end: f32) -> bool {
    let a = (lo - r.o) * r.inv;
    let b = (hi - r.o) * r.inv;
    let near = min(a, b);
    let far = max(a, b);
    let t0 = max(max(near.x, near.y), max(near.z, 0.0));
    let t1 = min(min(far.x, far.y), min(far.z, t_end));
    return t0 <= t1;
}

fn sheared(r: Ray, v: vec3<f32>) -> vec3<f32> {
    let a = v - r.o;
    return vec3<f32>(
        a.x * r.mx.x + a.y * r.mx.y + a.z * r.mx.z,
        a.x * r.my.x + a.y * r.my.y + a.z * r.my.z,
        a.x * r.mz.x + a.y * r.mz.y + a.z * r.mz.z,
    );
}

// The edge function from the lexicographically first endpoint, then signed (trace.comp.glsl).
fn edge_function(p: vec3<f32>, q: vec3<f32>, swapped: bool) -> f32 {
    let first = select(p, q, swapped);
    let second = select(q, p, swapped);
    let canonical = first.x * second.y - first.y * second.x;
    return select(-canonical, canonical, swapped);
}

// The ray's t at record `rec`, or -1 when it misses (closed, two-sided; 0 projected area
// misses).
fn hit_triangle(r: Ray, rec: u32) -> f32 {
    let q0 = tris[TRIANGLE_VEC4S * rec];
    let q1 = tris[TRIANGLE_VEC4S * rec + 1u];
    let q2 = tris[TRIANGLE_VEC4S * rec + 2u];
    let edges = bitcast<u32>(q1.w);
    let a = sheared(r, q0.xyz);
    let b = sheared(r, q1.xyz);
    let c = sheared(r, q2.xyz);
    let w = edge_function(a, b, (edges & 1u) != 0u);
    let u = edge_function(b, c, (edges & 2u) != 0u);
    let v = edge_function(c, a, (edges & 4u) != 0u);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return -1.0;
    }
    let det = u + v + w;
    if det == 0.0 {
        return -1.0;
    }
    return (u * a.z + v * b.z + w * c.z) / det;
}

fn near_child(word: u32, d: vec3<f32>) -> u32 {
    let axis = word & 3u;
    let da = select(select(d.z, d.y, axis == 1u), d.x, axis == 0u);
    return (word >> 2u) + select(1u, 0u, da >= 0.0);
}

fn sibling(node: u32) -> u32 {
    return select(node - 1u, node + 1u, (node & 1u) == 1u);
}

// Whether the ray is occluded (the ordered stackless walk, RayBvh::walk).
fn occluded(r: Ray, d: vec3<f32>, t_end: f32, len: f32, point: bool, own: u32) -> bool {
    var state = FROM_PARENT;
    for (var step = 0u; step < BUDGET; step++) {
        let cur = state >> 2u;
        let how = state & 3u;
        let lo = nodes[NODE_VEC4S * cur];
        let parent = bitcast<u32>(lo.w);
        if how == FROM_CHILD {
            if cur == 0u {
                return false;
            }
            let parent_word = bitcast<u32>(nodes[NODE_VEC4S * parent + 1u].w);
            state = select((parent << 2u) | FROM_CHILD, (sibling(cur) << 2u) | FROM_SIBLING,
                           cur == near_child(parent_word, d));
            continue;
        }
        let hi = nodes[NODE_VEC4S * cur + 1u];
        let word = bitcast<u32>(hi.w);
        var leave = true;
        if hits_box(r, lo.xyz, hi.xyz, t_end) {
            if (word & LEAF_BIT) != 0u {
                let first = (word & ~LEAF_BIT) >> LEAF_COUNT_BITS;
                let count = word & ((1u << LEAF_COUNT_BITS) - 1u);
                for (var k = 0u; k < 4u; k++) {
                    if k >= count {
                        break;
                    }
                    let rec = first + k;
                    if bitcast<u32>(tris[TRIANGLE_VEC4S * rec].w) != own {
                        let t = hit_triangle(r, rec);
                        let before_light = !point || (1.0 - t) * len > params.eps;
                        if t >= 0.0 && t * len > params.eps_near && before_light {
                            return true;
                        }
                    }
                }
            } else {
                state = (near_child(word, d) << 2u) | FROM_PARENT;
                leave = false;
            }
        }
        if leave {
            if cur == 0u {
                return false;
            }
            state = select((parent << 2u) | FROM_CHILD, (sibling(cur) << 2u) | FROM_SIBLING, how == FROM_PARENT);
        }
    }
    return false;
}

// Whether the shadow ray of the visible sample `p` on triangle `triangle` is blocked: the
// light slot's light; a BVH of no node blocks nothing.
fn sample_occluded(p: vec3<f32>, triangle: u32) -> bool {
    if params.nodes == 0u {
        return false;
    }
    let o = on_own_plane(p, triangle);
    let point = u.light.w != 0.0;
    var d = normalize(u.light.xyz);
    if point {
        d = u.light.xyz / u.light.w - o;
    }
    let len = select(1.0, length(d), point);
    // A sample within 2 eps of a point light: the segment is empty, it is lit.
    if point && !(len > 2.0 * params.eps) {
        return false;
    }
    let t_end = select(3.4e38, 1.0, point);
    return occluded(make_ray(o, d), d, t_end, len, point, triangle);
}
