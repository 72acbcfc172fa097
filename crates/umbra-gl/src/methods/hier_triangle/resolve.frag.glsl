// hier-triangle, per light: the decision into the stencil (Classification::StencilZero: lit
// where 0), the merge of the live bitmask per pixel (Sintorn et al. 2014: a sample is shadowed
// when its bit, or the bit of any node on its path to the root, was cleared; live.glsl).
// Full-screen; a shadowed sample survives and the stencil state writes 1 (REPLACE); the others
// (background included) are discarded and keep the cleared 0. No colour, no depth. At most
// MAX_LEVELS iterations. Prepended: hier/hierarchy.glsl, hier/region.glsl, frustum.glsl,
// live.glsl.

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uvec2 tile = p / LEAF_SIDE;
    uint leaf = tile.y * u_level[0].x + tile.x;
    uint k = (p.y % LEAF_SIDE) * LEAF_SIDE + p.x % LEAF_SIDE;
    // Only samples: a cleared node's background pixels stay 0 (count_shadows' contract).
    if ((state[u_valid_offset + leaf] & (1u << k)) == 0u) {
        discard;
    }
    bool shadowed = (state[live_word(0u, leaf)] & (1u << k)) == 0u;
    uint node = leaf;
    for (uint l = 0u; l < u_levels && !shadowed; ++l) {
        uint parent;
        uint bit;
        parent_of(l, node, parent, bit);
        shadowed = (state[live_word(l + 1u, parent)] & (1u << bit)) == 0u;
        node = parent;
    }
    if (!shadowed) {
        discard;
    }
}
