// cs-silhouette: silhouette edges found by a compute shader and compacted for an indirect draw.
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.2 and its future work (a compute-shader
// silhouette): every edge's multiplicity by Alg. 3 with the reference edge of Alg. 4 (the
// shared multiplicity.glsl, umbra_opposite_contribution), sides extruded with Eq. 2 by the
// vertex shader that draws the result (sides.vert.glsl). Any multiplicity: an edge with
// multiplicity m writes |m| quad records (no 3-bit packing as in the authors' version).
//
// One invocation per edge. Compaction: the workgroup sums its quads in shared memory, one
// invocation reserves that many slots with ONE atomicAdd on the indirect draw command's vertex
// count (6 vertices per quad), and every invocation writes its quads at its offset. The
// output order across workgroups is whatever the atomics give; the stencil counts
// (INCR_WRAP / DECR_WRAP) are order-independent, so the image is deterministic anyway.
// Prepended by the Rust side: "#version 450 core", multiplicity.glsl.

layout(local_size_x = 256) in;

// Welded positions, tightly packed vec3 (the scene's vertex buffer): 3 floats per vertex.
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
// Per edge: (A, B, first opposite, opposite count), A < B in umbra_greater order.
layout(std430, binding = 2) readonly buffer Edges { uvec4 edges[]; };
layout(std430, binding = 3) readonly buffer Opposites { uint opposites[]; };
// DrawArraysIndirectCommand of the sides draw; `count` (vertices) is the atomic counter.
layout(std430, binding = 4) coherent buffer SidesCommand {
    uint count;
    uint instance_count;
    uint first;
    uint base_instance;
} cmd;
// One record per side quad: (X, Y) vertex indices, the quad is Y X X_inf Y_inf
// (m > 0: X = A, Y = B; m < 0: X = B, Y = A: the project's side convention).
layout(std430, binding = 5) writeonly buffer Quads { uvec2 quads[]; };

uniform vec4 u_light;
uniform uint u_first_edge;  // several dispatches when the edges exceed one dispatch's groups
uniform uint u_edge_count;

shared uint s_quads;  // quads of this workgroup
shared uint s_base;   // first quad slot of this workgroup

vec3 umbra_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

void main() {
    uint e = u_first_edge + gl_GlobalInvocationID.x;
    if (gl_LocalInvocationIndex == 0u) {
        s_quads = 0u;
    }
    memoryBarrierShared();
    barrier();

    int m = 0;
    uvec4 edge = uvec4(0u);
    if (e < u_edge_count) {
        edge = edges[e];
        vec3 a = umbra_position(edge.x);
        vec3 b = umbra_position(edge.y);
        for (uint k = 0u; k < edge.w; ++k) {
            m += umbra_opposite_contribution(a, b, umbra_position(opposites[edge.z + k]), u_light);
        }
    }
    uint n = uint(abs(m));
    uint local_offset = 0u;
    if (n > 0u) {
        local_offset = atomicAdd(s_quads, n);
    }
    memoryBarrierShared();
    barrier();
    if (gl_LocalInvocationIndex == 0u && s_quads > 0u) {
        s_base = atomicAdd(cmd.count, 6u * s_quads) / 6u;
    }
    memoryBarrierShared();
    barrier();
    if (n > 0u) {
        uvec2 q = m > 0 ? edge.xy : edge.yx;
        for (uint k = 0u; k < n; ++k) {
            quads[s_base + local_offset + k] = q;
        }
    }
}
