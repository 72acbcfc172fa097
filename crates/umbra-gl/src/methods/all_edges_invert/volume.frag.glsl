// all-edges-invert shadow volumes: fragment shader. Paper 002, Section 3: the volume pass only
// drives the stencil operations (ZFAIL = INVERT, PASS = INCR under write mask 1101b); colour
// writes are masked off, so there is nothing to compute, and no depth write keeps early
// depth/stencil testing on.
#version 450 core

void main() {
}
