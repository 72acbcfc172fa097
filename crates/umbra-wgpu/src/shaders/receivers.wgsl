// The receiver map of one light (umbra_geom::receivers), the WGSL twin of umbra-gl's
// receivers/scatter.frag.glsl: every visible sample that may receive the light raises its
// light-space cell to its distance from the light (point) or its depth along the light
// (directional), rounded up, with the expressions of ReceiverGrid::sample_cell.
// cpu-silhouette reads the map back and culls and clamps its volumes against it exactly (CC
// shadow volumes, Lloyd et al., EGSR 2004; docs/exactness.md, "Volumes clamped to their
// receivers").
//
// Drawn with the host's depth as a read-only attachment and as a texture. Where the device has
// SHADER_EARLY_DEPTH_TEST, receivers.rs puts `@early_depth_test(force)` on fs_scatter and the
// pipeline tests depth EQUAL, so hidden fragments never run it (as umbra-gl's
// early_fragment_tests). Standard WGSL cannot ask for that, and the atomic write happens
// whether or not a later test fails, so the shader also tests the depth itself (the only test
// without the feature): a fragment is a visible sample when
// its depth is the stored one (reversed-Z: nearer is greater, so `>=` the stored depth less
// `depth_slack`, which is 0 for a float depth, whose stored value is the fragment's very depth
// from the same invariant expression as the host's depth pass). Any extra sample a slack lets
// in only raises its cell: the map stays an upper bound, and only keeps more.
//
// A sample whose seen side clearly faces away from the light is left out: the lighting pass
// never lights it, whatever its count. "Clearly": its cosine with the light is below -2^-10,
// far beyond the rounding by which two programs may compute `n_dot_l > 0` differently.
//
// Cells and values need not be the CPU's very bits: the CPU widens each triangle's cell
// rectangle by RECEIVER_MARGIN of the grid, and each value is rounded up by 2^-20 of the
// magnitudes involved, far beyond a contraction of `a * b + c` here.
// Prepended: `enable primitive_index;`.

struct Scatter {
    // Camera clip space from world space, as the host's depth pass used it.
    clip_from_world: mat4x4<f32>,
    // w = 1 point light, w = 0 directional light coming FROM xyz.
    light: vec4<f32>,
    // ReceiverGrid::Flat (directional): origin, u, v, travel (xyz), lo (xy) and scale (zw).
    origin: vec4<f32>,
    u: vec4<f32>,
    v: vec4<f32>,
    travel: vec4<f32>,
    lo_scale: vec4<f32>,
    // Cells along a side (both grids).
    side: u32,
    // How far below the stored depth a fragment still counts as the visible sample.
    depth_slack: f32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> s: Scatter;
// One unit normal per triangle (w unused), indexed by primitive_index; counter-clockwise = front.
@group(0) @binding(1) var<storage, read> triangle_normals: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> receivers: array<atomic<u32>>;
@group(0) @binding(3) var depth: texture_depth_2d;

struct ScatterVertex {
    // The host's depth pass computes the same expression with an invariant position.
    @builtin(position) @invariant position: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
}

@vertex
fn vs_scatter(@location(0) world_pos: vec3<f32>) -> ScatterVertex {
    var o: ScatterVertex;
    o.world_pos = world_pos;
    o.position = s.clip_from_world * vec4<f32>(world_pos, 1.0);
    return o;
}

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

@fragment
fn fs_scatter(
    f: ScatterVertex,
    @builtin(front_facing) front: bool,
    @builtin(primitive_index) triangle: u32,
) {
    let seen = textureLoad(depth, vec2<i32>(f.position.xy), 0);
    if f.position.z < seen - s.depth_slack {
        return;
    }
    var n = triangle_normals[triangle].xyz;
    if !front {
        n = -n;
    }
    let l = normalize(s.light.xyz - f.world_pos * s.light.w);
    if dot(n, l) < -1.0 / 1024.0 {
        return;
    }
    var cell: u32;
    var value: f32;
    if s.light.w != 0.0 {
        let rel = f.world_pos - s.light.xyz;
        let a = abs(rel);
        // A sample at the light is lit: no cell.
        if !(a.x + a.y + a.z > 0.0) {
            return;
        }
        cell = receiver_cube_cell(rel, s.side);
        value = length(rel) * (1.0 + ROUND_UP);
    } else {
        let rel = f.world_pos - s.origin.xyz;
        let ci = receiver_cell(dot(rel, s.u.xyz), s.lo_scale.x, s.lo_scale.z, s.side);
        let cj = receiver_cell(dot(rel, s.v.xyz), s.lo_scale.y, s.lo_scale.w, s.side);
        cell = cj * s.side + ci;
        let a = abs(rel);
        value = dot(rel, s.travel.xyz) + (a.x + a.y + a.z) * ROUND_UP;
    }
    atomicMax(&receivers[cell], receiver_encode(value));
}
