// gs-triangle shadow volumes: fragment shader. Stencil-only pass (paper 001 Section 2.1
// per-triangle volumes, z-fail of Everitt & Kilgard 2002 or z-pass of Heidmann 1991): the
// stencil operations count, colour writes are masked off; nothing to compute, and no depth
// write, so early depth/stencil testing stays on.
#version 450 core

void main() {
}
