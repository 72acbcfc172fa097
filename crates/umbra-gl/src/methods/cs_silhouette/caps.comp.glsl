// cs-silhouette: shadow-volume caps oriented by a compute shader and compacted for an indirect
// draw. Paper 001, Section 2.3 (caps oriented by the same reference-edge test as the sides,
// Alg. 3-4, umbra_triangle_orientation from the shared multiplicity.glsl); paper 003 Alg. 2
// for what a cap is. Prepended: "#version 450 core", multiplicity.glsl.
//
// One invocation per triangle: an edge-on triangle (orientation 0) gets no cap (its edges'
// sides cancel as well); every other triangle writes its three vertex indices wound to face
// the light. Compaction as in sides.comp.glsl: one atomicAdd per cap on the caps draw
// command's vertex count (u_vertices_per_cap per cap).

layout(local_size_x = 256) in;

layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
// The scene's index buffer: 3 vertex indices per triangle.
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 3) coherent buffer CapsCommand {
    uint count;
    uint instance_count;
    uint first;
    uint base_instance;
} cmd;
// Per cap: 3 vertex indices, the light cap's counter-clockwise order.
layout(std430, binding = 4) writeonly buffer Caps { uint caps[]; };

// The GPU cull (gpu_cull/cull.comp.glsl), when u_cull != 0: per triangle its piece, and word
// 1 + p whether piece p is needed; a triangle of a dropped piece has no cap.
layout(std430, binding = 5) readonly buffer Pieces { uint piece[]; };
layout(std430, binding = 6) readonly buffer Needed { uint needed[]; };

uniform vec4 u_light;
uniform uint u_cull;
uniform uint u_first_triangle;
uniform uint u_triangle_count;
// 6 (light cap + dark cap) for a point light, 3 (light cap only) for a directional light.
uniform uint u_vertices_per_cap;

vec3 umbra_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

void main() {
    uint t = u_first_triangle + gl_GlobalInvocationID.x;
    if (t >= u_triangle_count || (u_cull != 0u && needed[1u + piece[t]] == 0u)) {
        return;
    }
    uvec3 tri = uvec3(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    int orientation = umbra_triangle_orientation(umbra_position(tri.x), umbra_position(tri.y), umbra_position(tri.z), u_light);
    if (orientation == 0) {
        return;
    }
    // Facing away: swap two vertices (paper 003 Alg. 2, lines 5-6; cpu-silhouette's order).
    uvec3 wound = orientation > 0 ? tri : tri.xzy;
    uint slot = 3u * (atomicAdd(cmd.count, u_vertices_per_cap) / u_vertices_per_cap);
    caps[slot] = wound.x;
    caps[slot + 1u] = wound.y;
    caps[slot + 2u] = wound.z;
}
