// The orientation pass of umbra-three's GPU silhouettes (`silhouettes: 'gpu'`): every
// triangle of a caster oriented towards the light once per light position, captured by
// transform feedback (one point in, one int out) and copied into the light slot's R32I
// orientation texture, which the polygon pass then reads as it reads the wasm's (paper 001
// Alg. 4 through the triangle's reference edge, umbra_triangle_orientation of the native
// shared/multiplicity.glsl; +1 faces the light, -1 away, 0 edge-on). Computed once and read
// by every side and cap, a value cannot disagree with itself whatever a compiler contracts
// (GLSL ES 3.00 has no `precise`): the volumes close. No #version line: spliced after the
// ES 3.00 prelude, multiplicity.glsl and elements.glsl.

uniform vec4 u_light;
uniform highp sampler2D u_vertices;
uniform highp isampler2D u_triangle_vertices;

flat out int v_orientation;

vec3 umbra_vertex(int v) {
    return texelFetch(u_vertices, umbra_texel(v), 0).xyz;
}

void main() {
    // Transform feedback only: nothing of this pass is rasterised.
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    int t = gl_VertexID;
    vec3 p0 = umbra_vertex(texelFetch(u_triangle_vertices, umbra_texel(3 * t), 0).r);
    vec3 p1 = umbra_vertex(texelFetch(u_triangle_vertices, umbra_texel(3 * t + 1), 0).r);
    vec3 p2 = umbra_vertex(texelFetch(u_triangle_vertices, umbra_texel(3 * t + 2), 0).r);
    v_orientation = umbra_triangle_orientation(p0, p1, p2, u_light);
}
