#version 300 es
// The vertex shader of umbra's depth pass and mask pass (drawer.js), shared VERBATIM by the
// two: the ES 3.00 port of crates/umbra-gl/src/shaders/scene.vert.glsl (Heidmann 1991;
// Everitt & Kilgard 2002). A mesh is drawn in its own (object) space with its clip-from-object
// matrix, the matrix its shadow volumes are drawn with: `invariant gl_Position` and the same
// expression as the w = 1 vertices of the polygon pass (polygons.vert.glsl) give bit-identical
// positions, so the mask pass's depth func EQUAL selects exactly the visible surface and the
// sides meet the caster. The flat triangle normal (topology.js flatTriangles, f64 as the
// native flat_normal) is read from the mesh's RGB32F texture of one texel per triangle, the
// triangle gl_VertexID / 3 of the de-indexed mesh (drawArrays: gl_VertexID counts from the
// draw's first vertex): ES 3.00 has neither gl_PrimitiveID nor storage buffers, and a texel per
// triangle is a third of a normal per vertex. umbra_snap (snap.glsl) and umbra_texel
// (elements.glsl), spliced in after #version by drawer.js: the snap=N diagnostic, a texel's
// place.
precision highp float;

layout(location = 0) in vec3 a_world_pos;

uniform mat4 u_clip_from_world;
uniform highp sampler2D u_normals;

out vec3 v_world_pos;
flat out vec3 v_normal;

invariant gl_Position;

void main() {
    v_world_pos = a_world_pos;
    v_normal = texelFetch(u_normals, umbra_texel(gl_VertexID / 3), 0).xyz;
    gl_Position = umbra_snap(u_clip_from_world * vec4(a_world_pos, 1.0));
}
