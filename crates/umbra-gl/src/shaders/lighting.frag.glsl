// Pass 3 of the stencil shadow-volume frame (Heidmann 1991; Everitt & Kilgard 2002 §2), run
// once per light where the method's stencil classification says "lit" (stencil == 0 for the
// counting methods, or the method's stencil test), added onto the colour buffer (blend ONE,
// ONE) with depth func EQUAL. A shader classification (umbra_lit, the shadow maps) multiplies
// the light's term by its 0/1 instead (UMBRA_CUSTOM_LIT); with UMBRA_DISCARD_UNLIT (the resolve
// into the stencil for count_shadows) it discards where umbra_lit is false.
// Shading: Lambert diffuse + Blinn-Phong specular, TWO-SIDED: the flat triangle normal is
// flipped to the side the camera sees, so a surface whose seen side faces away from the light
// gets neither diffuse nor specular (matches the shadow volumes and the reference, which treat
// that side as shadowed).
// Light in homogeneous coordinates: L = normalize(light.xyz - p * light.w) covers point
// (w = 1) and directional (w = 0, light comes FROM light.xyz) lights alike.
//
// Lit mask (location 3, an R8 attachment cleared to 0 before this light's pass, present only
// when captured): 1 where this fragment receives the light, i.e. the classification passed
// (the stencil test, else the fragment never gets here; or umbra_lit) AND the seen side faces
// the light — the SAME test that gates the diffuse term below, so the mask and the image agree
// by construction.
#version 450 core

in vec3 v_world_pos;

// One unit normal per triangle, indexed by gl_PrimitiveID (= index into WeldedMesh::triangles).
layout(std430, binding = 0) readonly buffer TriangleNormals {
    vec4 triangle_normals[];
};

uniform vec4 u_light;
uniform vec3 u_light_color;
// The eye (w = 1), or the direction towards it (w = 0) in an orthographic view: the eye at
// infinity behind the camera, every view vector the same.
uniform vec4 u_eye;
uniform vec3 u_albedo;
uniform float u_specular;
uniform float u_shininess;

layout(location = 0) out vec4 o_color;
layout(location = 3) out vec4 o_lit;

#ifdef UMBRA_CUSTOM_LIT
// Provided by the shadow method (Classification::Shader), appended after this file.
bool umbra_lit(vec3 world_pos);
#endif

void main() {
#ifdef UMBRA_CUSTOM_LIT
    bool classified_lit = umbra_lit(v_world_pos);
#ifdef UMBRA_DISCARD_UNLIT
    // The resolve into the stencil (count_shadows): only lit fragments may write stencil 0.
    if (!classified_lit) {
        discard;
    }
#endif
#else
    // Stencil classifications: the stencil test already rejected the unlit fragments.
    const bool classified_lit = true;
#endif
    // Two-sided: the normal of the side the camera sees. The stored normal is that of the
    // counter-clockwise winding (glFrontFace(CCW)), so gl_FrontFacing says exactly which side
    // the rasterizer saw — decided from the same clip-space vertices that decided coverage,
    // not from an interpolated view vector that can disagree on near-edge-on triangles.
    vec3 n = triangle_normals[gl_PrimitiveID].xyz;
    if (!gl_FrontFacing) {
        n = -n;
    }
    vec3 v = normalize(u_eye.xyz - v_world_pos * u_eye.w);
    vec3 l = normalize(u_light.xyz - v_world_pos * u_light.w);
    float n_dot_l = dot(n, l);
    // The seen side faces the light (a zero-area triangle has n = 0 and never does), and the
    // method's shader classification (if any) says lit. For Classification::Shader the light's
    // term is multiplied by this 0/1 rather than discarded: a shader that may discard forces
    // late depth and stencil tests, and the shadow-map lookup then runs for every fragment of
    // the overdraw instead of the visible one (measured on llvmpipe: 4x `none`'s lighting).
    bool receives_light = n_dot_l > 0.0 && classified_lit;
    vec3 color = vec3(0.0);
    if (receives_light) {
        vec3 h = normalize(l + v);
        float spec = pow(max(dot(n, h), 0.0), u_shininess);
        color = u_light_color * (u_albedo * n_dot_l + vec3(u_specular * spec));
    }
    // Alpha 0: pass 1 wrote coverage alpha 1, the additive blend keeps it.
    o_color = vec4(color, 0.0);
    o_lit = vec4(receives_light ? 1.0 : 0.0);
}
