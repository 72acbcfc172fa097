// Element i of umbra-three's data textures (volumes.js): texel (i mod 2^shift,
// i / 2^shift) of a texture 2^u_texture_shift texels wide, u_texture_rows high. No #version
// line: spliced after the ES 3.00 prelude.

uniform int u_texture_shift;
uniform int u_texture_rows;

ivec2 umbra_texel(int i) {
    return ivec2(i & ((1 << u_texture_shift) - 1), i >> u_texture_shift);
}

// The clip-space position of texel i's centre in a viewport covering the whole texture: a
// point of size 1 there covers exactly that texel (its centre is the point's; the
// neighbours' are a whole texel away). Exact in x (width a power of two); in y off by at most
// a few ulps of the row count, far below the half texel that would matter.
vec4 umbra_point_at(int i) {
    vec2 size = vec2(float(1 << u_texture_shift), float(u_texture_rows));
    vec2 texel = vec2(umbra_texel(i));
    return vec4((texel + 0.5) / size * 2.0 - 1.0, 0.0, 1.0);
}
