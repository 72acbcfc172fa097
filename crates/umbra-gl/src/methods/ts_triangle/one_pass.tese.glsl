// ts-triangle-1pass (single-pass per-triangle method): tessellation evaluation shader.
// Paper 001, Section 2.1, Fig. 3 ("the evaluation shader then twists the shape in order to
// create a volume"); extrusion Eq. 2 (umbra_extrude).
//
// With levels (1, 5, 1, 5) / (5, 1) and fractional odd spacing the quad becomes a strip of 5
// cells between the rows v = 0 and v = 1, with columns at u = k / 5, k = 0..5 (the inner
// rows of the spec's "1 + epsilon" rounding lie at v = 0 and v = 1 up to rounding - llvmpipe
// puts them exactly there, the paper's Fig. 3 merges them too - so a vertex is identified by
// its column k = round(5 u) and its row round(v) alone). Each column is mapped to two of the
// six volume points A, B, C (the triangle wound to face the light) and A', B', C' (extruded,
// w = 0):
//
//   column k    0   1   2   3   4   5
//   row v = 0   A   A'  A'  A   B   B'
//   row v = 1   B   B'  C'  C   C   C'
//
// so that the 5 cells, emitted counter-clockwise in (u, v), are exactly the 5 faces of the
// triangle's volume, each counter-clockwise seen from outside:
//   cell 0: A A' B' B  = side of edge A -> B  (B A A' B' rotated)
//   cell 1: A' A' C' B' = dark cap A' C' B' (one triangle of the cell is degenerate)
//   cell 2: A' A C C'  = side of edge C -> A
//   cell 3: A B C C    = light cap A B C    (one degenerate triangle)
//   cell 4: B B' C' C  = side of edge B -> C
// Every cell is a planar quad or a triangle with a repeated corner, so the result does not
// depend on which diagonal the tessellator splits a cell along. (This table was found by an
// exhaustive search over all column assignments; there are 12 solutions, all rotations or
// mirrors of this one, and in all of them the light cap shares its two columns with two
// sides.)
//
// Depths (side_depth.frag.glsl): the light cap's vertices are shared with the sides of cells 2
// and 4, so they cannot be moved to the far plane in this stage. Like the paper (Section 2.3:
// the single-pass method z-fights with the caster otherwise), the fragment shader moves the
// cap's fragments; it also gives every side fragment the depth of the side's canonical plane
// (so the two copies of a side shared by neighbours cancel exactly). It tells the faces apart
// by e_corner, the one-hot vector of the point (A, B or C) a vertex was placed at: sides have
// one component exactly 0, caps none.

layout(quads, fractional_odd_spacing, ccw) in;

in vec3 c_world[];
patch in dvec4 tc_side_plane[3];

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

out vec3 e_corner;
flat out dvec4 e_side_plane[3];

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

void main() {
    // Not clipped here: its light cap shares vertices with sides; side_depth.frag.glsl
    // handles the near-plane cut of the cap per fragment (shared/depth.glsl).
    UMBRA_NEAR_CLIP(1.0);
    int k = int(round(gl_TessCoord.x * 5.0));
    bool top = gl_TessCoord.y >= 0.5;
    // Point index per column (see the table above): bottom row A A A A B B, top row B B C C C C.
    int i = top ? (k < 2 ? 1 : 2) : (k < 4 ? 0 : 1);
    bool extruded = k == 1 || k == 2 || k == 5;
    vec3 p = c_world[i];
    vec4 world = extruded ? umbra_extrude(p, u_light) : vec4(p, 1.0);
    gl_Position = u_clip_from_world * world;
    e_corner = vec3(i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0);
    e_side_plane = tc_side_plane;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
