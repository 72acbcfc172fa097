// cpu-silhouette: draws the volume umbra_geom::silhouette::extract_indexed built on the CPU
// (paper 001, Sections 2.2-2.3, extrusion Eq. 2), expanded to its very vertices
// (IndexedVolume::expand_into: sides, light caps P0 P1 P2, dark caps P0inf P2inf P1inf, all
// homogeneous world positions, every vertex at infinity extruded by the CPU), in ONE draw
// with ONE vertex shader: every vertex goes through the same clip_from_world * world of the
// same compiled code, so a vertex shared by a side and a cap (the same world bits) lands on
// the same clip bits and the volume is watertight. (umbra-gl draws caps from the mesh's
// position buffer in separate draws and relies on GLSL's `invariant` and `precise`, which
// WGSL lacks.) The light caps, vertices first_light_cap..first_dark_cap, are then clipped at
// the near plane and pushed to the far plane (paper 003 Eq. 6); x, y and w stay those of the
// sides' vertices. Edge-on triangles come as degenerate caps: zero area, no fragment.
// Prepended: `enable clip_distances;`, volume.wgsl.

@vertex
fn vs_volume(@builtin(vertex_index) vertex: u32, @location(0) world: vec4<f32>) -> UmbraVolumeVertex {
    let clip = u.clip_from_world * world;
    if vertex >= u.first_light_cap && vertex < u.first_dark_cap {
        return umbra_volume_vertex(umbra_push_to_far(clip), umbra_near_distance(clip));
    }
    return umbra_volume_vertex(clip, 1.0);
}
