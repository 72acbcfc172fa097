// ray-bvh, per frame: the view samples the shadow rays start from. Drawn with the scene's own
// vertex shader (shaders/scene.vert.glsl, invariant gl_Position: bit-identical depths) over the
// frame's depth with depth func EQUAL and every write masked, so exactly the visible surface of
// each pixel reaches this shader; early_fragment_tests makes the depth test run BEFORE it,
// which is required because a shader's buffer writes happen whether or not a later test fails.
// It stores the interpolated world position (the sample the ray-traced reference classifies)
// and the triangle id (gl_PrimitiveID = index into WeldedMesh::triangles: the scene is one draw
// in order). Coplanar duplicates at the same depth may both pass EQUAL; either one's id is
// right (the other lies within eps of the sample, which the ray's eps at its start skips).

#version 450 core

layout(early_fragment_tests) in;

in vec3 v_world_pos;

layout(std430, binding = 3) writeonly buffer Samples { uvec4 samples[]; };

uniform uint u_width;

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    samples[p.y * u_width + p.x] = uvec4(floatBitsToUint(v_world_pos), uint(gl_PrimitiveID));
}
