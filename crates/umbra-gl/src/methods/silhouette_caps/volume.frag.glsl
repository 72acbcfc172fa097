// Fragment shader of the GPU silhouette methods' volume passes (ts-silhouette, gs-silhouette,
// silhouette caps). Stencil-only counting pass (paper 001 Section 2; Everitt & Kilgard 2002
// z-fail, Heidmann 1991 z-pass): the stencil operations do the counting and colour writes are
// masked off, so there is nothing to compute. Prepended: "#version 450 core".

void main() {
}
