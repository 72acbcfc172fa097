// Deterministic orientation with a reference edge, shared by every wgpu silhouette method.
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.2: vertex order Eq. 1 / Alg. 2,
// CompMultiplicity Alg. 4. The WGSL twin of umbra_geom::order and
// umbra_geom::multiplicity::triangle_orientation: the same operations in the same order.
//
// WGSL has no `precise`: a driver may contract a * b + c into a fused multiply-add differently
// in two pipelines (or two call sites), so evaluating Alg. 4 once for a side and once for a cap
// could light a triangle through one and not the other, and open a volume. Hence this file is
// used in ONE place per method: the orientation pass (orientation.wgsl) evaluates every
// triangle's orientation once per light and frame and stores it; sides (the per-edge sum of
// Alg. 3) and caps read that stored value. Whatever rounding the driver chose, sides and caps
// agree, so the volume closes.
//
// No enable directives or bindings here: spliced after a shader's own.

// sgn(a - b) by comparison: exact for every pair of floats (Alg. 2 without the subtraction,
// which could underflow to 0 for distinct a, b).
fn umbra_sign_of_difference(a: f32, b: f32) -> i32 {
    return select(0, 1, a > b) - select(0, 1, a < b);
}

// Alg. 2: > 0 when a > b, < 0 when a < b, 0 when equal (lexicographic on x, y, z).
fn umbra_greater(a: vec3<f32>, b: vec3<f32>) -> i32 {
    return 4 * umbra_sign_of_difference(a.x, b.x) + 2 * umbra_sign_of_difference(a.y, b.y)
        + umbra_sign_of_difference(a.z, b.z);
}

// Alg. 4, CompMultiplicity(A, B, C, L) for A < B < C: sgn(((C - A) x (L.xyz - A * L.w)) . (B - A)).
// +1 when triangle A -> B -> C (counter-clockwise) faces the light.
fn umbra_comp_multiplicity(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, l: vec4<f32>) -> i32 {
    let x = c - a;
    let y = vec3<f32>(l.x - a.x * l.w, l.y - a.y * l.w, l.z - a.z * l.w);
    let n = vec3<f32>(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
    let d = b - a;
    let dot_nd = n.x * d.x + n.y * d.y + n.z * d.z;
    return select(0, 1, dot_nd > 0.0) - select(0, 1, dot_nd < 0.0);
}

// Orientation of triangle p0 -> p1 -> p2 towards the light through its reference edge (the
// sorting network of umbra_geom::multiplicity::triangle_orientation): +1 faces the light,
// -1 faces away, 0 edge-on.
fn umbra_triangle_orientation(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>, l: vec4<f32>) -> i32 {
    var a = p0;
    var b = p1;
    var c = p2;
    var t: vec3<f32>;
    var parity = 1;
    if umbra_greater(a, b) > 0 { t = a; a = b; b = t; parity = -parity; }
    if umbra_greater(b, c) > 0 { t = b; b = c; c = t; parity = -parity; }
    if umbra_greater(a, b) > 0 { t = a; a = b; b = t; parity = -parity; }
    return parity * umbra_comp_multiplicity(a, b, c, l);
}
