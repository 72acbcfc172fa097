// Shadow-map depth pass, geometry stage of the ONE-PASS (layered) cube map: paper 003's
// omnidirectional shadow-mapping baseline (Section 3.1, Tables 1-2) rendered with layered
// rendering (GL 4.5 §9.8, gl_Layer selects the cube face, §8.13 face order +X -X +Y -Y +Z -Z).
// Instanced geometry shader: invocation i renders cube face i. A triangle is dropped from a
// face when all three vertices lie outside the same side plane of that face's frustum (the
// clipper would discard it anyway; dropping it here saves llvmpipe the clipping setup), so a
// triangle usually reaches one or two faces, not six.
// No #version here: mod.rs prepends it.

layout(triangles, invocations = 6) in;
layout(triangle_strip, max_vertices = 3) out;

// Light clip space from world space, one matrix per cube face (built in mod.rs, face_rows()).
uniform mat4 u_face_clip_from_world[6];

void main() {
    mat4 m = u_face_clip_from_world[gl_InvocationID];
    vec4 c[3];
    for (int i = 0; i < 3; ++i) {
        c[i] = m * gl_in[i].gl_Position;
    }
    // Outside the same side plane (x < -w, x > w, y < -w, y > w) or behind the light (w < 0)
    // for all three vertices: invisible in this face.
    for (int k = 0; k < 2; ++k) {
        if (c[0][k] < -c[0].w && c[1][k] < -c[1].w && c[2][k] < -c[2].w) return;
        if (c[0][k] > c[0].w && c[1][k] > c[1].w && c[2][k] > c[2].w) return;
    }
    if (c[0].w < 0.0 && c[1].w < 0.0 && c[2].w < 0.0) return;
    for (int i = 0; i < 3; ++i) {
        // gl_Layer is a per-vertex output of the geometry stage: set it for every vertex.
        gl_Layer = gl_InvocationID;
        gl_Position = c[i];
        EmitVertex();
    }
    EndPrimitive();
}
