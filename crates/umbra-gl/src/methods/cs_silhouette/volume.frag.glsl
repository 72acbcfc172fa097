// cs-silhouette shadow volumes: fragment shader. Stencil-only z-fail / z-pass pass (Everitt &
// Kilgard 2002 / Heidmann 1991; paper 001 Section 2): the stencil ops count, colour writes are
// masked off, nothing to compute but the wide counter's o_count and, for every
// fragment, its face's plane depth (from the vertex stage). Prepended:
// "#version 450 core" and shared/face_depth.frag.glsl.

// The wide counter (src/counter.rs): +1 for a front face, -1 for a back face, summed by
// blending into an R32F buffer under Counter::Float32; under Counter::Stencil8 the colour
// write mask is off and this output is ignored.
layout(location = 0) out float o_count;

void main() {
    o_count = gl_FrontFacing ? 1.0 : -1.0;
    umbra_write_face_depth();
}
