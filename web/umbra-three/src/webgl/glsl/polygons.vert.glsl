// The polygon pass of umbra-three's shadow volumes: paper 003's sides
// (Section 2.4, Alg. 1) and caps (Section 2.5, Alg. 2, Eq. 6) of every edge record or
// triangle, each computed ONCE per frame as a clipped convex polygon and captured by
// transform feedback (one point in, one polygon out); fan.vert.glsl then draws them. What it
// changes from the native vs-silhouette (crates/umbra-gl/src/methods/vs_silhouette/), and why:
//
// 1. Orientations are read, not recomputed. The wasm (crates/umbra-wasm/src/silhouette.rs)
//    orients every triangle once per light (paper 001 Alg. 4 in f32, never contracted) into
//    u_orientation; a cap reads its triangle's value, and an edge record sums
//    sign_i * orientation(T_i) over its opposite slots (edge_triangles, from `umbra export`:
//    T_i the slot's triangle, + when it walks the edge A -> B), which is paper 001's Alg. 3
//    bit for bit. GLSL ES 3.00 has no `precise`; evaluated apart for the sides and the caps,
//    a compiler could contract the test differently and give a triangle two orientations (an
//    open volume). One value read twice cannot disagree. The sides visit only the records the
//    wasm listed with the same sum nonzero (u_records): every other record has no side.
// 2. Every polygon is clipped here (clip.glsl) to just inside the viewport, and light caps also
//    to the camera's near plane: no rasteriser clips a volume (SwiftShader's clipper
//    re-projects vertices that its unclipped triangles share, and the volume cracks), and
//    ES 3.00 has no gl_ClipDistance for the near-plane cut of light caps (native umbra:
//    gl_ClipDistance[0]).
//
// The caster's geometry is its welded vertices (u_vertices, RGB32F, one texel each) named by
// index: the two vertices A, B of every edge record (u_record_vertices, sides-data's order)
// and the three of every triangle (u_triangle_vertices, caps-data's order). The positions are
// those paper 003's sides-data and caps-data (Eq. 8, 9) repeat per record and per triangle,
// bit for bit; the opposite vertices of sides-data are not needed here (orientations are
// read, point 1), and a record's opposite slots are its nonzero edge_triangles entries (0 for
// an unused slot).
//
// GPU silhouettes (u_all_records 1, `silhouettes: 'gpu'`): the orientations come from the
// orientation pass (orient.vert.glsl) instead of the wasm, and with no list every record is
// visited (record gl_VertexID); one of multiplicity 0 gives no polygon, as paper 003 draws
// every edge.
//
// u_mode 0: edge record u_records[gl_VertexID]: the quad B A A_inf B_inf (the native id_CCW
// triangles (B, A, A_inf), (B, A_inf, B_inf)) for curMult > 0, reversed for curMult < 0 (so
// that opposite-signed records of a split edge clip to the same polygon and cancel), drawn
// |curMult| times (Alg. 1). u_mode 1 / 2: the light / dark cap of triangle `gl_VertexID`,
// wound to face the light (Alg. 2, lines 5-6), the dark
// cap extruded and reversed (line 11), the light cap pushed to the far plane after its cut
// (Eq. 6); drawn once, or not at all for an edge-on triangle (lines 2-4).
//
// Culled to the receivers (u_culled 1, drawer.js `volumeCull`; crates/umbra-wasm/src/cull.rs):
// the wasm has dropped the triangles whose shadow frustum holds no visible sample (orientation
// 0: no cap, no part in any edge) and put each welded vertex's far end into u_far (homogeneous,
// this caster's space; w = 0 at infinity), computed ONCE there in f64 and read by every
// polygon that uses it, so the clamped volume closes as the infinite one does. A side's far
// vertices are then u_far of its record's two welded vertices (u_record_vertices) instead of
// umbra_extrude; u_mode 1 and 2 visit only the kept triangles of nonzero orientation
// (u_kept), and u_mode 2 is the far cap (the dark cap at the far ends: umbra_geom's
// extract_clamped far caps, P0' P2' P1' of the light-facing-oriented triangle), drawn under
// z-pass too, since a clamped far cap may lie in front of a visible sample. A far cap all at
// infinity is left out where the unclamped volume has no dark cap (u_skip_infinite: z-pass,
// or a directional light, whose points at infinity coincide).
//
// u_mode 3: the light cap of triangle `gl_VertexID` (u_culled: of u_kept[gl_VertexID]) at its
// TRUE depth: the polygon of u_mode 1 (the same vertices, wound to face the light, cut by the
// viewport planes and last by the near plane by the same clip), not pushed to the far plane,
// and only for triangles in [u_range.x, u_range.y) (the range of a one-sided material; n = 0
// elsewhere). Its signed repeat is the triangle's orientation (+-1; the fan pass draws |repeat|
// copies), so that the fan pass can tell the triangle's own facing on screen from the cap's
// (gl_FrontFacing, reversed where the orientation is -1). drawer.js counts these caps where
// they lie in front of the sample, for the faces its depth pass culls (docs/web.md,
// "FrontSide: the surface three.js shows").
//
// Out: the polygon's vertices v_p0 .. v_p7 (clip space, as drawn) and v_info = (vertex
// count, signed repeat), 36 floats: 9 RGBA32F texels per polygon once copied to a texture.

uniform mat4 u_clip_from_world;
uniform vec4 u_light;
uniform int u_mode;
uniform int u_max_mult;
uniform highp sampler2D u_vertices;
uniform highp isampler2D u_edge_triangles;
uniform highp isampler2D u_orientation;
uniform highp isampler2D u_records;
uniform int u_all_records;
uniform int u_culled;
uniform int u_skip_infinite;
uniform highp sampler2D u_far;
uniform highp isampler2D u_record_vertices;
uniform highp isampler2D u_triangle_vertices;
uniform highp isampler2D u_kept;
uniform ivec2 u_range;

// w = 1 vertices must be bit for bit where the scene's vertex shader puts the same point
// (same expression, invariant), so the sides meet the caster and a light cap keeps the
// triangle's footprint.
invariant out vec4 v_p0;
invariant out vec4 v_p1;
invariant out vec4 v_p2;
invariant out vec4 v_p3;
invariant out vec4 v_p4;
invariant out vec4 v_p5;
invariant out vec4 v_p6;
invariant out vec4 v_p7;
out vec4 v_info;

int umbra_orientation_of(int triangle) {
    return texelFetch(u_orientation, umbra_texel(triangle), 0).r;
}

// Welded vertex `v` of the caster (its space).
vec3 umbra_vertex(int v) {
    return texelFetch(u_vertices, umbra_texel(v), 0).xyz;
}

// The far end of welded vertex `v` (culled volumes only).
vec4 umbra_far(int v) {
    return texelFetch(u_far, umbra_texel(v), 0);
}

void main() {
    // Transform feedback only: nothing of this pass is rasterised.
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    vec4 poly[UMBRA_CLIP_MAX];
    for (int i = 0; i < UMBRA_CLIP_MAX; ++i) {
        poly[i] = vec4(0.0);
    }
    int n = 0;
    int repeat = 0;
    int planes = 4;
    int record = u_mode == 0 ? (u_all_records != 0 ? gl_VertexID : texelFetch(u_records, umbra_texel(gl_VertexID), 0).r)
        : (u_culled != 0 ? texelFetch(u_kept, umbra_texel(gl_VertexID), 0).r : gl_VertexID);
    if (u_mode == 0) {
        // Alg. 1, line 2: the record's (sub-)multiplicity, Alg. 3's terms read; its used
        // slots come first.
        for (int i = 0; i < u_max_mult; ++i) {
            int t = texelFetch(u_edge_triangles, umbra_texel(record * u_max_mult + i), 0).r;
            if (t == 0) {
                break;
            }
            int o = umbra_orientation_of(abs(t) - 1);
            repeat += t > 0 ? o : -o;
        }
        if (repeat != 0) {
            int va = texelFetch(u_record_vertices, umbra_texel(2 * record), 0).r;
            int vb = texelFetch(u_record_vertices, umbra_texel(2 * record + 1), 0).r;
            vec3 a = umbra_vertex(va);
            vec3 b = umbra_vertex(vb);
            vec4 pa = u_clip_from_world * vec4(a, 1.0);
            vec4 pb = u_clip_from_world * vec4(b, 1.0);
            vec4 a_far = umbra_extrude(a, u_light);
            vec4 b_far = umbra_extrude(b, u_light);
            if (u_culled != 0) {
                a_far = umbra_far(va);
                b_far = umbra_far(vb);
            }
            vec4 pa_inf = u_clip_from_world * a_far;
            vec4 pb_inf = u_clip_from_world * b_far;
            poly[0] = pb;
            poly[1] = repeat > 0 ? pa : pb_inf;
            poly[2] = pa_inf;
            poly[3] = repeat > 0 ? pb_inf : pa;
            n = 4;
        }
    } else {
        int o = umbra_orientation_of(record);
        if (u_mode == 3 && (record < u_range.x || record >= u_range.y)) {
            o = 0; // not of the one-sided range drawn: no polygon
        }
        if (o != 0) {
            // u_mode 3: the orientation's sign rides on the repeat (fan.vert.glsl).
            repeat = u_mode == 3 ? o : 1;
            n = 3;
            int v0 = texelFetch(u_triangle_vertices, umbra_texel(3 * record), 0).r;
            int v1 = texelFetch(u_triangle_vertices, umbra_texel(3 * record + 1), 0).r;
            int v2 = texelFetch(u_triangle_vertices, umbra_texel(3 * record + 2), 0).r;
            vec3 p0 = umbra_vertex(v0);
            vec3 p1 = umbra_vertex(v1);
            vec3 p2 = umbra_vertex(v2);
            // The far ends of the three vertices (culled: u_far; else at infinity).
            vec4 f0 = umbra_extrude(p0, u_light);
            vec4 f1 = umbra_extrude(p1, u_light);
            vec4 f2 = umbra_extrude(p2, u_light);
            if (u_culled != 0 && u_mode == 2) {
                f0 = umbra_far(v0);
                f1 = umbra_far(v1);
                f2 = umbra_far(v2);
            }
            if (o < 0) {
                vec3 t = p1;
                p1 = p2;
                p2 = t;
                vec4 g = f1;
                f1 = f2;
                f2 = g;
            }
            if (u_mode == 1 || u_mode == 3) {
                // Cut by the near plane last (plane 4), so that its cuts by the viewport
                // planes on the edges it shares with the sides are theirs.
                planes = 5;
                poly[0] = u_clip_from_world * vec4(p0, 1.0);
                poly[1] = u_clip_from_world * vec4(p1, 1.0);
                poly[2] = u_clip_from_world * vec4(p2, 1.0);
            } else if (u_skip_infinite != 0 && f0.w == 0.0 && f1.w == 0.0 && f2.w == 0.0) {
                n = 0;
            } else {
                poly[0] = u_clip_from_world * f2;
                poly[1] = u_clip_from_world * f1;
                poly[2] = u_clip_from_world * f0;
            }
        }
    }
    // Most polygons need no cut: test that first (fixed indices), clip only the others.
    bool inside = umbra_inside(poly[0], planes) && umbra_inside(poly[1], planes) && umbra_inside(poly[2], planes)
        && (n == 3 || umbra_inside(poly[3], planes));
    if (n > 0 && !inside) {
        n = umbra_clip(poly, n, planes);
    }
    if (u_mode == 1) {
        for (int i = 0; i < UMBRA_CLIP_MAX; ++i) {
            poly[i] = umbra_push_to_far(poly[i]); // Eq. 6, after the near-plane cut
        }
    }
    v_p0 = poly[0];
    v_p1 = poly[1];
    v_p2 = poly[2];
    v_p3 = poly[3];
    v_p4 = poly[4];
    v_p5 = poly[5];
    v_p6 = poly[6];
    v_p7 = poly[7];
    v_info = vec4(float(n), float(repeat), 0.0, 0.0);
}
