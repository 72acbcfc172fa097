// ts-triangle-1pass: fragment shader. Paper 001, Section 2.3: "Single-pass per-triangle
// method suffers from inconsistent rasterization of two identical triangles at the same depth
// but with different winding [...] We had to manually push the front cap's fragments into depth
// of 1.0f, so they would fail the depth test, otherwise we observed self-shadowing artifacts."
//
// Stage reason: the light cap shares its tessellated vertices with two sides (see
// one_pass.tese.glsl), so it can only be moved to the far plane per fragment. Its fragments are
// the ones where both flags are non-zero (interior of cell 3; a flag that is 0 at all three
// vertices of a triangle interpolates to exactly 0). They get depth u_far_clip_z: the window
// depth of the far plane equals its clip z / w for both the standard (-1..1 mapped to 0..1:
// z = w gives 1) and the reversed (zero-to-one clip control: z = 0 gives 0) convention.
// Every other fragment keeps its rasterized depth. Writing gl_FragDepth turns off early depth
// testing for this program (the cost the paper reports and umbra measures).
//
// UMBRA_NO_FRAGMENT_DEPTH (measurement only, NOT exact): leave every fragment at its
// rasterized depth, so the cap z-fights with the caster as the paper describes; the
// difference in time to the default is the price of the depth write.
#version 450 core

noperspective in vec2 e_cap_flags;

uniform float u_far_clip_z;

void main() {
#ifndef UMBRA_NO_FRAGMENT_DEPTH
    bool light_cap = e_cap_flags.x > 0.0 && e_cap_flags.y > 0.0;
    gl_FragDepth = light_cap ? u_far_clip_z : gl_FragCoord.z;
#endif
}
