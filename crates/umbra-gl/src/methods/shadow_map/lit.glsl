// Shadow-map lookup in the lighting pass (Williams 1978; omnidirectional cube shadow maps as
// the baseline of paper 003, Section 3.1, Tables 1-2; 8K maps of paper 001, Tables 6 and 8).
// Appended to the renderer's lighting fragment shader (Classification::Shader): defines
// bool umbra_lit(vec3 world_pos). UMBRA_SM_PCF (defined by mod.rs for the "+pcf" variant)
// selects 3 x 3 percentage-closer filtering.
//
// Both kinds of map live in ONE sampler type, a 2D array depth texture with hardware
// comparison: the "cube" is 6 layers in GL's face order +X -X +Y -Y +Z -Z, and the face and
// (s, t) of a direction are computed here with GL 4.5 Table 8.19's rules (the same ones the
// face matrices in mod.rs render with). So every pixel does exactly one texture lookup (nine
// with PCF): llvmpipe executes both sides of a branch under a mask, so a samplerCubeShadow plus
// a sampler2DShadow chosen by a uniform branch would pay for both lookups.
//
// Depth convention of the maps (mod.rs): REVERSED, larger = closer to the light.
//   point light at L:        stored depth = n / d, d = max(|r.x|, |r.y|, |r.z|), r = p - L
//                            (the face's view depth; infinite far plane, near n);
//   directional light:       stored depth = (h - h_min) / (h_max - h_min), h = dot(p, l),
//                            l = direction TOWARDS the light, over the scene's bounds.
// A sample is lit iff its own depth >= the stored (closest occluder's) depth: comparison
// GL_COMPARE_REF_TO_TEXTURE with GL_GEQUAL, NEAREST filtering = a hard test. The bias
// (constant + slope-scaled) was applied when the map was rendered (glPolygonOffset). PCF:
// 3 x 3 texels of the same face/map (clamped at its edges), majority vote (>= 5 of 9 lit),
// since umbra_lit answers lit / shadowed, not a fraction.

layout(binding = 0) uniform sampler2DArrayShadow u_sm_map;

// 0: point light (6 layers); 1: directional light (1 layer).
uniform int u_sm_kind;
// Point light position and near distance n.
uniform vec3 u_sm_light_pos;
uniform float u_sm_near;
// Directional: (s, t, depth) in [0,1]^3 of the map from world space.
uniform mat4 u_sm_map_from_world;
// Map resolution in texels per side.
uniform float u_sm_resolution;

// (s, t, layer, reference depth) of a world position.
vec4 umbra_sm_coords(vec3 world_pos) {
    vec3 r = world_pos - u_sm_light_pos;
    vec3 a = abs(r);
    float ma;
    float layer;
    vec2 sc_tc;
    if (a.x >= a.y && a.x >= a.z) {
        ma = a.x;
        layer = r.x >= 0.0 ? 0.0 : 1.0;
        sc_tc = r.x >= 0.0 ? vec2(-r.z, -r.y) : vec2(r.z, -r.y);
    } else if (a.y >= a.z) {
        ma = a.y;
        layer = r.y >= 0.0 ? 2.0 : 3.0;
        sc_tc = r.y >= 0.0 ? vec2(r.x, r.z) : vec2(r.x, -r.z);
    } else {
        ma = a.z;
        layer = r.z >= 0.0 ? 4.0 : 5.0;
        sc_tc = r.z >= 0.0 ? vec2(r.x, -r.y) : vec2(-r.x, -r.y);
    }
    // At the light itself (ma = 0): depth +inf, always lit.
    vec4 cube = vec4(0.5 * sc_tc / ma + 0.5, layer, u_sm_near / ma);
    vec4 m = u_sm_map_from_world * vec4(world_pos, 1.0);
    vec4 dir = vec4(m.xy / m.w, 0.0, m.z / m.w);
    return u_sm_kind == 0 ? cube : dir;
}

bool umbra_lit(vec3 world_pos) {
    vec4 c = umbra_sm_coords(world_pos);
#ifdef UMBRA_SM_PCF
    float texel = 1.0 / u_sm_resolution;
    float lit = 0.0;
    for (int i = -1; i <= 1; ++i) {
        for (int j = -1; j <= 1; ++j) {
            vec2 st = clamp(c.xy + texel * vec2(float(i), float(j)), vec2(0.0), vec2(1.0));
            lit += texture(u_sm_map, vec4(st, c.z, c.w));
        }
    }
    return lit >= 4.5;
#else
    return texture(u_sm_map, c) > 0.5;
#endif
}
