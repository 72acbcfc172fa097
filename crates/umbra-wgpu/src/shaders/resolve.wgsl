// The vertex stage of a surface resolve (Common::surface_resolve_pipeline): the scene's
// positions drawn with the same invariant clip_from_world expression as every other scene pass,
// so that depth EQUAL against the caller's depth keeps exactly its visible surface; the world
// position goes to the method's fs_resolve. Needs volume.wgsl's light slot `u`.

struct ResolveVertex {
    @builtin(position) @invariant position: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
}

@vertex
fn vs_resolve(@location(0) p: vec3<f32>) -> ResolveVertex {
    var o: ResolveVertex;
    o.world_pos = p;
    o.position = u.clip_from_world * vec4<f32>(p, 1.0);
    return o;
}
