// ts-triangle (two-pass per-triangle method), pass 1: tessellation evaluation shader.
// Paper 001, Section 2.1, Algorithm 1 and Fig. 2; extrusion Eq. 2 (umbra_extrude).
//
// The patch (inner level 3, outer 1, equal spacing) has 6 vertices: the 3 corners, where one
// tessellation coordinate is 0 (c = x y z = 0), keep the triangle's points; the 3 inner ones
// (c != 0) take the position of the corner with the largest coordinate and are pushed to
// infinity (X = l_w P[i] - L, w = 0). The 7 triangles become the 3 sides and the dark (back)
// cap at infinity (Fig. 2d). On the corners Alg. 1 blends P[0] x + P[1] y + P[2] z with
// exactly one coordinate 1 and the others 0: that is P[i] for the largest coordinate too,
// which is what is computed here (no arithmetic on the positions, so every side vertex is
// bit-identical to the same vertex in every other program).
//
// Winding: the control shader wound the patch to face the light; the tessellated sheet with
// its inner triangle pushed to infinity closes the light cap's boundary from the far side, so
// its primitives are emitted clockwise ("reversed triangle winding") to face OUT of the volume.
// For a directional light every inner vertex extrudes to the same point -L: the dark cap has
// zero area and the sides become triangles, as they should.
//
// For the fragment shader (side_depth.frag.glsl): e_corner, the one-hot vector of the corner i
// a vertex belongs to (a side's fragments have the third component exactly 0), and the
// patch's three canonical side depth planes, flat.

layout(triangles, equal_spacing, cw) in;

in vec3 c_world[];
patch in dvec4 tc_side_plane[3];

out vec3 e_corner;
flat out dvec4 e_side_plane[3];

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

void main() {
    // Never clipped: only light caps are clipped at the near plane (shared/depth.glsl).
    UMBRA_NEAR_CLIP(1.0);
    vec3 t = gl_TessCoord;
    float c = t.x * t.y * t.z;
    int i = (t.x >= t.y && t.x >= t.z) ? 0 : (t.y >= t.z ? 1 : 2);
    vec3 p = c_world[i];
    vec4 world = c == 0.0 ? vec4(p, 1.0) : umbra_extrude(p, u_light);
    gl_Position = u_clip_from_world * world;
    e_corner = vec3(i == 0 ? 1.0 : 0.0, i == 1 ? 1.0 : 0.0, i == 2 ? 1.0 : 0.0);
    e_side_plane = tc_side_plane;
    UMBRA_SCENE_CLIP(gl_Position); // shared/depth.glsl: z-pass volumes clipped to the scene box
}
