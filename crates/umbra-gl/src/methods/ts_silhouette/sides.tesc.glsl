// ts-silhouette sides, tessellation control stage: paper 001, Section 2.2.
// One invocation per edge patch (Fig. 4): patch vertex 0 = A, 1 = B (A < B in the vertex order
// of Eq. 1 / Alg. 2, as umbra_geom::EdgeAdjacency stores them), 2 = the count vertex
// (x = number n of opposite vertices in this patch), 3 .. 3 + n - 1 = the opposite vertices.
//
// Multiplicity (Alg. 3 with CompMultiplicity, Alg. 4, through umbra_side_contribution: the
// reference edge, or Peciva 2013's 3-edge test with UMBRA_THREE_EDGE): m = sum over the
// patch's opposites. An edge with more opposites than a patch holds is split over several
// patches whose m add up to the edge's (see ts_silhouette/patches.rs): |m| <= n <= K here.
//
// Tessellation levels (Section 2.2, Fig. 6): the quad domain with inner levels
// (2|m| - 1, 1), outer levels (1, 2|m| - 1, 1, 2|m| - 1), i.e. a strip of 2|m| - 1 cells along
// u: the evaluation stage bends it into |m| overlapping side quads (Alg. 5). m = 0 (not a
// silhouette for this patch): outer level 0 discards the patch.
//
// The four corners of the side quad (Eq. 2, extrusion C = (A * l_w - L.xyz, 0)) are computed
// here ONCE per patch, already in clip space, so every generated vertex that maps to a corner
// is bit-identical (watertight volumes). The quad Q0 Q1 Q2 Q3 in umbra_geom::silhouette's
// winding (counter-clockwise seen from outside the volume; Q0 Q1 on the edge, Q2 Q3 at
// infinity):
//   m > 0: B A A_inf B_inf        m < 0: A B B_inf A_inf
// is stored as Alg. 5's corners P0..P3 (the evaluation stage's cell 0 is P0 P1 / P2 P3, wound
// P0 P1 P3 P2, see sides.tese.glsl) in one of two rotations, both of which keep that winding:
//   |m| = 1:  P0 = Q1, P1 = Q2, P2 = Q0, P3 = Q3  (cell wound Q1 Q2 Q3 Q0)
//   |m| > 1:  P0 = Q2, P1 = Q3, P2 = Q1, P3 = Q0  (cell wound Q2 Q3 Q0 Q1)
// Why two: the tessellator (implementation-dependent; llvmpipe here) emits a single quad
// (|m| = 1, all levels 1) as (c00 c01 c10) (c10 c01 c11) and the quads of a strip with other
// vertex orders; the rotation is chosen so that on llvmpipe every triangle of |m| <= 2 starts
// with a vertex on the edge (w = 1), never with one at infinity (w = 0): llvmpipe clips a
// triangle starting at a w = 0 vertex into a fan that covers pixels along its clipped sides
// slightly differently, which showed as a stray count of 2 on Conference (torture pose 0).
// With |m| = 1 this is also exactly cpu-silhouette's diagonal (Q0-Q2). For |m| >= 3 (only
// when an edge has 3+ consistently oriented opposite vertices) about half of the copies in the
// strip's interior still start at infinity: Alg. 5 alternates the copies' rotation by 180
// degrees, and no other corner assignment keeps the degenerate cells degenerate.
// Face depth: the side's window depth function (its plane through Q0 Q1 Q2, or
// u_edge_on_depth seen edge-on; shared/side_plane.glsl) is computed here once per patch and
// passed, as a patch output, through the evaluation stage to the fragment shader, which writes
// it as every fragment's depth (shared/face_depth.frag.glsl).
// Prepended: "#version 450 core", shared/multiplicity.glsl, shared/depth.glsl,
// silhouette_caps/determinism.glsl.

// One output vertex: the patch's work is done once, not per output control point.
layout(vertices = 1) out;

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

in vec3 v_patch_vertex[];

patch out vec4 p_corner[4];
patch out dvec3 p_face_depth;

void main() {
    vec3 a = v_patch_vertex[0];
    vec3 b = v_patch_vertex[1];
    // Never read beyond the patch, whatever the count vertex says.
    int count = min(int(v_patch_vertex[2].x), gl_PatchVerticesIn - 3);
    int m = 0;
    for (int i = 0; i < count; ++i) {
        m += umbra_side_contribution(a, b, v_patch_vertex[3 + i], u_light);
    }
    int copies = abs(m);
    if (copies == 0) {
        // An outer level of 0 discards the patch: no quads.
        gl_TessLevelOuter[0] = 0.0;
        gl_TessLevelOuter[1] = 0.0;
        gl_TessLevelOuter[2] = 0.0;
        gl_TessLevelOuter[3] = 0.0;
        gl_TessLevelInner[0] = 0.0;
        gl_TessLevelInner[1] = 0.0;
        return;
    }
    float level = float(2 * copies - 1);
    gl_TessLevelOuter[0] = 1.0;    // u = 0 edge: the first quad's edge side
    gl_TessLevelOuter[1] = level;  // v = 0 edge: the strip's bottom row
    gl_TessLevelOuter[2] = 1.0;    // u = 1 edge
    gl_TessLevelOuter[3] = level;  // v = 1 edge: the strip's top row
    gl_TessLevelInner[0] = level;
    gl_TessLevelInner[1] = 1.0;

    // The quad Q0 Q1 Q2 Q3 in umbra_geom::silhouette's winding, stored as Alg. 5's corners in
    // the rotation chosen for |m| (see the header).
    vec3 first = m > 0 ? b : a;   // Q0
    vec3 second = m > 0 ? a : b;  // Q1
    vec4 q0 = umbra_clip_from_world_point(u_clip_from_world, vec4(first, 1.0));
    vec4 q1 = umbra_clip_from_world_point(u_clip_from_world, vec4(second, 1.0));
    vec4 q2 = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(second, u_light));
    vec4 q3 = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(first, u_light));
    p_face_depth = umbra_face_depth_of_plane(umbra_window_depth_plane(q0, q1, q2));
    if (copies == 1) {
        p_corner[0] = q1;
        p_corner[1] = q2;
        p_corner[2] = q0;
        p_corner[3] = q3;
    } else {
        p_corner[0] = q2;
        p_corner[1] = q3;
        p_corner[2] = q1;
        p_corner[3] = q0;
    }
}
