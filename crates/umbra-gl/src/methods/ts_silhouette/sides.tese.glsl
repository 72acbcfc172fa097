// ts-silhouette sides, tessellation evaluation stage: paper 001, Section 2.2, Alg. 5, Eq. 2,
// Fig. 6: tessellation coordinates -> one of the four side-quad corners P0..P3 (computed in
// the control stage, clip space).
//
// The quad domain has inner level L = 2|m| - 1 along u, so the generated vertices sit in
// columns a = round(u * L) = 0..L; along v they sit in rows v = 0 and v = 1 (and, because GL
// treats an inner level of 1 as 1 + eps, fractional_odd_spacing adds two interior rows at
// 0 < v1 < 1/2 < v2 < 1, which round(v) folds onto rows 0 and 1: the strip's grid is unchanged).
// Alg. 5: id = 2a + b, t = (id mod 2) xor (floor(id / 4) mod 2), l = floor((id + 2) / 4) mod 2,
// corner n = t + 2l. Column by column (period 4): (P0, P1), (P2, P3), (P3, P2), (P1, P0), ...
// so cell 0 is the quad P0 P1 P3 P2, cell 1 collapses to the segment P2-P3, cell 2 is the same
// quad rotated by 180 degrees (same winding), cell 3 collapses to P0-P1, ...: the 2|m| - 1
// cells give |m| copies of the quad and |m| - 1 degenerate (zero-area, never rasterized) cells.
//
// Winding: `cw` makes every generated triangle clockwise in (u, v), i.e. (0,0) -> (0,1) ->
// (1,1) -> (1,0) for cell 0: P0 -> P1 -> P3 -> P2, which the control stage's corner
// assignment makes a rotation of the quad Q0 Q1 Q2 Q3 it wants.
// Spacing: fractional_odd_spacing with an odd integer level L gives exactly L equal segments.
// Prepended: "#version 450 core" + shared GLSL.

layout(quads, fractional_odd_spacing, cw) in;

patch in vec4 p_corner[4];
// The side's window depth function, from the control stage, for the fragment shader,
// which writes it as every fragment's depth (shared/face_depth.frag.glsl); doubles must be flat.
patch in dvec3 p_face_depth;
flat out dvec3 face_window_depth;

void main() {
    // Never clipped: only light caps are clipped at the near plane (shared/depth.glsl).
    gl_ClipDistance[0] = 1.0;
    int a = int(round(gl_TessCoord.x * gl_TessLevelInner[0]));
    int b = int(round(gl_TessCoord.y));
    int id = 2 * a + b;
    int t = (id % 2) ^ ((id / 4) % 2);
    int l = ((id + 2) / 4) % 2;
    gl_Position = p_corner[t + 2 * l];
    face_window_depth = p_face_depth;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
