// Window-space depth functions of volume faces, evaluated in double precision in the fragment
// shader: the canonical side depths of the tessellated per-triangle volumes (ts-triangle,
// ts-triangle-1pass) and the face depth every other stencil volume pass gives all its
// fragments (gs-/vs-triangle, the silhouette methods and their caps; see umbra_face_depth_*
// below). Paper 001, Section 2.1 (per-triangle volumes; Section 2.3 on
// setting depths in the fragment shader), Eq. 2 (the side quad A B A' B' lies in the plane
// through A, B and the light).
// No #version line: spliced after the shared multiplicity.glsl and depth.glsl (u_far_clip_z)
// into the stage that knows the face (control, geometry or vertex shader).
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
//   extruded A, Eq. 2; the same f32 clip coordinates the rasterizer would get), as the 4D
//   cofactor vector p of the three homogeneous points - no matrix inverse, fine for points
//   behind the eye (w < 0) or at infinity (w = 0); z_ndc = -(p.x x_ndc + p.y y_ndc + p.w) / p.z.
//   Folded here with the viewport and depth-range transforms into the window-space depth
//   function z_window = r.x x_window + r.y y_window + r.z, all in double precision (GLSL 4.00):
//   with reversed-Z the depths of distant samples are tiny values that a float evaluation of
//   that sum would lose to cancellation; in double it is the plane of the rounded clip points
//   to ~1e-15, and the fragment shader only does two double multiply-adds.
// * edge-on: the side's plane contains the eye up to rounding (p.z negligible next to the other
//   coefficients): its rays lie in its plane and it must not count. Returned as the zero
//   plane (side_depth.frag.glsl tests p.z == 0).
//
// A computed depth breaks a tie between a side and the caster it was cast from (at pixels on
// their shared edge) independently of how the rasterizer breaks it for the caster; measured on
// the torture suite and the three real scenes this costs nothing outside the boundary band.
// (Keeping the rasterized depth within a pixel or two of the edge was tried and was worse:
// there the two copies of a shared side disagree again.)

uniform mat4 u_clip_from_world;
uniform vec2 u_viewport_size;
uniform vec2 u_depth_from_ndc;

double umbra_det3(dvec3 a, dvec3 b, dvec3 c) {
    UMBRA_PRECISE double d = a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
    return d;
}

// The window-space depth function of the plane through the clip-space points ac, bc, vc:
// (r.x, r.y, r.z, 0) with z_window = r.x x + r.y y + r.z; or (0, 0, 0, 1) if the plane is seen
// edge-on.
dvec4 umbra_window_depth_plane(vec4 ac, vec4 bc, vec4 vc) {
    dvec4 ad = dvec4(ac);
    dvec4 bd = dvec4(bc);
    dvec4 vd = dvec4(vc);
    dvec4 plane = dvec4(umbra_det3(ad.yzw, bd.yzw, vd.yzw), -umbra_det3(ad.xzw, bd.xzw, vd.xzw),
                  umbra_det3(ad.xyw, bd.xyw, vd.xyw), -umbra_det3(ad.xyz, bd.xyz, vd.xyz));
    // (A NaN plane - from non-finite input - fails the comparison and counts as edge-on.)
    bool edge_on = !(abs(plane.z) > 1e-6 * (abs(plane.x) + abs(plane.y) + abs(plane.w)));
    if (edge_on) {
        return dvec4(0.0LF, 0.0LF, 0.0LF, 1.0LF);
    }
    // z_ndc = n.x x_ndc + n.y y_ndc + n.w, x_ndc = x (2 / W) - 1, z_window = scale z_ndc + offset.
    UMBRA_PRECISE dvec4 n = -plane / plane.z;
    UMBRA_PRECISE double scale = double(u_depth_from_ndc.x);
    UMBRA_PRECISE double sx = 2.0LF / double(u_viewport_size.x);
    UMBRA_PRECISE double sy = 2.0LF / double(u_viewport_size.y);
    UMBRA_PRECISE dvec4 r = dvec4(scale * n.x * sx, scale * n.y * sy, scale * (n.w - n.x - n.y) + double(u_depth_from_ndc.y), 0.0LF);
    return r;
}

// (r.x, r.y, r.z, 0): z_window = r.x x + r.y y + r.z; or (0, 0, 0, 1) for a side seen edge-on.
// The side of edge p-q, computed from its endpoints in canonical order (identical for both
// copies of a shared side).
dvec4 umbra_side_depth_plane(vec3 p, vec3 q, vec4 l) {
    bool forward = umbra_greater(p, q) < 0;
    vec3 a = forward ? p : q;
    vec3 b = forward ? q : p;
    vec4 ac = u_clip_from_world * vec4(a, 1.0);
    vec4 bc = u_clip_from_world * vec4(b, 1.0);
    vec4 vc = u_clip_from_world * umbra_extrude(a, l);
    return umbra_window_depth_plane(ac, bc, vc);
}

// Face depths for every fragment of the volume passes whose depth was rasterized
// (docs/exactness.md). llvmpipe sets a triangle's interpolation planes up in f32 from the
// clipped triangle (lp_state_setup.c): where the float area rounds to 0 the depth is NaN and
// fails every depth test (Conference, directional light, 2560x1440, pixel (686, 1010); test
// pinned_depths.rs, rasterized_depth_fragment_with_nan_depth_*), and on a needle-shaped
// side clipped far away it is finite but off by the depth of a point 0.165 pixel away (Crytek
// Sponza, point light, 2560x1440, pixel (1590, 147); test
// needle_side_behind_the_sample_counts_behind_it). The stage that knows the face passes its
// depth function, flat, as a dvec3 f: z_window = f.x x_window + f.y y_window + f.z, and the
// fragment shader writes it as every fragment's gl_FragDepth (shared/face_depth.frag.glsl).
uniform float u_edge_on_depth;

// A side through the clip-space points ac, bc, vc (two of its corners on the caster edge, one
// extruded): its plane, or, seen edge-on, u_edge_on_depth, the depth that is never counted
// (near plane for z-fail, far plane for z-pass: its rays lie in its plane and cross it nowhere).
dvec3 umbra_face_depth_of_plane(dvec4 r) {
    return r.w != 0.0LF ? dvec3(0.0LF, 0.0LF, double(u_edge_on_depth)) : r.xyz;
}

// Light caps (pushed to the far plane, depth.glsl) and dark caps (at infinity, clamped to the
// far plane): the far plane's window depth, u_far_clip_z (1 standard, 0 reversed-Z).
dvec3 umbra_face_depth_far() {
    return dvec3(0.0LF, 0.0LF, double(u_far_clip_z));
}
