// The stand-alone frame's scene passes (Heidmann 1991; Everitt & Kilgard 2002 §2), the twin of
// umbra-gl's shaders/scene.vert.glsl, depth_ambient.frag.glsl and lighting.frag.glsl.
//
// vs_scene is shared VERBATIM by the depth pass and the lighting pass, and computes the same
// expression as every shadow-volume vertex shader's w = 1 vertices (clip_from_world * (p, 1)),
// with an invariant position: bit-identical depths, so the lighting pass's depth EQUAL selects
// exactly the visible surface and the volumes meet the casters without cracks.
//
// Triangle ids: the scene is one indexed draw over all triangles in order, so primitive_index
// is the index into WeldedMesh::triangles (the id the ray-traced oracle receives).
// Prepended: `enable primitive_index;`.

struct Frame {
    clip_from_world: mat4x4<f32>,
    // xyz: albedo * ambient.
    ambient: vec4<f32>,
    // xyz: the eye (world space).
    eye: vec4<f32>,
    // xyz: albedo.
    albedo: vec4<f32>,
    // xyz: the light colour.
    light_color: vec4<f32>,
    // x: Blinn-Phong specular strength, y: exponent.
    specular: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
// One unit normal per triangle (w unused), indexed by primitive_index; counter-clockwise = front.
@group(0) @binding(1) var<storage, read> triangle_normals: array<vec4<f32>>;

struct Light {
    // w = 1 point light, w = 0 directional light coming FROM xyz.
    light: vec4<f32>,
}
// Per light: one 256-byte slot per light, dynamic offset.
@group(1) @binding(0) var<uniform> light: Light;

struct SceneVertex {
    @builtin(position) @invariant position: vec4<f32>,
    @location(0) world_pos: vec3<f32>,
}

@vertex
fn vs_scene(@location(0) world_pos: vec3<f32>) -> SceneVertex {
    var o: SceneVertex;
    o.world_pos = world_pos;
    o.position = frame.clip_from_world * vec4<f32>(world_pos, 1.0);
    return o;
}

// Pass 1: depth + ambient, and the verification attachments.
//   location 0: ambient colour (RGBA8);
//   location 1: world position (RGBA32F, w = 1 marks geometry) for the ray-traced oracle;
//   location 2: triangle id (R32Uint).
struct DepthOut {
    @location(0) color: vec4<f32>,
    @location(1) world_pos: vec4<f32>,
    @location(2) triangle_id: u32,
}

@fragment
fn fs_depth(v: SceneVertex, @builtin(primitive_index) triangle: u32) -> DepthOut {
    var o: DepthOut;
    o.color = vec4<f32>(frame.ambient.xyz, 1.0);
    o.world_pos = vec4<f32>(v.world_pos, 1.0);
    o.triangle_id = triangle;
    return o;
}

// Pass 1 without the verification attachments (frames that capture neither).
@fragment
fn fs_depth_color(v: SceneVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(frame.ambient.xyz, 1.0);
}

// Pass 3, once per light where the stencil says "lit" (stencil test EQUAL 0, depth EQUAL),
// added onto the colour (blend ONE, ONE). Lambert + Blinn-Phong, TWO-SIDED: the flat normal is
// flipped to the side the camera sees (front_facing, decided from the same clip-space
// vertices that decided coverage), so a surface whose seen side faces away from the light gets
// neither diffuse nor specular (as the shadow volumes and the reference treat it: shadowed).
// Location 1: the lit mask (R8, cleared to 0 before this light's pass, blended ONE, ONE: an
// OR): 1 where this fragment receives the light, the SAME test that gates the diffuse term.
struct LightingOut {
    @location(0) color: vec4<f32>,
    @location(1) lit: vec4<f32>,
}

fn umbra_shade(v: SceneVertex, front: bool, triangle: u32) -> LightingOut {
    var n = triangle_normals[triangle].xyz;
    if !front {
        n = -n;
    }
    let view = normalize(frame.eye.xyz - v.world_pos);
    let l = normalize(light.light.xyz - v.world_pos * light.light.w);
    let n_dot_l = dot(n, l);
    // The seen side faces the light (a zero-area triangle has n = 0 and never does).
    let faces_light = n_dot_l > 0.0;
    var color = vec3<f32>(0.0);
    if faces_light {
        let h = normalize(l + view);
        let spec = pow(max(dot(n, h), 0.0), frame.specular.y);
        color = frame.light_color.xyz * (frame.albedo.xyz * n_dot_l + vec3<f32>(frame.specular.x * spec));
    }
    var o: LightingOut;
    // Alpha 0: pass 1 wrote coverage alpha 1, the additive blend keeps it.
    o.color = vec4<f32>(color, 0.0);
    o.lit = vec4<f32>(select(0.0, 1.0, faces_light));
    return o;
}

@fragment
fn fs_lighting(v: SceneVertex, @builtin(front_facing) front: bool, @builtin(primitive_index) triangle: u32) -> LightingOut {
    return umbra_shade(v, front, triangle);
}

// Pass 3 without the lit mask (frames that do not capture it).
@fragment
fn fs_lighting_color(v: SceneVertex, @builtin(front_facing) front: bool, @builtin(primitive_index) triangle: u32) -> @location(0) vec4<f32> {
    return umbra_shade(v, front, triangle).color;
}
