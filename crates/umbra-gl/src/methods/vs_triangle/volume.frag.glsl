// vs-triangle shadow volumes: fragment shader. Stencil-only pass (paper 001 Section 2.1 per-
// triangle volumes, counted with z-fail, Everitt & Kilgard 2002, or z-pass, Heidmann 1991):
// the stencil operations do the counting and colour writes are masked off, so there is
// nothing to compute but the wide counter's o_count and, for every fragment, its face's
// plane depth (shared/face_depth.frag.glsl, prepended with
// "#version 450 core").

// The wide counter (src/counter.rs): +1 for a front face, -1 for a back face, summed by
// blending into an R32F buffer under Counter::Float32; under Counter::Stencil8 the colour
// write mask is off and this output is ignored.
layout(location = 0) out float o_count;

void main() {
    o_count = gl_FrontFacing ? 1.0 : -1.0;
    umbra_write_face_depth();
}
