// cpu-silhouette: draws the volume umbra_geom::silhouette::extract_indexed built on the CPU
// (paper 001, Sections 2.2-2.3, extrusion Eq. 2), the twin of umbra-gl's
// cpu_silhouette/volume.vert.glsl, one entry point per part:
//   vs_sides:      CPU-built homogeneous world positions (vec4), drawn as they are; two of
//                  every quad's vertices are at infinity (w = 0);
//   vs_light_caps: the scene's welded positions indexed by the CPU-oriented caps, clipped at
//                  the near plane and pushed to the far plane (paper 003 Eq. 6);
//   vs_dark_caps:  the same positions and indices extruded to infinity here with Eq. 2, the
//                  CPU's expression (l.w is 0 or 1, so no contraction can change a bit: a dark
//                  cap's vertex equals the side vertex it shares), drawn with the front face
//                  flipped (Cw), which reverses their winding as the volume needs (P0inf P2inf
//                  P1inf).
// Edge-on triangles come as degenerate caps (one vertex three times): zero area, no fragment.
// Prepended: `enable clip_distances;`, volume.wgsl.

@vertex
fn vs_sides(@location(0) world: vec4<f32>) -> UmbraVolumeVertex {
    return umbra_volume_vertex(u.clip_from_world * world, 1.0);
}

@vertex
fn vs_light_caps(@location(0) p: vec3<f32>) -> UmbraVolumeVertex {
    let clip = u.clip_from_world * vec4<f32>(p, 1.0);
    return umbra_volume_vertex(umbra_push_to_far(clip), umbra_near_distance(clip));
}

@vertex
fn vs_dark_caps(@location(0) p: vec3<f32>) -> UmbraVolumeVertex {
    return umbra_volume_vertex(u.clip_from_world * umbra_extrude(p, u.light), 1.0);
}
