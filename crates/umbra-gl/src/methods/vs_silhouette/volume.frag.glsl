// vs-silhouette shadow volumes: fragment shader. Paper 003 Section 2.1, step 2: the stencil
// z-fail pass (Everitt & Kilgard 2002) only counts, colour writes are masked off, so there is
// nothing to compute. Common subset of GLSL 4.50 core and GLSL ES 3.00 (no #version here; ES
// needs the default float precision the Rust prelude declares).

void main() {
}
