// Element i of umbra-three's data textures (volumes.js): texel (i mod 2^shift,
// i / 2^shift) of a texture 2^u_texture_shift texels wide. No #version line: spliced after
// the ES 3.00 prelude.

uniform int u_texture_shift;

ivec2 umbra_texel(int i) {
    return ivec2(i & ((1 << u_texture_shift) - 1), i >> u_texture_shift);
}

