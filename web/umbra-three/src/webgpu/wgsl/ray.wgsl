// ray-bvh on umbra-three's WebGPU path (rays.js): native umbra-wgpu's shadow ray (its
// shaders/ray_bvh.wgsl, the walk through the BVH the wasm builds with umbra_geom::ray_bvh)
// from each visible sample of umbra's depth pass, in two passes:
//   1. fs_sample, once per frame: every triangle drawn again on the depth pass's surface
//      (surface.wgsl vs_surface, depth EQUAL), each fragment writing its pixel's visible
//      sample into an rgba32uint texture: its world position's f32 bits and its triangle, the
//      seen side in the top bit. An integer target keeps the bits as they are.
//   2. fs_ray, per light: one triangle over the viewport, so each pixel's ray is walked once.
//      Reason: walked in the scene pass itself, a ray runs for every fragment the rasterizer
//      shades before its depth test, and SwiftShader shaded covered fragments behind the
//      surface too: 23.1 s for Sibenik's point light at 640 x 360, against 10.1-11.1 s here.
//      The decision: lit = no caster on the ray AND the seen side
//      faces the light (native umbra's decision, surface.wgsl faces_light); a pixel without a
//      sample is lit, as where no volume counts.
// Prepended: `enable clip_distances;`, volume.wgsl (the light slot `u`), surface.wgsl (the
// storage `positions`, `indices` and `normals`, group 1, which the walk and the facing read),
// mask.wgsl (vs_mask: one triangle over the viewport, pass 2's vertex stage), the wasm's
// constants, ray_bvh.wgsl, sample_bits.wgsl and samples.wgsl (pass 1: fs_sample).

// The BVH (umbra_geom::ray_bvh's vec4 layout), the walk's Params (ray_bvh.wgsl) and the
// samples of pass 1.
@group(2) @binding(0) var<storage, read> nodes: array<vec4<f32>>;
@group(2) @binding(1) var<storage, read> tris: array<vec4<f32>>;
@group(2) @binding(2) var<uniform> params: Params;
@group(2) @binding(3) var samples: texture_2d<u32>;

@fragment
fn fs_ray(@builtin(position) pixel: vec4<f32>) -> @location(0) vec4<f32> {
    let s = textureLoad(samples, vec2<u32>(pixel.xy), 0);
    if s.w == NO_SAMPLE {
        return vec4<f32>(1.0);
    }
    let p = bitcast<vec3<f32>>(s.xyz);
    let triangle = s.w & ~BACK_SEEN;
    // Reason for the order: a sample whose seen side faces away is shadowed without its ray.
    let lit = faces_light(p, triangle, (s.w & BACK_SEEN) == 0u) && !sample_occluded(p, triangle);
    return vec4<f32>(select(0.0, 1.0, lit));
}
