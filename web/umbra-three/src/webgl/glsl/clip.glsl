// Homogeneous polygon clipping (Sutherland & Hodgman 1974, "Reentrant polygon clipping", in
// clip space as Blinn & Newell 1978, "Clipping using homogeneous coordinates"), done in the
// vertex shader for umbra-three's shadow volumes (polygons.vert.glsl). No #version line:
// spliced after the ES 3.00 prelude and shared/depth.glsl (umbra_near_distance).
//
// Why umbra-three clips, and to just inside the viewport: SwiftShader (Chromium's WebGL 2
// without a GPU) sets a triangle it has to clip up from vertex positions it recomputes after
// clipping, and an unclipped triangle from the positions its vertex stage projected; at its
// 1/16-pixel vertex snapping a vertex shared by the two kinds can land on two different
// positions, and a shadow volume with such a seam counts wrong along it (docs/web.md: Sibenik
// at 640 x 360, 165 samples outside the band with a guard band twice the viewport, which
// SwiftShader clips again; 18, its snapping alone, when nothing reaches its clipper). The
// shader-clipped polygons lie inside |x|, |y| <= (1 - UMBRA_GUARD_MARGIN) w, so no
// rasteriser ever clips them, and every vertex is projected one way.
//
// Watertight by construction: a vertex's distance to a plane is computed by one expression
// whose every product is exact (w * 2^-15, and umbra_near_distance's +-1 * z), so no compiler
// contraction can change it; an edge crossing a plane is cut by umbra_clip_edge from its
// INSIDE end whichever polygon it belongs to and whichever way that polygon walks it, so two
// volume polygons sharing an edge get the same cut vertex (one program computes them all;
// the residual assumption is that a compiler contracts that one expression the same way
// wherever it inlines it). Everything that reaches a visible sample survives: every pixel
// centre lies inside the planes (|NDC| <= 1 - 1/8192 for any viewport WebGL allows), and only
// light caps are cut by the near plane (native umbra's gl_ClipDistance[0],
// methods/shared/depth.glsl), whose other side z-fail never counts.

// 2^-15: the planes lie 1/32768 of the half-viewport inside its border. Outside every pixel
// centre of viewports up to 16384 pixels (centres are at most 1 - 1/16384 from the middle),
// far enough inside (3e-5 relative, 256 float ulps) that rounding never puts a vertex outside.
const float UMBRA_GUARD_MARGIN = 1.0 / 32768.0;
// A convex polygon gains at most one vertex per plane: a quad (side) through the 4 viewport
// planes, or a triangle (cap) through 4 + the near plane, ends with at most 8.
const int UMBRA_CLIP_MAX = 8;

// Signed distance of clip-space v to plane `plane` (0-3: left, right, bottom, top, just
// inside the viewport; 4: the camera's near plane), >= 0 inside.
float umbra_plane_distance(int plane, vec4 v) {
    float inset = v.w * UMBRA_GUARD_MARGIN; // exact: a power of two
    if (plane == 0) return (v.w + v.x) - inset;
    if (plane == 1) return (v.w - v.x) - inset;
    if (plane == 2) return (v.w + v.y) - inset;
    if (plane == 3) return (v.w - v.y) - inset;
    return umbra_near_distance(v);
}

// Whether v is inside planes 0 .. planes-1.
bool umbra_inside(vec4 v, int planes) {
    bool inside = true;
    for (int p = 0; p < 5; ++p) {
        if (p < planes) inside = inside && umbra_plane_distance(p, v) >= 0.0;
    }
    return inside;
}

// The point where edge inside -> outside crosses the plane (d_in >= 0 > d_out), always from
// the inside end (the form of SwiftShader's own Clipper.cpp clipEdge).
vec4 umbra_clip_edge(vec4 v_in, vec4 v_out, float d_in, float d_out) {
    return (d_out * v_in - d_in * v_out) / (d_out - d_in);
}

// Clips the convex polygon poly[0 .. n-1] (clip space, any winding, kept) by planes
// 0 .. planes-1 in that order; returns the new vertex count (< 3: nothing left). Every array
// index is a constant (the loops have constant bounds and unroll), so the polygon stays in
// registers: each output vertex is gathered from the candidates that could land on it rather
// than scattered to a computed index (llvmpipe runs the scattering form 8 times slower).
int umbra_clip(inout vec4 poly[UMBRA_CLIP_MAX], int n, int planes) {
    for (int p = 0; p < 5; ++p) {
        if (p >= planes || n < 3) break;
        // Each vertex's distance once, read by both of its edges.
        float d[UMBRA_CLIP_MAX];
        bool any_out = false;
        for (int i = 0; i < UMBRA_CLIP_MAX; ++i) {
            d[i] = umbra_plane_distance(p, poly[i]);
            any_out = any_out || (i < n && d[i] < 0.0);
        }
        if (!any_out) continue;
        // Walking the polygon, vertex i is kept when inside and edge i -> i+1 adds its cut
        // when it crosses; at[i] counts what came before vertex i.
        vec4 kept[UMBRA_CLIP_MAX];
        for (int k = 0; k < UMBRA_CLIP_MAX; ++k) {
            kept[k] = vec4(0.0);
        }
        int at = 0;
        for (int i = 0; i < UMBRA_CLIP_MAX; ++i) {
            if (i < n) {
                vec4 next = i + 1 < n ? poly[(i + 1) % UMBRA_CLIP_MAX] : poly[0];
                float d_next = i + 1 < n ? d[(i + 1) % UMBRA_CLIP_MAX] : d[0];
                bool in_i = d[i] >= 0.0;
                bool crosses = in_i != (d_next >= 0.0);
                vec4 cut = in_i ? umbra_clip_edge(poly[i], next, d[i], d_next) : umbra_clip_edge(next, poly[i], d_next, d[i]);
                int cut_at = at + int(in_i);
                // A convex polygon gains at most one vertex per plane: at < UMBRA_CLIP_MAX
                // unless rounding made it non-convex, and then the extra vertices are dropped.
                for (int k = 0; k < UMBRA_CLIP_MAX; ++k) {
                    if (in_i && k == at) kept[k] = poly[i];
                    if (crosses && k == cut_at) kept[k] = cut;
                }
                at = cut_at + int(crosses);
            }
        }
        for (int k = 0; k < UMBRA_CLIP_MAX; ++k) {
            poly[k] = kept[k];
        }
        n = min(at, UMBRA_CLIP_MAX);
    }
    return n;
}
