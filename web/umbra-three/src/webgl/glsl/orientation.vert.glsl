// The orientation pass of umbra-three: every triangle's orientation
// towards the light, computed ONCE per frame into one texel of an R8I texture, the value the
// caps (volume.vert.glsl) and, through the multiplicity pass, the sides then read. Paper 001,
// Alg. 3-4: umbra_triangle_orientation (shared multiplicity.glsl), the reference-edge test the
// native methods run in every stage.
//
// One point per triangle (drawArrays POINTS, vertex i = triangle i), its three vertices from
// caps-data (paper 003 Eq. 9, 3 vec4 per triangle) as attributes; point i lands on the centre
// of texel i (UMBRA_POINT_AT, elements.glsl), size 1: exactly that texel.

layout(location = 0) in vec4 a_p0;
layout(location = 1) in vec4 a_p1;
layout(location = 2) in vec4 a_p2;

uniform vec4 u_light;

flat out int v_value;

void main() {
    v_value = umbra_triangle_orientation(a_p0.xyz, a_p1.xyz, a_p2.xyz, u_light);
    gl_Position = umbra_point_at(gl_VertexID);
    gl_PointSize = 1.0;
}
