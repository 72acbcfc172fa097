// ray-bvh's resolve pass on native umbra-wgpu (methods/ray_bvh.rs): the shadow ray of
// ray_bvh.wgsl traced where the decision is resolved into the caller's stencil: the scene drawn
// with depth EQUAL against the caller's depth (the same invariant expression as every other
// scene pass), so each fragment is the visible sample of its pixel (its interpolated world
// position and primitive_index, the triangle id); a fragment whose ray meets nothing survives
// and sets the stencil to 0 (lit), the others are discarded (the stencil was cleared to 1).
// Prepended: `enable primitive_index;`, volume.wgsl (the light slot `u`), resolve.wgsl, the
// constants, ray_bvh.wgsl.

@group(1) @binding(0) var<storage, read> nodes: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read> tris: array<vec4<f32>>;
@group(1) @binding(2) var<storage, read> positions: array<f32>;
@group(1) @binding(3) var<storage, read> indices: array<u32>;
@group(1) @binding(4) var<uniform> params: Params;

@fragment
fn fs_resolve(v: ResolveVertex, @builtin(primitive_index) triangle: u32) {
    if sample_occluded(v.world_pos, triangle) {
        discard;
    }
}
