// The transform pass: every welded vertex to camera clip space ONCE per light and frame,
// twice: the point itself (w = 1) and the point extruded away from the light to infinity
// (001 Eq. 2, w = 0). Stored as clip[2 v] and clip[2 v + 1]; every side and cap vertex of
// cs-silhouette and vs-silhouette reads these (shaders/cs_draw.wgsl, vs_draw.wgsl) instead
// of computing clip_from_world * p itself.
//
// Why: a shadow volume is watertight only if triangles sharing an edge have bit-identical
// vertices there. Sides and caps are drawn by different pipelines; WGSL has no `invariant`
// that a driver must honour the way GLSL's `invariant gl_Position` binds umbra-gl's shaders,
// and a compiler may evaluate the same matrix product with different fused multiply-adds in
// two pipelines (a constant w = 1 in one, a w read from memory in the other). Computed once,
// in one place, the vertices are the same bits wherever they are read, whatever the compiler
// does (the orientation pass's argument, for positions). No failure was traced to this; it
// closes the door by construction, and the draws get cheaper (vs-silhouette's sides run
// 6 * maxMult vertices per record).
// Prepended: volume.wgsl (the light slot `u`: matrix, light, u.vertices; umbra_item).

@group(1) @binding(0) var<storage, read> positions: array<f32>;
@group(1) @binding(1) var<storage, read_write> clip: array<vec4<f32>>;

@compute @workgroup_size(256)
fn transform(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let v = umbra_item(gid, groups);
    if v >= u.vertices {
        return;
    }
    let p = vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    clip[2u * v] = u.clip_from_world * vec4<f32>(p, 1.0);
    clip[2u * v + 1u] = u.clip_from_world * umbra_extrude(p, u.light);
}
