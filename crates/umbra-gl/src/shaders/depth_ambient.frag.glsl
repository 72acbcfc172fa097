// Pass 1 of the stencil shadow-volume frame (Heidmann 1991; Everitt & Kilgard 2002 §2):
// lay down depth and the ambient term, and the verification attachments.
//   location 0: ambient colour = albedo * ambient (RGBA8);
//   location 1: world position (RGBA32F, w = 1 marks geometry) for the ray-traced oracle;
//   location 2: triangle id = gl_PrimitiveID = index into WeldedMesh::triangles (R32UI),
//               valid because the scene is one glDrawElements over all triangles in order.
// Locations without a draw buffer are discarded by GL.
#version 450 core

in vec3 v_world_pos;

uniform vec3 u_ambient_color;

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_world_pos;
layout(location = 2) out uint o_triangle_id;

void main() {
    o_color = vec4(u_ambient_color, 1.0);
    o_world_pos = vec4(v_world_pos, 1.0);
    o_triangle_id = uint(gl_PrimitiveID);
}
