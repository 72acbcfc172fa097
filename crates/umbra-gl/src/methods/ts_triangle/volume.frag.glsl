// ts-triangle shadow volumes: fragment shader. Stencil-only pass (paper 001 Section 2.1,
// z-fail of Everitt & Kilgard 2002): the stencil operations count, colour writes are masked
// off; nothing to compute and no depth write, so early depth/stencil testing stays on.
#version 450 core

void main() {
}
