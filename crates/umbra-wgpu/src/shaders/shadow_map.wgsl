// shadow-map-cube:RES on wgpu (Williams 1978; the omnidirectional cube shadow maps paper 003
// measures against, Section 3.1, Tables 1-2): the twin of umbra-gl's shadow_map/depth.vert.glsl
// and lit.glsl, in two parts.
//
// vs_map: the light's depth pass, one draw per cube face (wgpu has no geometry shader, so
// umbra-gl's layered pass is six passes here) or one for a directional light's map: window
// depth = n / d for a face (d its view depth, infinite far plane), (h - h_min) / (h_max - h_min)
// along the light for the directional map: REVERSED, larger = closer to the light.
//
// vs_resolve (resolve.wgsl) / fs_resolve: the method's decision resolved into the caller's stencil (cleared
// to 1): the scene drawn with depth EQUAL against the caller's depth (the same invariant
// expression as every other scene pass), a fragment whose sample the map sees lit survives and
// sets the stencil to 0 (StencilOperation::Zero), the others are discarded. Lit iff the
// sample's own depth >= the stored (closest occluder's) depth: a comparison sampler with
// GreaterEqual and nearest filtering = a hard test; "+pcf": 3 x 3 texels of the same
// face/map, majority vote (>= 5 of 9 lit), as umbra_lit answers lit or shadowed.
//
// Cube faces are 6 layers of a 2D array in GL's face order +X -X +Y -Y +Z -Z with GL 4.5
// Table 8.19's face selection, computed here as in lit.glsl. wgpu's framebuffer rows run top
// down (GL's bottom up), so a face's t coordinate is flipped when sampled: the map rendered
// and read with the same rule.
// Prepended: `enable clip_distances;`, volume.wgsl (the light slot `u`).

struct Face {
    light_clip_from_world: mat4x4<f32>,
}
// Per face (dynamic offset, 256-byte slots), the map pass's only bind group.
@group(2) @binding(0) var<uniform> face: Face;

@vertex
fn vs_map(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return face.light_clip_from_world * vec4<f32>(p, 1.0);
}

struct Lookup {
    // Directional: (s, t, depth) in [0,1]^3 of the map from world space.
    map_from_world: mat4x4<f32>,
    // xyz: point light position; w: near distance n.
    light_near: vec4<f32>,
    // x: 0 point light (6 layers), 1 directional; y: texels per side.
    kind_resolution: vec4<f32>,
}
@group(1) @binding(0) var map: texture_depth_2d_array;
@group(1) @binding(1) var map_sampler: sampler_comparison;
@group(1) @binding(2) var<uniform> lookup: Lookup;

// (s, t, layer, reference depth) of a world position, t in wgpu's top-down row order.
fn umbra_sm_coords(world_pos: vec3<f32>) -> vec4<f32> {
    let r = world_pos - lookup.light_near.xyz;
    let a = abs(r);
    var ma: f32;
    var layer: f32;
    var sc_tc: vec2<f32>;
    if a.x >= a.y && a.x >= a.z {
        ma = a.x;
        layer = select(1.0, 0.0, r.x >= 0.0);
        sc_tc = select(vec2<f32>(r.z, -r.y), vec2<f32>(-r.z, -r.y), r.x >= 0.0);
    } else if a.y >= a.z {
        ma = a.y;
        layer = select(3.0, 2.0, r.y >= 0.0);
        sc_tc = select(vec2<f32>(r.x, -r.z), vec2<f32>(r.x, r.z), r.y >= 0.0);
    } else {
        ma = a.z;
        layer = select(5.0, 4.0, r.z >= 0.0);
        sc_tc = select(vec2<f32>(-r.x, -r.y), vec2<f32>(r.x, -r.y), r.z >= 0.0);
    }
    // At the light itself (ma = 0): depth +inf, always lit.
    let st = 0.5 * sc_tc / ma + 0.5;
    let cube = vec4<f32>(st.x, 1.0 - st.y, layer, lookup.light_near.w / ma);
    let m = lookup.map_from_world * vec4<f32>(world_pos, 1.0);
    let dir = vec4<f32>(m.x / m.w, 1.0 - m.y / m.w, 0.0, m.z / m.w);
    return select(cube, dir, lookup.kind_resolution.x != 0.0);
}

fn umbra_sm_test(st: vec2<f32>, c: vec4<f32>) -> f32 {
    return textureSampleCompareLevel(map, map_sampler, st, i32(c.z), c.w);
}

fn umbra_lit(world_pos: vec3<f32>) -> bool {
    let c = umbra_sm_coords(world_pos);
    return umbra_sm_test(c.xy, c) > 0.5;
}

fn umbra_lit_pcf(world_pos: vec3<f32>) -> bool {
    let c = umbra_sm_coords(world_pos);
    let texel = 1.0 / lookup.kind_resolution.y;
    var lit = 0.0;
    for (var i = -1; i <= 1; i++) {
        for (var j = -1; j <= 1; j++) {
            let st = clamp(c.xy + texel * vec2<f32>(f32(i), f32(j)), vec2<f32>(0.0), vec2<f32>(1.0));
            lit += umbra_sm_test(st, c);
        }
    }
    return lit >= 4.5;
}

@fragment
fn fs_resolve(v: ResolveVertex) {
    if !umbra_lit(v.world_pos) {
        discard;
    }
}

@fragment
fn fs_resolve_pcf(v: ResolveVertex) {
    if !umbra_lit_pcf(v.world_pos) {
        discard;
    }
}
