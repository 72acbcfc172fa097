// vs-triangle shadow volumes: fragment shader. Stencil-only pass (paper 001 Section 2.1 per-
// triangle volumes, counted with z-fail, Everitt & Kilgard 2002, or z-pass, Heidmann 1991):
// the stencil operations do the counting and colour writes are masked off, so there is
// nothing to compute. Kept empty so early depth/stencil testing stays on.
#version 450 core

void main() {
}
