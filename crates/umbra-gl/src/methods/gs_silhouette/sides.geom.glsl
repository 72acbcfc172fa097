// gs-silhouette sides, geometry stage: paper 001, Section 2.2 (multiplicity with the reference
// edge, Alg. 3-4; extrusion Eq. 2) in a geometry shader, the implementation the paper's
// Tables 1-5 and 8-9 compare the tessellation method against ("GS").
//
// One input point per edge patch (gl_PrimitiveIDIn = patch index). The patch is read from the
// SAME layout as ts-silhouette's (Fig. 4-5, ts_silhouette/patches.rs), bound as storage
// buffers: u_elements[patch * UMBRA_PATCH_STRIDE + (0: A, 1: B, 2: count vertex,
// 3.. : opposite vertices)] index the vertex buffer u_vertices (vec3 as 3 floats; the count
// vertex holds the number n of opposite vertices of this patch in x).
//
// m = sum of umbra_side_contribution over the patch's opposites (Alg. 3; with UMBRA_THREE_EDGE
// Peciva 2013's 3-edge test). |m| copies of the side quad Q0 Q1 Q2 Q3 = B A A_inf B_inf
// (m > 0) or A B B_inf A_inf (m < 0), umbra_geom::silhouette's winding, are emitted, each as
// the 4-vertex strip Q1 Q2 Q0 Q3: its triangles are Q1 Q2 Q0 and Q0 Q2 Q3, cpu-silhouette's
// two triangles (same diagonal Q0-Q2) wound the same way, and both START ON THE EDGE (w = 1):
// llvmpipe clips a triangle whose first vertex is at infinity (w = 0) into a fan that covers
// pixels along its clipped sides slightly differently (see ts_silhouette/sides.tesc.glsl).
// An edge with more opposites than UMBRA_PATCH_CAPACITY is split over several patches whose m
// add up (patches.rs), so |m| <= UMBRA_PATCH_CAPACITY and max_vertices = 4 * UMBRA_PATCH_CAPACITY
// respects GL_MAX_GEOMETRY_OUTPUT_VERTICES and GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS
// (checked at prepare).
//
// Every emitted vertex also carries the side's window depth function, flat
// (face_window_depth: its plane through Q0 Q1 Q2, or u_edge_on_depth seen edge-on;
// shared/side_plane.glsl), computed once per invocation: the fragment shader writes it as
// every fragment's depth (shared/face_depth.frag.glsl). It adds 6 components
// (a dvec3) to every output vertex: 10 with gl_Position (ts_silhouette/patches.rs,
// gs_capacity_limit).
//
// Defines (inserted at link time): UMBRA_PATCH_CAPACITY (K), UMBRA_PATCH_STRIDE (3 + K),
// UMBRA_ELEMENTS_BINDING, UMBRA_VERTICES_BINDING.
// Prepended: "#version 450 core", shared/multiplicity.glsl, shared/depth.glsl,
// silhouette_caps/determinism.glsl.

layout(points) in;
layout(triangle_strip, max_vertices = 4 * UMBRA_PATCH_CAPACITY) out;

layout(std430, binding = UMBRA_ELEMENTS_BINDING) readonly buffer Elements {
    uint u_elements[];
};
layout(std430, binding = UMBRA_VERTICES_BINDING) readonly buffer Vertices {
    float u_vertices[];
};

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;

flat out dvec3 face_window_depth;

vec3 patch_vertex(uint slot) {
    uint i = 3u * u_elements[uint(gl_PrimitiveIDIn) * uint(UMBRA_PATCH_STRIDE) + slot];
    return vec3(u_vertices[i], u_vertices[i + 1u], u_vertices[i + 2u]);
}

void main() {
    vec3 a = patch_vertex(0u);
    vec3 b = patch_vertex(1u);
    // Never read beyond the patch, whatever the count vertex says.
    int count = min(int(patch_vertex(2u).x), UMBRA_PATCH_CAPACITY);
    int m = 0;
    for (int i = 0; i < count; ++i) {
        m += umbra_side_contribution(a, b, patch_vertex(uint(3 + i)), u_light);
    }
    if (m == 0) {
        return;
    }
    vec3 first = m > 0 ? b : a;
    vec3 second = m > 0 ? a : b;
    vec4 q0 = umbra_clip_from_world_point(u_clip_from_world, vec4(first, 1.0));
    vec4 q1 = umbra_clip_from_world_point(u_clip_from_world, vec4(second, 1.0));
    vec4 q2 = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(second, u_light));
    vec4 q3 = umbra_clip_from_world_point(u_clip_from_world, umbra_extrude(first, u_light));
    dvec3 face = umbra_face_depth_of_plane(umbra_window_depth_plane(q0, q1, q2));
    int copies = abs(m);
    for (int c = 0; c < copies; ++c) {
        face_window_depth = face; // outputs are undefined after EmitVertex
        gl_ClipDistance[0] = 1.0; // sides: never clipped (shared/depth.glsl)
        gl_Position = q1;
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        face_window_depth = face; // outputs are undefined after EmitVertex
        gl_ClipDistance[0] = 1.0; // sides: never clipped (shared/depth.glsl)
        gl_Position = q2;
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        face_window_depth = face; // outputs are undefined after EmitVertex
        gl_ClipDistance[0] = 1.0; // sides: never clipped (shared/depth.glsl)
        gl_Position = q0;
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        face_window_depth = face; // outputs are undefined after EmitVertex
        gl_ClipDistance[0] = 1.0; // sides: never clipped (shared/depth.glsl)
        gl_Position = q3;
        UMBRA_SCENE_CLIP(gl_Position);
        EmitVertex();
        EndPrimitive();
    }
}
