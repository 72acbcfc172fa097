// Shadow-map lookup in the lighting pass (Williams 1978; omnidirectional cube shadow maps as
// the baseline of paper 003, Section 3.1, Tables 1-2; 8K maps of paper 001, Tables 6 and 8).
// Appended to the renderer's lighting fragment shader (Classification::Shader): defines
// bool umbra_lit(vec3 world_pos).
//
// Depth convention of the maps (mod.rs): REVERSED, larger = closer to the light.
//   cube (point light at L):  stored depth = n / d, d = max(|r.x|, |r.y|, |r.z|), r = p - L,
//                             the cube face's view depth (infinite far plane, near n);
//   2D (directional light):   stored depth = (h - h_min) / (h_max - h_min), h = dot(p, l),
//                             l = direction TOWARDS the light, over the scene's bounds.
// A sample is lit iff its own depth >= the stored (closest occluder's) depth: hardware
// comparison GL_COMPARE_REF_TO_TEXTURE with GL_GEQUAL, NEAREST filtering = a hard test.
// The bias (constant + slope-scaled) was applied when the map was rendered (glPolygonOffset).
// PCF (u_sm_pcf): 3 x 3 texel neighbourhood in the map, majority vote (>= 5 of 9 lit), since
// umbra_lit answers lit / shadowed, not a fraction.

layout(binding = 0) uniform samplerCubeShadow u_sm_cube;
layout(binding = 1) uniform sampler2DShadow u_sm_map2d;

// 0: cube map of a point light; 1: 2D map of a directional light.
uniform int u_sm_kind;
// Point light position (cube) and near distance n.
uniform vec3 u_sm_light_pos;
uniform float u_sm_near;
// Directional: (s, t, depth) in [0,1]^3 of the 2D map from world space.
uniform mat4 u_sm_map_from_world;
uniform bool u_sm_pcf;
// Map resolution in texels per side.
uniform float u_sm_resolution;

bool umbra_lit(vec3 world_pos) {
    if (u_sm_kind == 0) {
        vec3 r = world_pos - u_sm_light_pos;
        vec3 a = abs(r);
        float d = max(a.x, max(a.y, a.z));
        if (d <= 0.0) {
            return true;
        }
        float ref_depth = u_sm_near / d;
        if (!u_sm_pcf) {
            return texture(u_sm_cube, vec4(r, ref_depth)) > 0.5;
        }
        // Tangent axes of the face r selects; one texel spans 2 d / resolution there.
        vec3 t1, t2;
        if (a.x >= a.y && a.x >= a.z) {
            t1 = vec3(0.0, 1.0, 0.0); t2 = vec3(0.0, 0.0, 1.0);
        } else if (a.y >= a.z) {
            t1 = vec3(1.0, 0.0, 0.0); t2 = vec3(0.0, 0.0, 1.0);
        } else {
            t1 = vec3(1.0, 0.0, 0.0); t2 = vec3(0.0, 1.0, 0.0);
        }
        float texel = 2.0 * d / u_sm_resolution;
        float lit = 0.0;
        for (int i = -1; i <= 1; ++i) {
            for (int j = -1; j <= 1; ++j) {
                lit += texture(u_sm_cube, vec4(r + texel * (float(i) * t1 + float(j) * t2), ref_depth));
            }
        }
        return lit >= 4.5;
    }
    vec4 m = u_sm_map_from_world * vec4(world_pos, 1.0);
    vec3 stc = m.xyz / m.w;
    if (!u_sm_pcf) {
        return texture(u_sm_map2d, stc) > 0.5;
    }
    float texel = 1.0 / u_sm_resolution;
    float lit = 0.0;
    for (int i = -1; i <= 1; ++i) {
        for (int j = -1; j <= 1; ++j) {
            lit += texture(u_sm_map2d, vec3(stc.xy + texel * vec2(float(i), float(j)), stc.z));
        }
    }
    return lit >= 4.5;
}
