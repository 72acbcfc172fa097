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
// Prepended: `enable primitive_index;`, receiver_cell.wgsl (the cells and the encoding).

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
