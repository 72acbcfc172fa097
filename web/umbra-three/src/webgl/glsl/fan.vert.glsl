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
    if (polygon >= u_count) {
        return;
    }
    vec4 info = texelFetch(u_polygons, umbra_texel(9 * polygon + 8), 0);
    int n = int(info.x);
    int repeat = abs(int(info.y));
    if (copy >= repeat || f + 2 >= n) {
        return; // Alg. 1, line 7: useless copy; or past the polygon's fan
    }
    // umbra_snap (snap.glsl): the snap=N diagnostic; unchanged by default.
    gl_Position = umbra_snap(texelFetch(u_polygons, umbra_texel(9 * polygon + (corner == 0 ? 0 : f + corner)), 0));
}
