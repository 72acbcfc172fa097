// Canonical side depths for the tessellated per-triangle volumes (ts-triangle, ts-triangle-1pass).
// Paper 001, Section 2.1 (per-triangle volumes; Section 2.3 on setting depths in the fragment
// shader), Eq. 2 (the side quad A B A' B' lies in the plane through A, B and the light).
// No #version line: spliced into the control shaders after the shared multiplicity.glsl.
//
// Why: two light-facing neighbours both cast the side of their shared edge, with opposite
// windings, and the two copies must cancel at EVERY sample, also where a receiver lies at the
// side's depth up to rounding. The tessellator decides the two copies' triangulation and vertex
// order (they differ: the same edge is A -> B in one patch and B -> A in the other), so their
// rasterized depths can differ in the last bit. So the fragment shader gives side fragments a
// depth computed here once per patch from the edge's endpoints in canonical order (A < B,
// umbra_greater): identical for both copies.
//
// What is computed, per side:
// * plane: the side's plane in clip space, through the clip-space points A, B and A_inf (the
//   extruded A, Eq. 2), as the 4D cofactor vector of the three homogeneous points - no matrix
//   inverse, no division, fine for points behind the eye (w < 0) or at infinity (w = 0). At a
//   fragment, z_ndc = -(p.x x_ndc + p.y y_ndc + p.w) / p.z.
// * line: the edge A B projected to the window, a homogeneous 2D line scaled so that
//   |line . (x, y, 1)| is the distance in pixels. Next to its own edge a side is compared
//   with the caster triangle's rasterized surface, which meets it there: that comparison must
//   use the side's own rasterized depth (built from the same clipped vertices A, B as the
//   caster's), or a computed depth may break the tie the other way than the rasterizer.
// * edge_on: the side's plane contains the eye (p.z negligible) or the edge projects to a
//   point: its rays lie in its plane and it must not count.

uniform mat4 u_clip_from_world;
uniform vec2 u_viewport_size;

float umbra_det3(vec3 a, vec3 b, vec3 c) {
    UMBRA_PRECISE float d = a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
    return d;
}

// plane = (p.x, p.y, p.z, p.w) in clip space; line = (l.x, l.y, l.z, edge_on ? 1 : 0).
void umbra_side_depth_plane(vec3 p, vec3 q, vec4 l, out vec4 plane, out vec4 line) {
    bool forward = umbra_greater(p, q) < 0;
    vec3 a = forward ? p : q;
    vec3 b = forward ? q : p;
    vec4 ac = u_clip_from_world * vec4(a, 1.0);
    vec4 bc = u_clip_from_world * vec4(b, 1.0);
    vec4 vc = u_clip_from_world * umbra_extrude(a, l);
    plane = vec4(umbra_det3(ac.yzw, bc.yzw, vc.yzw), -umbra_det3(ac.xzw, bc.xzw, vc.xzw),
                 umbra_det3(ac.xyw, bc.xyw, vc.xyw), -umbra_det3(ac.xyz, bc.xyz, vc.xyz));
    vec2 half_size = 0.5 * u_viewport_size;
    UMBRA_PRECISE vec3 aw = vec3((ac.xy + ac.w) * half_size, ac.w);
    UMBRA_PRECISE vec3 bw = vec3((bc.xy + bc.w) * half_size, bc.w);
    UMBRA_PRECISE vec3 lw = cross(aw, bw);
    float scale = length(lw.xy);
    bool edge_on = !(abs(plane.z) > 1e-6 * (abs(plane.x) + abs(plane.y) + abs(plane.w))) || !(scale > 0.0);
    line = vec4(lw / scale, edge_on ? 1.0 : 0.0);
}
