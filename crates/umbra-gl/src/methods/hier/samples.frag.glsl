// The view-sample hierarchy, per frame: the view samples. Drawn with the scene's own vertex shader
// (shaders/scene.vert.glsl, invariant gl_Position: bit-identical depths) over the frame's depth
// with depth func EQUAL and every write masked, so exactly the visible surface of each pixel
// reaches this shader — early_fragment_tests makes the depth test run BEFORE it, which is
// required because a shader's buffer writes happen whether or not a later test fails. It stores
// the interpolated world position (the sample the ray-traced reference classifies) and the
// triangle id (gl_PrimitiveID = index into WeldedMesh::triangles: the scene is one draw in
// order). Coplanar duplicates at the same depth may both pass EQUAL; either one's id is right
// (the other lies within eps of the sample, which the per-sample test ignores). It also sets the
// sample's bit in its leaf's mask of samples seen from their triangle's front (gl_FrontFacing,
// the rasterizer's own decision, the one the lighting pass's two-sided normal follows):
// hier-triangle drops the samples whose seen side faces away from the light.

#version 450 core

layout(early_fragment_tests) in;

in vec3 v_world_pos;

layout(std430, binding = 3) writeonly buffer Samples { uvec4 samples[]; };
layout(std430, binding = 5) buffer State { uint state[]; };

uniform uint u_width;
// Leaves per row of the hierarchy, and where the front masks begin in the state buffer
// (hier/layout.rs front_offset; cleared before this pass).
uniform uint u_leaves_x;
uniform uint u_front_offset;

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    samples[p.y * u_width + p.x] = uvec4(floatBitsToUint(v_world_pos), uint(gl_PrimitiveID));
    if (gl_FrontFacing) {
        uvec2 leaf = p / LEAF_SIDE;
        uvec2 k = p % LEAF_SIDE;
        atomicOr(state[u_front_offset + leaf.y * u_leaves_x + leaf.x], 1u << (k.y * LEAF_SIDE + k.x));
    }
}
