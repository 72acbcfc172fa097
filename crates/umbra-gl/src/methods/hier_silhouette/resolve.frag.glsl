// hier-silhouette, per light: the decision into the stencil (Classification::StencilZero: lit
// where 0). Full-screen; a pixel whose sample's count W is not 0 survives and the stencil state
// writes 1 (REPLACE); the others (background included) are discarded and keep the cleared 0.
// No colour, no depth. Prepended: hier/hierarchy.glsl, hier/region.glsl,
// shared/multiplicity.glsl, faces.glsl.

void main() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint pixel = p.y * u_frame.x + p.x;
    if (samples[pixel].w == NO_TRIANGLE || counts[u_counts_partial + pixel] == 0) {
        discard;
    }
}
