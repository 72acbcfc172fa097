// ray-bvh on umbra-three's WebGPU path (rays.js): native umbra-wgpu's shadow ray (its
// shaders/ray_bvh.wgsl, the walk through the BVH the wasm builds with umbra_geom::ray_bvh) from
// each visible sample of umbra's depth pass. Drawn as the facing pass is (surface.wgsl
// vs_surface, depth EQUAL on the depth pass's surface): each fragment is its pixel's visible
// sample, with its world position and its triangle (the id its ray skips). The decision:
// lit = the ray meets no caster AND the seen side faces the light (native umbra's decision,
// surface.wgsl seen_side_faces_light).
// Prepended: `enable clip_distances;`, volume.wgsl (the light slot `u`), surface.wgsl (the
// storage `positions` and `indices` the walk reads, group 1), the wasm's constants,
// ray_bvh.wgsl.

// The BVH (umbra_geom::ray_bvh's vec4 layout) and the walk's Params (ray_bvh.wgsl).
@group(2) @binding(0) var<storage, read> nodes: array<vec4<f32>>;
@group(2) @binding(1) var<storage, read> tris: array<vec4<f32>>;
@group(2) @binding(2) var<uniform> params: Params;

@fragment
fn fs_ray(v: SurfaceVertex, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Reason for the order: a sample whose seen side faces away is shadowed without its ray.
    let lit = seen_side_faces_light(v, front) && !sample_occluded(v.world_pos, v.triangle);
    return vec4<f32>(select(0.0, 1.0, lit));
}
