// Pass 3 of the stencil shadow-volume frame (Heidmann 1991; Everitt & Kilgard 2002 §2), run
// once per light where the stencil test says "lit" (stencil == 0 for the counting methods),
// added onto the colour buffer (blend ONE, ONE) with depth func EQUAL.
// Shading: Lambert diffuse + Blinn-Phong specular, TWO-SIDED: the flat triangle normal is
// flipped to face the camera, so a surface whose visible side faces away from the light gets
// neither diffuse nor specular (matches the shadow volumes, which treat that side as shadowed).
// Light in homogeneous coordinates: L = normalize(light.xyz - p * light.w) covers point
// (w = 1) and directional (w = 0, light comes FROM light.xyz) lights alike.
#version 450 core

in vec3 v_world_pos;

// One unit normal per triangle, indexed by gl_PrimitiveID (= index into WeldedMesh::triangles).
layout(std430, binding = 0) readonly buffer TriangleNormals {
    vec4 triangle_normals[];
};

uniform vec4 u_light;
uniform vec3 u_light_color;
uniform vec3 u_eye;
uniform vec3 u_albedo;
uniform float u_specular;
uniform float u_shininess;

layout(location = 0) out vec4 o_color;

#ifdef UMBRA_CUSTOM_LIT
// Provided by the shadow method (Classification::Shader), appended after this file.
bool umbra_lit(vec3 world_pos);
#endif

void main() {
#ifdef UMBRA_CUSTOM_LIT
    if (!umbra_lit(v_world_pos)) {
        discard;
    }
#endif
    vec3 n = triangle_normals[gl_PrimitiveID].xyz;
    vec3 v = normalize(u_eye - v_world_pos);
    // Two-sided: the normal of the side the camera sees.
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    vec3 l = normalize(u_light.xyz - v_world_pos * u_light.w);
    float n_dot_l = dot(n, l);
    vec3 color = vec3(0.0);
    if (n_dot_l > 0.0) {
        vec3 h = normalize(l + v);
        float spec = pow(max(dot(n, h), 0.0), u_shininess);
        color = u_light_color * (u_albedo * n_dot_l + vec3(u_specular * spec));
    }
    // Alpha 0: pass 1 wrote coverage alpha 1, the additive blend keeps it.
    o_color = vec4(color, 0.0);
}
