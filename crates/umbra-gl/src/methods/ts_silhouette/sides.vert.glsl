// ts-silhouette sides, vertex stage: paper 001, Section 2.2, Fig. 4-5. Each element of an edge
// patch (A, B, count vertex, opposite vertices) fetches one vertex of the extended vertex
// buffer; this stage passes it through UNCHANGED (world space; the count vertex carries the
// number of opposite vertices in x), all the work is per patch in the control stage.
// Prepended: "#version 450 core" + shared GLSL.

layout(location = 0) in vec3 a_patch_vertex;

out vec3 v_patch_vertex;

void main() {
    v_patch_vertex = a_patch_vertex;
}
