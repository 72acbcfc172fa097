// vs-silhouette shadow volumes: fragment shader. Paper 003 Section 2.1, step 2: the stencil
// z-fail pass (Everitt & Kilgard 2002) only counts, colour writes are masked off, so there is
// nothing to compute but the wide counter's o_count and, in GLSL 4.50, every fragment's depth,
// taken from its face's plane (shared/face_depth.frag.glsl, prepended by
// vs_silhouette/mod.rs for that dialect only: it needs doubles). Common subset of GLSL 4.50
// core and GLSL ES 3.00 (no #version here; ES needs the default float precision the Rust
// prelude declares); also read by the WebGL viewer's build (web/build.mjs), which compiles it
// as ES.

// The wide counter (src/counter.rs): +1 for a front face, -1 for a back face, summed by
// blending into an R32F buffer under Counter::Float32; under Counter::Stencil8 the colour
// write mask is off and this output is ignored.
layout(location = 0) out float o_count;

void main() {
    o_count = gl_FrontFacing ? 1.0 : -1.0;
#ifndef GL_ES
    umbra_write_face_depth();
#endif
}
