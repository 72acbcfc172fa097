// The receiver map of one light (umbra_geom::receivers): every visible sample that may receive
// the light raises its light-space cell to its distance from the light (point) or its depth
// along the light (directional), rounded up, with the very f32 expressions of
// ReceiverGrid::sample_cell. CC shadow volumes (Lloyd et al., EGSR 2004) cull and clamp volumes
// against such a map; cpu-silhouette reads it back to do so exactly.
//
// Drawn with the scene's own vertex shader (shaders/scene.vert.glsl, invariant gl_Position)
// over the frame's depth with depth func EQUAL and every write masked (GlState::visible_samples),
// so exactly the visible surface of each pixel reaches this shader; early_fragment_tests runs
// that test BEFORE the shader, as the atomic write happens whether or not a later test fails.
// Coplanar duplicates at the same depth may both pass EQUAL: both raise their cells, which only
// keeps more.
//
// A sample whose seen side clearly faces away from the light is left out: the lighting pass
// (shaders/lighting.frag.glsl) never lights it, whatever its count, so no volume needs to reach
// it. "Clearly": its cosine with the light is below -2^-10, far beyond the rounding by which
// two programs may compute the lighting pass's `n_dot_l > 0` differently; samples nearer to
// edge-on stay in the map.

// Prepended by receivers/mod.rs: "#version 450 core" and shared/receiver_cell.glsl
// (receiver_encode, receiver_cell, receiver_cube_cell).

layout(early_fragment_tests) in;

in vec3 v_world_pos;

// One unit normal per triangle, indexed by gl_PrimitiveID (the scene's normal buffer, as the
// lighting pass reads it).
layout(std430, binding = 0) readonly buffer TriangleNormals { vec4 triangle_normals[]; };
layout(std430, binding = UMBRA_RECEIVERS_BINDING) coherent buffer Receivers { uint receivers[]; };

uniform vec4 u_light;
// ReceiverGrid::Cube: u_side. ReceiverGrid::Flat: u_origin, u_u, u_v, u_travel, u_lo, u_scale.
uniform uint u_side;
uniform vec3 u_origin;
uniform vec3 u_u;
uniform vec3 u_v;
uniform vec3 u_travel;
uniform vec2 u_lo;
uniform vec2 u_scale;

const float ROUND_UP = 1.0 / 1048576.0;


void main() {
    vec3 n = triangle_normals[gl_PrimitiveID].xyz;
    if (!gl_FrontFacing) {
        n = -n;
    }
    vec3 l = normalize(u_light.xyz - v_world_pos * u_light.w);
    if (dot(n, l) < -1.0 / 1024.0) {
        return;
    }
    uint cell;
    float value;
    if (u_light.w != 0.0) {
        vec3 rel = v_world_pos - u_light.xyz;
        vec3 a = abs(rel);
        // A sample at the light is lit: no cell.
        if (!(a.x + a.y + a.z > 0.0)) {
            return;
        }
        cell = receiver_cube_cell(rel, u_side);
        value = length(rel) * (1.0 + ROUND_UP);
    } else {
        vec3 rel = v_world_pos - u_origin;
        uint ci = receiver_cell(dot(rel, u_u), u_lo.x, u_scale.x, u_side);
        uint cj = receiver_cell(dot(rel, u_v), u_lo.y, u_scale.y, u_side);
        cell = cj * u_side + ci;
        vec3 a = abs(rel);
        value = dot(rel, u_travel) + (a.x + a.y + a.z) * ROUND_UP;
    }
    atomicMax(receivers[cell], receiver_encode(value));
}
