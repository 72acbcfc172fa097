// The scene's surface on umbra-three's WebGPU path (passes.js): every drawn triangle, in world
// space (world.js), pulled from storage by vertex_index (a non-indexed draw of 3 vertices per
// triangle), so that the fragment stage knows its triangle without WebGPU's optional
// primitive_index. Two pipelines share vs_surface, and so bit for bit the same positions and
// depths:
//   * the depth pass (no fragment stage): umbra's depth, what the volumes count against;
//   * the facing pass, after a light's count and its stencil-EQUAL-0 decision (mask.wgsl):
//     depth EQUAL on the depth pass's surface, stencil EQUAL 0, writes the seen side's facing
//     into the light's mask (fs_facing).
// Why the facing pass: the decision at a sample is lit = (count 0) AND (the seen side of its
// triangle faces the light) (docs/exactness.md, "The method's decision"; native umbra-wgpu's
// scene.wgsl umbra_shade, the WebGL path's mask.frag.glsl). Without it a sample on a triangle
// whose unlit side the camera sees rests on the count alone, and there its own volume's sides
// pass within a fraction of a pixel of it, at nearly its depth: SwiftShader's snapping and
// f32 depth setup of those sides, not in the band, decided it (Crytek Sponza, 640 x 360: 59
// false-light samples outside the band, nearly all "first hit towards the light: own
// triangle"). The facing is the reference's plane test, whose precision the band has (FACING).
// Prepended: `enable clip_distances;`, volume.wgsl (the light slot `u`).

// World positions (x y z per vertex, f32) and 3 vertex indices per triangle: the merged frame.
@group(1) @binding(0) var<storage, read> positions: array<f32>;
@group(1) @binding(1) var<storage, read> indices: array<u32>;
// One unit normal per triangle (w unused), counter-clockwise = front: umbra_geom::flat_normal
// of the world positions, in f64 rounded to f32 (world.js triangleNormals), as native umbra's
// triangle_normals.
@group(1) @binding(2) var<storage, read> normals: array<vec4<f32>>;

struct SurfaceVertex {
    // The expression of every umbra pass's w = 1 vertices (transform.wgsl, resolve.wgsl):
    // clip_from_world * (p, 1), invariant.
    @builtin(position) @invariant position: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
    @location(1) @interpolate(flat) triangle: u32,
}

@vertex
fn vs_surface(@builtin(vertex_index) vertex: u32) -> SurfaceVertex {
    let i = indices[vertex];
    let p = vec3<f32>(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
    var o: SurfaceVertex;
    o.world_pos = p;
    o.triangle = vertex / 3u;
    o.position = u.clip_from_world * vec4<f32>(p, 1.0);
    return o;
}

// Whether the seen side of triangle `triangle` faces the light at `p` (false for a triangle
// without area): native umbra-wgpu's faces_light (scene.wgsl umbra_shade), the normal flipped
// to the side the camera sees by `front` (front_facing, decided from the same clip-space
// vertices as coverage; the pipeline's front face is counter-clockwise, the normal's winding,
// in world space, so a mirroring world matrix needs nothing more). Also ray.wgsl's.
fn faces_light(p: vec3<f32>, triangle: u32, front: bool) -> bool {
    var n = normals[triangle].xyz;
    if !front {
        n = -n;
    }
    let l = normalize(u.light.xyz - p * u.light.w);
    return dot(n, l) > 0.0;
}

// 1 where the seen side faces the light, 0 where it faces away (or the triangle has no area).
@fragment
fn fs_facing(v: SurfaceVertex, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(select(0.0, 1.0, faces_light(v.world_pos, v.triangle, front)));
}
