// hier-triangle, per light: the decision into the stencil (Classification::StencilZero: lit
// where 0). Full-screen; a pixel whose sample is shadowed — its bit in the leaf's mask, or its
// leaf or an ancestor covered — survives and the stencil state writes 1 (REPLACE); the others
// are discarded and keep the cleared 0. No colour, no depth. Prepended: the header and
// common.glsl.

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uvec2 tile = p / LEAF_SIDE;
    uint leaf = tile.y * u_level[0].x + tile.x;
    uint k = (p.y % LEAF_SIDE) * LEAF_SIDE + p.x % LEAF_SIDE;
    bool bit = (state[u_bits_offset + leaf] & (1u << k)) != 0u;
    if (!bit && !covered_from_above(0u, leaf)) {
        discard;
    }
}
