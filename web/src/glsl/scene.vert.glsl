#version 300 es
// Scene vertex shader of the WebGL viewer, shared VERBATIM by pass 1 (depth + ambient) and
// pass 3 (lighting): the ES 3.00 port of crates/umbra-gl/src/shaders/scene.vert.glsl
// (Heidmann 1991; Everitt & Kilgard 2002). `invariant gl_Position` and the same expression as
// the w = 1 vertices of vs-silhouette's sides give bit-identical positions, so the lighting
// pass's depth func EQUAL selects exactly the visible surface and the sides meet the caster.
// The flat triangle normal comes as a per-vertex attribute (the viewer de-indexes the mesh,
// three vertices per triangle): ES 3.00 has neither gl_PrimitiveID nor storage buffers.
// umbra_snap (snap.glsl, spliced in after #version by renderer.js): the snap=N diagnostic.
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
