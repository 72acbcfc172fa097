// What every shadow-volume vertex shader of umbra-wgpu shares: the per-light uniforms, the
// extrusion to infinity (001 Eq. 2), light caps pushed to the far plane (paper 003 Eq. 6), the
// near-plane clip of light caps and the scene-box clip of z-pass volumes (clip distances), and
// the counting fragment shader; and what the compute passes share: their invocation index and
// the indirect draw command they compact into. The WGSL twin of umbra-gl's
// methods/shared/depth.glsl. No enable directives: the Rust side prepends
// `enable clip_distances;`.

// Per light (group 0, binding 0, one 256-byte slot per light, dynamic offset).
struct UmbraLight {
    // Camera clip space from world space (reversed-Z, infinite far plane), f32 columns.
    clip_from_world: mat4x4<f32>,
    // w = 1 point light, w = 0 directional light coming FROM xyz.
    light: vec4<f32>,
    // The z-pass scene box in clip space ((clip_from_world)^-T times the world planes), used
    // when scene_clip != 0.
    scene_planes: array<vec4<f32>, 6>,
    // Clip z of the far plane as a multiple of w: 0 under reversed-Z (depth exactly 0).
    far_clip_z: f32,
    // 1: this light counts z-pass and its volumes are clipped to the scene box.
    scene_clip: u32,
    // Cap vertices per triangle: 6 (light cap + dark cap) for a point light, 3 for a
    // directional one (its dark cap has zero area).
    vertices_per_cap: u32,
    // Triangles of the scene (the orientation pass and vs-silhouette's caps).
    triangles: u32,
    // Edge records (the sides of cs-silhouette and vs-silhouette).
    records: u32,
    // Opposite slots per edge record (vs-silhouette's maxMult).
    max_mult: u32,
    // Welded vertices (the transform pass).
    vertices: u32,
    pad0: u32,
    // cpu-silhouette's one vertex stream: its light caps are vertices
    // first_light_cap..first_dark_cap (sides before, dark caps after).
    first_light_cap: u32,
    first_dark_cap: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> u: UmbraLight;

// Clip distance 0: the near-plane clip of light caps; 1-6: the scene box (z-pass only).
struct UmbraVolumeVertex {
    // w = 1 vertices land exactly where the scene's vertex shader puts the same point: the
    // same expression, invariant (SPIR-V Invariant, MSL invariant, HLSL precise).
    @builtin(position) @invariant position: vec4<f32>,
    @builtin(clip_distances) clip_distances: array<f32, 7>,
}

// P extruded away from the light to infinity: (P * l.w - L.xyz, 0) (001 Eq. 2). l.w is 0 or 1,
// so P * l.w is exact and no contraction can change the result: a side's and a dark cap's
// vertex at infinity are the same bits.
fn umbra_extrude(p: vec3<f32>, l: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(p * l.w - l.xyz, 0.0);
}

// Paper 003 Eq. 6, B = (a_x, a_y, a_w, a_w) in the standard convention: the light cap keeps its
// screen footprint and moves to the far plane (depth exactly 0 under reversed-Z), so it FAILS
// the strict depth test (GREATER) at every sample, background included, and z-fail always
// counts it; only samples the caster itself hides change.
fn umbra_push_to_far(clip: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(clip.xy, u.far_clip_z * clip.w, clip.w);
}

// Clip-space distance from the near plane (reversed-Z: the near plane is z = w).
fn umbra_near_distance(clip: vec4<f32>) -> f32 {
    return clip.w - clip.z;
}

// A volume vertex at `clip`. `near_distance`: the light cap's umbra_near_distance (computed
// before it was pushed), 1 for every other vertex. Light caps of casters the camera's near
// plane cuts are clipped at that plane: the scene's depth pass clipped the caster there, so a
// sample seen through the cut-away part is visible, and a cap pushed to the far plane would
// count behind it (umbra-gl's torture case near-plane-cuts-caster, found on Crytek Sponza).
// The scene box (z-pass lights only): z-pass counts crossings between the eye and the sample,
// both inside the box, so clipping the volumes to it removes no counted crossing, only fill.
fn umbra_volume_vertex(clip: vec4<f32>, near_distance: f32) -> UmbraVolumeVertex {
    var o: UmbraVolumeVertex;
    o.position = clip;
    o.clip_distances[0] = near_distance;
    let clipped = u.scene_clip != 0u;
    for (var i = 0; i < 6; i++) {
        o.clip_distances[i + 1] = select(1.0, dot(u.scene_planes[i], clip), clipped);
    }
    return o;
}

// Counting pass: the stencil operations count (two-sided, INCR_WRAP / DECR_WRAP); no colour
// is written (every colour target's write mask is empty). The one thing computed is the depth
// the depth test sees: the rasterizer's own, except that a NaN becomes 0, the far plane.
// Why: a side quad of a short silhouette edge has its two vertices at infinity a fraction of a
// pixel apart, so one of its triangles is a needle; lavapipe gave such a needle a fragment with
// a NaN depth (Conference, z-fail: three duplicate needles over one floor sample), the clamped
// NaN passed the GREATER test, and the sample lost three back faces (a stencil of -3, a false
// shadow). A needle's fragments lie at its far end, by the vertices at infinity (depth 0), so 0
// is their depth up to the needle's width; and 0 is what z-fail counts as behind every sample,
// like the caps at infinity. Any other depth passes through unchanged (the same bits).
fn umbra_volume_depth(z: f32) -> f32 {
    // A NaN test on the bits: a compiler may assume no NaN in floating-point comparisons.
    let nan = (bitcast<u32>(z) & 0x7FFFFFFFu) > 0x7F800000u;
    return select(z, 0.0, nan);
}

@fragment
fn fs_volume(@builtin(position) position: vec4<f32>) -> @builtin(frag_depth) f32 {
    return umbra_volume_depth(position.z);
}

// Multisampled passes: a written depth holds for every sample of the fragment, so the shader
// runs per sample (reading sample_index asks for it) and position.z is that sample's depth.
@fragment
fn fs_volume_per_sample(@builtin(position) position: vec4<f32>, @builtin(sample_index) sample: u32) -> @builtin(frag_depth) f32 {
    _ = sample;
    return umbra_volume_depth(position.z);
}

// Invocation index over a 2D grid of 256-wide workgroups (a dimension holds at most 65,535;
// volumes.rs, dispatch_size).
fn umbra_item(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 256u;
}

// A draw-indirect command whose vertex count a compute pass reserves with atomicAdd
// (cs-silhouette: cs_sides.wgsl, orientation.wgsl).
struct DrawCommand {
    vertex_count: atomic<u32>,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}
