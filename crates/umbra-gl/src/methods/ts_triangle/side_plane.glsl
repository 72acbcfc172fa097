// Canonical side planes for the tessellated per-triangle volumes (ts-triangle, ts-triangle-1pass).
// Paper 001, Section 2.1 (per-triangle volumes; Section 2.3 on pushing depths in the fragment
// shader), Eq. 2 (the side quad A B A' B' lies in the plane through A, B and the light).
// No #version line: spliced into the control shaders after the shared multiplicity.glsl.
//
// Why: two light-facing neighbours both cast the side of their shared edge, with opposite
// windings, and the two copies must cancel at EVERY sample, also where a receiver lies at the
// side's depth up to rounding. The tessellator decides the two copies' triangulation and vertex
// order (they differ: the same edge is A -> B in one patch and B -> A in the other), so their
// rasterized depths can differ in the last bit. Instead the fragment shader gives every side
// fragment the depth of the side's plane, computed here from the edge's endpoints in canonical
// order (A < B, umbra_greater) and the light with `precise` arithmetic: identical for both
// copies. The plane is returned in clip space (p . X_clip = 0), so the fragment shader only
// evaluates it at its window position (side_depth.frag.glsl).

uniform mat4 u_world_from_clip;

// World-space plane through A, B (w = 1) and the homogeneous light L, moved to clip space.
// n = (B - A) x (L.xyz - A * L.w) (the Y vector of Alg. 4), d = -n . A.
vec4 umbra_side_plane_clip(vec3 p, vec3 q, vec4 l) {
    bool forward = umbra_greater(p, q) < 0;
    vec3 a = forward ? p : q;
    vec3 b = forward ? q : p;
    UMBRA_PRECISE vec3 x = b - a;
    UMBRA_PRECISE vec3 y = vec3(l.x - a.x * l.w, l.y - a.y * l.w, l.z - a.z * l.w);
    UMBRA_PRECISE vec3 n = vec3(x.y * y.z - x.z * y.y, x.z * y.x - x.x * y.z, x.x * y.y - x.y * y.x);
    UMBRA_PRECISE float d = -(n.x * a.x + n.y * a.y + n.z * a.z);
    // p_world . X_world = p_world . (world_from_clip X_clip) = (p_world * world_from_clip) . X_clip
    UMBRA_PRECISE vec4 plane = vec4(n, d) * u_world_from_clip;
    return plane;
}
