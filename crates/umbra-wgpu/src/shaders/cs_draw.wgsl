// cs-silhouette: draws what the compute passes compacted, with indirect draws (vertex counts
// written by the GPU: no CPU round trip). The twin of umbra-gl's cs_silhouette/sides.vert.glsl
// and caps.vert.glsl, except that no vertex is transformed here: every clip position comes
// from the transform pass (transform.wgsl: clip[2 v] the vertex, clip[2 v + 1] it extruded
// to infinity), so sides and caps share bit-identical vertices.
// Sides (paper 001 Section 2.2, Eq. 2): quad q = vertex_index / 6 reads its record (X, Y);
// triangles (Y, X, X_inf) and (Y, X_inf, Y_inf), exactly cpu-silhouette's vertices and order.
// Caps: cap c = vertex_index / vertices_per_cap, v = the rest: 0-2 the light cap P0 P1 P2
// pushed to the far plane (paper 003 Eq. 6) and clipped at the near plane, 3-5 (point lights
// only) the dark cap P2 P1 P0 at infinity (paper 003 Alg. 2, line 11; 001 Eq. 2).
// Prepended: `enable clip_distances;`, volume.wgsl.

@group(1) @binding(0) var<storage, read> clip: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read> quads: array<vec2<u32>>;
@group(1) @binding(2) var<storage, read> caps: array<u32>;

@vertex
fn vs_sides(@builtin(vertex_index) vertex: u32) -> UmbraVolumeVertex {
    let xy = quads[vertex / 6u];
    let v = vertex % 6u;
    // v: 0 Y, 1 X, 2 X_inf, 3 Y, 4 X_inf, 5 Y_inf.
    let is_x = v == 1u || v == 2u || v == 4u;
    let at_infinity = v == 2u || v == 4u || v == 5u;
    let i = select(xy.y, xy.x, is_x);
    return umbra_volume_vertex(clip[2u * i + select(0u, 1u, at_infinity)], 1.0);
}

@vertex
fn vs_caps(@builtin(vertex_index) vertex: u32) -> UmbraVolumeVertex {
    let c = vertex / u.vertices_per_cap;
    let v = vertex % u.vertices_per_cap;
    let k = select(5u - v, v, v < 3u);
    let i = caps[3u * c + k];
    if v < 3u {
        let p = clip[2u * i];
        return umbra_volume_vertex(umbra_push_to_far(p), umbra_near_distance(p));
    }
    return umbra_volume_vertex(clip[2u * i + 1u], 1.0);
}
