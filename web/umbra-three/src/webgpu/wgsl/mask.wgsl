// umbra-three's decision pass on WebGPU (passes.js): one triangle over the whole viewport,
// drawn after a light's volumes with the stencil test EQUAL to the count's start (0, z-fail),
// writes white (lit) into the light's r8unorm mask, which was cleared to black (shadowed).
// The facing pass follows (surface.wgsl fs_facing): on the scene's surface, where the count is
// 0, the seen side's facing towards the light replaces it (0 where it faces away); pixels no
// umbra-drawn triangle covers keep this pass's decision. three.js's lit node materials read
// that mask through the light's shadow node (umbra-shadows-webgpu.js). No bindings.

@vertex
fn vs_mask(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // Vertices (-1, -1), (3, -1), (-1, 3): the viewport and beyond, one triangle.
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_mask() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
