// The receiver map of one light on umbra-three's WebGPU path: every visible sample of the
// samples pass (samples.wgsl) raises its light-space cell, level 0 of the GPU cull's pyramid
// (umbra-wgpu's cull.wgsl `cells`), to its distance from the light (point) or its depth along
// it (directional), rounded up: native umbra-wgpu's scatter (receivers.wgsl fs_scatter) with
// the same expressions (receiver_cell.wgsl), one invocation per pixel instead of a scene draw.
// The sample's position is the very f32 world position the depth pass drew (its bits).
//
// A sample whose seen side clearly faces away from the light is left out, as natively: the
// facing pass never lights it whatever its count (its cosine below -2^-10, far beyond the
// rounding by which two programs may compute the facing differently).
// Prepended: `enable clip_distances;`, volume.wgsl (the light slot `u`, umbra_item),
// receiver_cell.wgsl, cull.wgsl (the grid `g`, `cells`), sample_bits.wgsl.

@group(3) @binding(0) var samples: texture_2d<u32>;
// One unit normal per drawn triangle (surface.wgsl's `normals`), counter-clockwise = front.
@group(3) @binding(1) var<storage, read> sample_normals: array<vec4<f32>>;

@compute @workgroup_size(256)
fn scatter_samples(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let size = textureDimensions(samples);
    let k = umbra_item(gid, groups);
    if k >= size.x * size.y {
        return;
    }
    let s = textureLoad(samples, vec2<u32>(k % size.x, k / size.x), 0);
    if s.w == NO_SAMPLE {
        return;
    }
    let p = bitcast<vec3<f32>>(s.xyz);
    var n = sample_normals[s.w & ~BACK_SEEN].xyz;
    if (s.w & BACK_SEEN) != 0u {
        n = -n;
    }
    let l = normalize(u.light.xyz - p * u.light.w);
    if dot(n, l) < -1.0 / 1024.0 {
        return;
    }
    var cell: u32;
    var value: f32;
    if u.light.w != 0.0 {
        let rel = p - u.light.xyz;
        let a = abs(rel);
        // A sample at the light is lit: no cell.
        if !(a.x + a.y + a.z > 0.0) {
            return;
        }
        cell = receiver_cube_cell(rel, g.side);
        value = length(rel) * (1.0 + ROUND_UP);
    } else {
        let rel = p - g.origin.xyz;
        let ci = receiver_cell(dot(rel, g.u.xyz), g.lo_scale.x, g.lo_scale.z, g.side);
        let cj = receiver_cell(dot(rel, g.v.xyz), g.lo_scale.y, g.lo_scale.w, g.side);
        cell = cj * g.side + ci;
        let a = abs(rel);
        value = dot(rel, g.travel.xyz) + (a.x + a.y + a.z) * ROUND_UP;
    }
    atomicMax(&cells[cell], receiver_encode(value));
}
