// Receiver maps (hier-triangle's, hier_triangle/receivers.glsl, and cpu-silhouette's cull,
// receivers/scatter.frag.glsl; umbra_geom::receivers on the CPU): a light-space cell per
// sample and the order-preserving encoding its atomicMax works on. No #version line: spliced
// after a shader's own.

// Order-preserving f32 -> u32 (a larger float gives a larger word; 0 is below every float).
uint receiver_encode(float x) {
    uint u = floatBitsToUint(x);
    return (u & 0x80000000u) != 0u ? ~u : (u | 0x80000000u);
}

float receiver_decode(uint e) {
    return uintBitsToFloat((e & 0x80000000u) != 0u ? (e & 0x7FFFFFFFu) : ~e);
}

// The cell index along one axis of a coordinate x in [lo, lo + extent), n cells (clamped).
uint receiver_cell(float x, float lo, float scale, uint n) {
    return uint(clamp(floor((x - lo) * scale), 0.0, float(n - 1u)));
}

// A point light's cell of the direction `rel` (not zero): the cube face of its largest
// coordinate (ties: x, then y; the face 2m for +, 2m + 1 for -), the other two divided by it,
// `side` x `side` cells in [-1, 1] (umbra_geom::receivers::ReceiverGrid::sample_cell).
uint receiver_cube_cell(vec3 rel, uint side) {
    vec3 a = abs(rel);
    uint m = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
    uint face = 2u * m + (rel[m] < 0.0 ? 1u : 0u);
    vec2 uv = vec2(rel[(m + 1u) % 3u], rel[(m + 2u) % 3u]) / a[m];
    float scale = 0.5 * float(side);
    uint ci = receiver_cell(uv.x, -1.0, scale, side);
    uint cj = receiver_cell(uv.y, -1.0, scale, side);
    return (face * side + cj) * side + ci;
}
