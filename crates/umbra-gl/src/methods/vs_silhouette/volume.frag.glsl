// vs-silhouette shadow volumes: fragment shader. Paper 003 Section 2.1, step 2: the stencil
// z-fail pass (Everitt & Kilgard 2002) only counts, colour writes are masked off, so there is
// nothing to compute but
// the wide counter's o_count. Common subset of GLSL 4.50 core and GLSL ES 3.00 (no #version here; ES
// needs the default float precision the Rust prelude declares).

// The wide counter (src/counter.rs): +1 for a front face, -1 for a back face, summed by
// blending into an R32F buffer under Counter::Float32; under Counter::Stencil8 the colour
// write mask is off and this output is ignored.
layout(location = 0) out float o_count;

void main() {
    o_count = gl_FrontFacing ? 1.0 : -1.0;
}
