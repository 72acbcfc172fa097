// Canonical side depths for the tessellated per-triangle volumes (ts-triangle, ts-triangle-1pass).
// Paper 001, Section 2.1 (per-triangle volumes; Section 2.3 on setting depths in the fragment
// shader), Eq. 2 (the side quad A B A' B' lies in the plane through A, B and the light).
// No #version line: spliced into the control shaders after the shared multiplicity.glsl.
//
// Why: two light-facing neighbours both cast the side of their shared edge, with opposite
// windings, and the two copies must cancel at EVERY sample, also where a receiver lies at the
// side's depth up to rounding. The tessellator decides the two copies' triangulation and vertex
// order (they differ: the same edge is A -> B in one patch and B -> A in the other), so their
// rasterized depths can differ in the last bit. Instead the fragment shader gives every side
// fragment a depth computed here once per patch from the edge's endpoints in canonical order
// (A < B, umbra_greater): identical for both copies.
//
// How: the side's depth as an affine function of the window position, built the way the
// rasterizer builds the caster triangle's: from the window positions of A and B (same clip
// expression as the scene's vertex shader, divided by w, viewport-transformed and snapped to
// the 1/256-pixel grid like llvmpipe's setup), so that along the edge A B it reproduces the
// caster's own depths and a side judges the caster's surface next to its edge the way a
// rasterized side would. The slope across the edge comes from a third point of the plane, the
// vanishing point of the extrusion (A_inf, in homogeneous window coordinates, so w <= 0 is
// fine). z(P) = z_A + alpha (P.x - x_A) + beta (P.y - y_A), where
//   alpha dx + beta dy = dz        (d = B - A)
//   alpha ex + beta ey = ez        (e = V - A w_V, the direction towards the vanishing point)
// A side seen edge-on (d and e parallel on screen, or not finite) is flagged: its rays lie in
// its plane and it must not count (side_depth.frag.glsl).

uniform mat4 u_clip_from_world;
uniform vec2 u_viewport_size;
uniform vec2 u_depth_from_ndc;

vec3 umbra_window_snapped(vec4 clip) {
    float inv_w = 1.0 / clip.w;
    vec3 ndc = clip.xyz * inv_w;
    vec2 xy = ndc.xy * (0.5 * u_viewport_size) + 0.5 * u_viewport_size;
    xy = round(xy * 256.0) / 256.0;
    return vec3(xy, ndc.z * u_depth_from_ndc.x + u_depth_from_ndc.y);
}

// anchor = (x_A, y_A, z_A, edge_on ? 1 : 0), slope = (alpha, beta).
void umbra_side_depth_plane(vec3 p, vec3 q, vec4 l, out vec4 anchor, out vec2 slope) {
    bool forward = umbra_greater(p, q) < 0;
    vec3 a = forward ? p : q;
    vec3 b = forward ? q : p;
    vec4 a_clip = u_clip_from_world * vec4(a, 1.0);
    vec4 b_clip = u_clip_from_world * vec4(b, 1.0);
    vec4 v_clip = u_clip_from_world * umbra_extrude(a, l);
    UMBRA_PRECISE vec3 aw = umbra_window_snapped(a_clip);
    UMBRA_PRECISE vec3 bw = umbra_window_snapped(b_clip);
    UMBRA_PRECISE vec3 vh = vec3(
        (v_clip.x + v_clip.w) * (0.5 * u_viewport_size.x),
        (v_clip.y + v_clip.w) * (0.5 * u_viewport_size.y),
        v_clip.z * u_depth_from_ndc.x + v_clip.w * u_depth_from_ndc.y);
    UMBRA_PRECISE vec3 e = vh - aw * v_clip.w;
    UMBRA_PRECISE vec3 d = bw - aw;
    UMBRA_PRECISE float det = d.x * e.y - d.y * e.x;
    UMBRA_PRECISE float alpha = (d.z * e.y - d.y * e.z) / det;
    UMBRA_PRECISE float beta = (d.x * e.z - d.z * e.x) / det;
    bool edge_on = !(abs(det) > 1e-6 * (abs(d.x) + abs(d.y)) * (abs(e.x) + abs(e.y)))
        || isinf(alpha) || isnan(alpha) || isinf(beta) || isnan(beta) || isnan(aw.z) || isinf(aw.x) || isinf(aw.y);
    anchor = vec4(aw, edge_on ? 1.0 : 0.0);
    slope = vec2(alpha, beta);
}
