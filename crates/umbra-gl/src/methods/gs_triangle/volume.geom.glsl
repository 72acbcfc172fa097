// gs-triangle: the shadow volume of every triangle, built in a geometry shader.
//
// Paper 001 (Milet, Kobrtek, Zemcik): Section 2.1 (per-triangle volumes; Section 3 compares
// the two-pass tessellation method against "a similar geometry shader implementation" - this
// one), Section 2.2-2.3 (orientation through the reference edge, Alg. 2-4, shared with caps:
// umbra_triangle_orientation), Eq. 2 (extrusion, umbra_extrude). Light caps pushed to the far
// plane: paper 003, Eq. 6 (umbra_push_to_far).
//
// Stage reason: one invocation per scene triangle sees the whole triangle and can emit its
// complete closed volume: 3 side quads + light cap + dark cap (at most 8 triangles, 24
// vertices, far below MAX_GEOMETRY_OUTPUT_VERTICES and its component limit).
//
// Every primitive is emitted as its own 3-vertex strip, so the rasterizer receives exactly the
// vertex order written here. Sides are emitted in one canonical order whichever triangle casts
// them, and the -1 sides in a second draw with glFrontFace(GL_CW) (u_pass = 1), exactly as in
// vs-triangle (see vs_triangle/volume.vert.glsl for why): with A < B in umbra_greater order,
// the side of an edge traversed A -> B (+1) and of one traversed B -> A (-1) are both the
// triangles (B, A, A_inf) (B, A_inf, B_inf), so the two copies two light-facing neighbours
// cast on their shared edge rasterize identically and cancel at every sample.
//
// Every emitted primitive also carries its face's window-space depth function, flat
// (face_window_depth, shared/side_plane.glsl): the fragment shader writes it as every fragment's
// depth (shared/face_depth.frag.glsl). This stage computes it because it is the one that knows which
// face a primitive is; sides: their plane from the edge's endpoints in canonical order (once
// per side, shared by its two triangles and identical for both copies of a shared side); caps:
// the far plane.

layout(triangles) in;
layout(triangle_strip, max_vertices = 24) out;

in vec3 v_world[];

// u_clip_from_world: declared in shared/side_plane.glsl (spliced before this body).
uniform vec4 u_light;
// z-fail needs the caps; z-pass does not (they could only ever fail the depth test).
uniform bool u_caps;
// 0: +1 sides and caps (glFrontFace CCW); 1: -1 sides only (glFrontFace CW).
uniform int u_pass;

// Same expression as the scene vertex shader for w = 1 vertices.
invariant gl_Position;

// The emitted face's window depth function (see the header); doubles must be flat.
flat out dvec3 face_window_depth;

void umbra_emit(vec4 world, bool push_to_far, dvec3 face) {
    // Written with every vertex: outputs are undefined after EmitVertex.
    face_window_depth = face;
    vec4 clip = u_clip_from_world * world;
    // Light caps: clipped at the near plane, then pushed (shared/depth.glsl); the rest never.
    UMBRA_NEAR_CLIP(push_to_far ? umbra_near_distance(clip) : 1.0);
    gl_Position = push_to_far ? umbra_push_to_far(clip) : clip;
    UMBRA_SCENE_CLIP(gl_Position);
    EmitVertex();
}

void umbra_triangle(vec4 a, vec4 b, vec4 c, bool push_to_far, dvec3 face) {
    umbra_emit(a, push_to_far, face);
    umbra_emit(b, push_to_far, face);
    umbra_emit(c, push_to_far, face);
    EndPrimitive();
}

// The side quad of edge p -> q of the light-facing winding, in canonical order, if its sign
// belongs to this draw.
void umbra_side(vec3 p, vec3 q) {
    bool forward = umbra_greater(p, q) < 0; // traversed A -> B: +1
    if (forward != (u_pass == 0)) {
        return;
    }
    vec3 a = forward ? p : q;
    vec3 b = forward ? q : p;
    vec4 A = vec4(a, 1.0);
    vec4 B = vec4(b, 1.0);
    vec4 A_inf = umbra_extrude(a, u_light);
    vec4 B_inf = umbra_extrude(b, u_light);
    dvec3 face = umbra_face_depth_of_plane(umbra_side_depth_plane(a, b, u_light));
    umbra_triangle(B, A, A_inf, false, face);
    umbra_triangle(B, A_inf, B_inf, false, face);
}

void main() {
    vec3 p0 = v_world[0];
    vec3 p1 = v_world[1];
    vec3 p2 = v_world[2];
    int o = umbra_triangle_orientation(p0, p1, p2, u_light);
    if (o == 0) {
        return; // edge-on or degenerate: casts nothing
    }
    if (o < 0) {
        vec3 s = p1;
        p1 = p2;
        p2 = s;
    }
    umbra_side(p0, p1);
    umbra_side(p1, p2);
    umbra_side(p2, p0);
    if (u_caps && u_pass == 0) {
        // Light cap: the triangle itself, facing the light, at the far plane.
        umbra_triangle(vec4(p0, 1.0), vec4(p1, 1.0), vec4(p2, 1.0), true, umbra_face_depth_far());
        if (u_light.w != 0.0) {
            // Dark cap at infinity, reversed (faces away from the light); zero area for a
            // directional light, so skipped there.
            umbra_triangle(umbra_extrude(p0, u_light), umbra_extrude(p2, u_light), umbra_extrude(p1, u_light), false, umbra_face_depth_far());
        }
    }
}
