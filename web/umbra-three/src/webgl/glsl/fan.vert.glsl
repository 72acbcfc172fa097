// umbra-three's shadow volumes, drawn: every polygon of the polygon pass
// (polygons.vert.glsl; u_polygons, 9 RGBA32F texels each: its vertices v0 .. v7, then
// (vertex count, signed repeat)) as a fan of triangles, |repeat| times (a side of
// multiplicity m is m coincident quads, paper 003 Alg. 1), into the stencil under the
// renderer's counting state. The vertices are read as the polygon pass wrote them: nothing
// is computed here, so each polygon is drawn exactly as clipped.
//
// Instance i covers polygons u_first + i * u_per_instance ..< u_count; each has u_repeat (the
// largest |repeat| of the range: 1 for caps and for the sides of multiplicity +-1, which the
// wasm lists first, maxMult for the other sides) potential copies of UMBRA_FAN vertices.
// Unused vertices go to UMBRA_CULLED, outside the viewport, so their whole triangle is
// discarded.

uniform int u_first;
uniform int u_count;
uniform int u_per_instance;
uniform int u_repeat;
uniform highp sampler2D u_polygons;

const int UMBRA_FAN = 3 * (UMBRA_CLIP_MAX - 2);

// The (smallest, largest) window depth of this fan triangle's three corners, for fan.frag.glsl,
// which keeps every fragment's depth in that range. Widened by 2^-20 of each end, so that the
// rasteriser's own rounding of a corner's depth (viewport transform) is never clamped.
flat out vec2 v_depth_range;

#ifdef UMBRA_CULLED_FACES
// The true-depth light caps of the faces a depth pass culls (polygons.vert.glsl u_mode 3): the
// sign of the polygon's repeat, its triangle's orientation towards the light, for fan.frag.glsl.
flat out float v_orientation;
#endif

float umbra_window_depth(vec4 clip) {
    float z = clip.z / clip.w;
    // u_far_clip_z (shared/depth.glsl): 0 with reversed-Z (clip control ZERO_TO_ONE, depth
    // z/w), 1 standard (depth (z/w + 1) / 2); the depth range is [0, 1] in both.
    return u_far_clip_z == 0.0 ? z : 0.5 * z + 0.5;
}

void main() {
    int per_polygon = u_repeat * UMBRA_FAN;
    int local = gl_VertexID / per_polygon;
    int polygon = u_first + gl_InstanceID * u_per_instance + local;
    int within = gl_VertexID - per_polygon * local;
    int copy = within / UMBRA_FAN;
    int k = within - UMBRA_FAN * copy;
    int f = k / 3;
    int corner = k - 3 * f;
    gl_Position = UMBRA_CULLED;
    v_depth_range = vec2(0.0);
#ifdef UMBRA_CULLED_FACES
    v_orientation = 0.0;
#endif
    if (polygon >= u_count) {
        return;
    }
    vec4 info = texelFetch(u_polygons, umbra_texel(9 * polygon + 8), 0);
    int n = int(info.x);
    int repeat = abs(int(info.y));
#ifdef UMBRA_CULLED_FACES
    v_orientation = info.y;
#endif
    if (copy >= repeat || f + 2 >= n) {
        return; // Alg. 1, line 7: useless copy; or past the polygon's fan
    }
    // The triangle's corners 0, f + 1, f + 2 (the polygon's fan), all read by each of them.
    vec4 c0 = texelFetch(u_polygons, umbra_texel(9 * polygon), 0);
    vec4 c1 = texelFetch(u_polygons, umbra_texel(9 * polygon + f + 1), 0);
    vec4 c2 = texelFetch(u_polygons, umbra_texel(9 * polygon + f + 2), 0);
    float z0 = umbra_window_depth(c0);
    float z1 = umbra_window_depth(c1);
    float z2 = umbra_window_depth(c2);
    float lo = min(z0, min(z1, z2));
    float hi = max(z0, max(z1, z2));
    v_depth_range = vec2(lo - abs(lo) * (1.0 / 1048576.0), hi + abs(hi) * (1.0 / 1048576.0));
    // umbra_snap (snap.glsl): the snap=N diagnostic; unchanged by default.
    gl_Position = umbra_snap(corner == 0 ? c0 : (corner == 1 ? c1 : c2));
}
