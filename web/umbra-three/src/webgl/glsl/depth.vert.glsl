#version 300 es
// The vertex shader of umbra's depth pass and mask pass (drawer.js), shared VERBATIM by the
// two: the ES 3.00 port of crates/umbra-gl/src/shaders/scene.vert.glsl (Heidmann 1991;
// Everitt & Kilgard 2002). A mesh is drawn in its own (object) space with its clip-from-object
// matrix, the matrix its shadow volumes are drawn with: `invariant gl_Position` and the same
// expression as the w = 1 vertices of the polygon pass (polygons.vert.glsl) give bit-identical
// positions, so the mask pass's depth func EQUAL selects exactly the visible surface and the
// sides meet the caster. The flat triangle normal (topology.js flatTriangles, f64 as the
// native flat_normal) comes as a per-vertex attribute of the de-indexed mesh: ES 3.00 has
// neither gl_PrimitiveID nor storage buffers. umbra_snap (snap.glsl, spliced in after
// #version by drawer.js): the snap=N diagnostic.
precision highp float;

layout(location = 0) in vec3 a_world_pos;
layout(location = 1) in vec3 a_normal;

uniform mat4 u_clip_from_world;

out vec3 v_world_pos;
flat out vec3 v_normal;

invariant gl_Position;

void main() {
    v_world_pos = a_world_pos;
    v_normal = a_normal;
    gl_Position = umbra_snap(u_clip_from_world * vec4(a_world_pos, 1.0));
}
