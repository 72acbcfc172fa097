// umbra-three's WebGPU volumes, drawn (passes.js): the classify pass's lists (classify.wgsl)
// under the z-fail counting state. vs_inside draws each inside polygon as it is (6 vertices:
// the quad's two triangles, or a cap and a triangle culled); vs_crossing clips each crossing
// polygon (polygon.wgsl umbra_clip) and draws its fan (18 vertices: up to 6 triangles, the
// unused ones culled). Every vertex of a triangle reads the triangle's three corners, for the
// fragment stage's depth range (fs_fan).
// Prepended: `enable clip_distances;`, volume.wgsl, polygon.wgsl.

@group(1) @binding(0) var<storage, read> clip: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read> quads: array<vec2<u32>>;
@group(1) @binding(2) var<storage, read> caps: array<u32>;
// This draw's list (bound at the inside or the crossing list's first word).
@group(1) @binding(3) var<storage, read> list: array<u32>;

struct FanVertex {
    @builtin(position) position: vec4<f32>,
    // (smallest, largest) window depth of the triangle's corners, slightly widened.
    @location(0) @interpolate(flat) depth_range: vec2<f32>,
}

// A triangle the rasteriser discards: its three vertices at one point outside the viewport.
const UMBRA_CULLED: vec4<f32> = vec4<f32>(2.0, 2.0, 0.0, 1.0);

// The vertex `corner` (0-2) of triangle (c0, c1, c2), with the corners' depth range.
// Widened by 2^-20 of each end, so that the rasteriser's own rounding of a corner's depth is
// never clamped (src/webgl/glsl/fan.vert.glsl).
fn umbra_fan_vertex(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, corner: u32) -> FanVertex {
    var o: FanVertex;
    // Reversed-Z with WebGPU's [0, 1] depth range: window depth z / w.
    let z0 = c0.z / c0.w;
    let z1 = c1.z / c1.w;
    let z2 = c2.z / c2.w;
    let lo = min(z0, min(z1, z2));
    let hi = max(z0, max(z1, z2));
    o.depth_range = vec2<f32>(lo - abs(lo) * (1.0 / 1048576.0), hi + abs(hi) * (1.0 / 1048576.0));
    o.position = select(select(c2, c1, corner == 1u), c0, corner == 0u);
    return o;
}

fn umbra_culled() -> FanVertex {
    var o: FanVertex;
    o.position = UMBRA_CULLED;
    o.depth_range = vec2<f32>(0.0);
    return o;
}

@vertex
fn vs_inside(@builtin(vertex_index) vertex: u32) -> FanVertex {
    let p = umbra_polygon(list[vertex / 6u]);
    let k = vertex % 6u;
    let f = k / 3u;
    if f + 2u >= p.n {
        return umbra_culled();
    }
    return umbra_fan_vertex(umbra_drawn(p, p.v[0]), umbra_drawn(p, p.v[f + 1u]), umbra_drawn(p, p.v[f + 2u]), k % 3u);
}

@vertex
fn vs_crossing(@builtin(vertex_index) vertex: u32) -> FanVertex {
    let p = umbra_clip(umbra_polygon(list[vertex / 18u]));
    let k = vertex % 18u;
    let f = k / 3u;
    if f + 2u >= p.n {
        return umbra_culled();
    }
    return umbra_fan_vertex(umbra_drawn(p, p.v[0]), umbra_drawn(p, p.v[f + 1u]), umbra_drawn(p, p.v[f + 2u]), k % 3u);
}

// The stencil counts (colour writes are off); the fragment's depth is kept within its
// triangle's corner depths: a depth interpolated inside a triangle lies between them, one
// outside is the rasteriser's f32 plane-setup error on a needle (a side seen nearly edge-on),
// moved back to the nearest end (a NaN to the smaller end: umbra_volume_depth's reason).
@fragment
fn fs_fan(@builtin(position) position: vec4<f32>, @location(0) @interpolate(flat) depth_range: vec2<f32>) -> @builtin(frag_depth) f32 {
    let z = position.z;
    let nan = (bitcast<u32>(z) & 0x7FFFFFFFu) > 0x7F800000u;
    return select(select(min(z, depth_range.y), depth_range.x, z < depth_range.x), depth_range.x, nan);
}
