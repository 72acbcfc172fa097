// gs-silhouette sides, vertex stage: paper 001, Section 3 (the geometry-shader silhouette the
// tessellation method is compared with). One point per edge patch, no vertex attributes: the
// geometry stage fetches the patch by gl_PrimitiveIDIn from storage buffers, so this stage has
// nothing to do. Prepended: "#version 450 core" + shared GLSL.

void main() {
}
