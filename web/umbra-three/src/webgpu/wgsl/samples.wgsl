// The samples pass of umbra-three's WebGPU path: every triangle drawn again on the depth
// pass's surface (surface.wgsl vs_surface, depth EQUAL), each fragment writing its pixel's
// visible sample into an rgba32uint texture (sample_bits.wgsl). An integer target keeps the
// bits as they are. Read by the rays (ray.wgsl) and by the receiver map's scatter
// (scatter.wgsl). Prepended: volume.wgsl, surface.wgsl, sample_bits.wgsl.

@fragment
fn fs_sample(v: SurfaceVertex, @builtin(front_facing) front: bool) -> @location(0) vec4<u32> {
    return vec4<u32>(bitcast<vec3<u32>>(v.world_pos), v.triangle | select(BACK_SEEN, 0u, front));
}
