// cs-silhouette shadow volumes: fragment shader. Stencil-only z-fail / z-pass pass (Everitt &
// Kilgard 2002 / Heidmann 1991; paper 001 Section 2): the stencil ops count, colour writes are
// masked off, nothing to compute. Prepended: "#version 450 core".

void main() {
}
