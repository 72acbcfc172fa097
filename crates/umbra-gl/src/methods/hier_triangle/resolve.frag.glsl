// hier-triangle, per light: the decision into the stencil (Classification::StencilZero: lit
// where 0). Full-screen; a pixel whose sample is shadowed — its bit in the leaf's mask, or its
// leaf or an ancestor covered — survives and the stencil state writes 1 (REPLACE); the others
// (background included) are discarded and keep the cleared 0. No colour, no depth. Prepended:
// hier/hierarchy.glsl, hier/region.glsl, frustum.glsl.

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uvec2 tile = p / LEAF_SIDE;
    uint leaf = tile.y * u_level[0].x + tile.x;
    uint k = (p.y % LEAF_SIDE) * LEAF_SIDE + p.x % LEAF_SIDE;
    uint bit = 1u << k;
    // Only samples: a covered node's background pixels stay 0 (count_shadows' contract).
    bool present = (state[u_valid_offset + leaf] & bit) != 0u;
    if (!present || ((state[u_bits_offset + leaf] & bit) == 0u && !covered_from_above(0u, leaf))) {
        discard;
    }
}
