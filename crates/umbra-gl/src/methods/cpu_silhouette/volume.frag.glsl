// cpu-silhouette shadow volumes: fragment shader. Stencil-only pass (paper 001 Section 2,
// Everitt & Kilgard 2002 z-fail / Heidmann 1991 z-pass): the stencil ops do the counting,
// colour writes are masked off, so there is nothing to compute here.
#version 450 core

void main() {
}
