// cs-silhouette: silhouette edges found by a compute shader and compacted for an indirect draw.
// Paper 001 (Milet, Kobrtek, Zemcik), Section 2.2 and its future work (a compute-shader
// silhouette): every edge's multiplicity by Alg. 3 with the reference edge of Alg. 4 (the
// shared multiplicity.glsl, umbra_opposite_contribution), sides extruded with Eq. 2 by the
// vertex shader that draws the result (sides.vert.glsl). Any multiplicity: an edge with
// multiplicity m writes |m| quad records (no 3-bit packing as in the authors' version).
//
// One invocation per edge record: an edge with more than MAX_OPPOSITES_PER_RECORD (mod.rs)
// opposites is split into records over consecutive ranges of its opposites, because llvmpipe
// ends every shader loop after 65,535 iterations (Mesa gallivm LP_MAX_TGSI_LOOP_ITERATIONS):
// a 100,000-page spine looped here in one invocation counted 65,535 pages. A record emits the
// quads of its partial multiplicity with its own sign; the stencil counts of an edge's records
// add up to its multiplicity (opposite-signed quads of one edge cancel).
// Compaction: a record with m != 0 (a small fraction of all edges)
// reserves its |m| slots with one atomicAdd on the indirect draw command's vertex count (the
// atomic counter, 6 vertices per quad) and writes its quads there. No shared memory and no
// barrier(): a workgroup-level reservation (shared-memory sum, one atomic per workgroup,
// three barriers) measured slower on llvmpipe, whose compute shaders run barrier() by
// switching coroutines, and silhouette edges are few. The output order is whatever the
// atomics give; the stencil counts (INCR_WRAP / DECR_WRAP) are order-independent, so the image
// is deterministic anyway.
// Prepended by the Rust side: "#version 450 core", multiplicity.glsl.

layout(local_size_x = 256) in;

// Welded positions, tightly packed vec3 (the scene's vertex buffer): 3 floats per vertex.
layout(std430, binding = 1) readonly buffer Positions { float positions[]; };
// Per edge record: (A, B, first opposite, opposite count <= MAX_OPPOSITES_PER_RECORD),
// A < B in umbra_greater order.
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

// The GPU cull (gpu_cull/cull.comp.glsl), when u_cull != 0: per edge record its piece, and
// word 1 + p whether piece p is needed. An edge's triangles are all in one piece, so an edge
// of a dropped piece loses all of them (m = 0) and every other edge none.
layout(std430, binding = 6) readonly buffer RecordPieces { uint record_piece[]; };
layout(std430, binding = 7) readonly buffer Needed { uint needed[]; };

uniform vec4 u_light;
uniform uint u_cull;
uniform uint u_first_edge;  // several dispatches when the edges exceed one dispatch's groups
uniform uint u_edge_count;  // edge records

vec3 umbra_position(uint i) {
    return vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

void main() {
    uint e = u_first_edge + gl_GlobalInvocationID.x;
    if (e >= u_edge_count) {
        return;
    }
    if (u_cull != 0u && needed[1u + record_piece[e]] == 0u) {
        return;
    }
    uvec4 edge = edges[e];
    vec3 a = umbra_position(edge.x);
    vec3 b = umbra_position(edge.y);
    int m = 0;
    for (uint k = 0u; k < edge.w; ++k) {
        m += umbra_opposite_contribution(a, b, umbra_position(opposites[edge.z + k]), u_light);
    }
    if (m == 0) {
        return;
    }
    uint n = uint(abs(m));
    uint first = atomicAdd(cmd.count, 6u * n) / 6u;
    uvec2 q = m > 0 ? edge.xy : edge.yx;
    for (uint k = 0u; k < n; ++k) {
        quads[first + k] = q;
    }
}
