// The cells of a light's receiver map and the encoding its atomicMax works on
// (umbra_geom::receivers: ReceiverGrid::sample_cell's f32 expressions, encode), shared by the
// native scatter (receivers.wgsl), the GPU cull (cull.wgsl) and umbra-three's WebGPU scatter
// of its samples. No bindings: spliced after a shader's own enable directives.

// Order-preserving f32 -> u32 (a larger float gives a larger word; 0 is below every float).
fn receiver_encode(x: f32) -> u32 {
    let u = bitcast<u32>(x);
    return select(u | 0x80000000u, ~u, (u & 0x80000000u) != 0u);
}

// The cell index along one axis of a coordinate x, n cells (clamped).
fn receiver_cell(x: f32, lo: f32, scale: f32, n: u32) -> u32 {
    return u32(clamp(floor((x - lo) * scale), 0.0, f32(n - 1u)));
}

// A point light's cell of the direction `rel` (not zero): the cube face of its largest
// coordinate (ties: x, then y; face 2m for +, 2m + 1 for -), the other two divided by it.
fn receiver_cube_cell(rel: vec3<f32>, side: u32) -> u32 {
    let a = abs(rel);
    var m = 2u;
    if a.x >= a.y && a.x >= a.z {
        m = 0u;
    } else if a.y >= a.z {
        m = 1u;
    }
    let face = 2u * m + select(0u, 1u, rel[m] < 0.0);
    let uv = vec2<f32>(rel[(m + 1u) % 3u], rel[(m + 2u) % 3u]) / a[m];
    let scale = 0.5 * f32(side);
    let ci = receiver_cell(uv.x, -1.0, scale, side);
    let cj = receiver_cell(uv.y, -1.0, scale, side);
    return (face * side + cj) * side + ci;
}

const ROUND_UP: f32 = 1.0 / 1048576.0;
