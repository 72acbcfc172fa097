// ts-triangle (volume pass) and ts-triangle-1pass: fragment shader with fragment depths.
// Paper 001, Section 2.3: "We had to manually push the front cap's fragments into depth of
// 1.0f, so they would fail the depth test" (single-pass method); Section 2.1 (per-triangle
// volumes). Stage reason: in a tessellated per-triangle volume neither the light cap (1-pass:
// it shares its tessellated vertices with two sides) nor the sides (both methods: their
// triangulation and vertex order are the tessellator's, different in the two patches that cast
// the same side) can be given a consistent depth in the evaluation stage; here they can.
//
// Which face a fragment belongs to: every tessellated vertex carries e_corner, the one-hot
// vector of the patch point (0, 1, 2) it was placed at. A side of the edge between points i and
// i + 1 only has vertices of those two points, so component i + 2 is 0 at all its vertices and
// interpolates to exactly 0.0 on every fragment (also after clipping: the clipper interpolates
// 0 and 0). Caps (light or dark) have all three points; inside them every component is
// positive in exact arithmetic, but near an edge rounding can leave one at a tiny positive or
// negative value - hardly ever exactly 0.0. So "some component == 0.0" means side, anything else
// cap.
//
//   UMBRA_CAPS_TO_FAR        cap fragments get the far plane's depth (the 1-pass light cap;
//                            the dark cap is there already)
//   UMBRA_CANONICAL_SIDES    side fragments get the depth of their canonical plane
//                            (e_side_plane, the window-space depth function from
//                            shared/side_plane.glsl, evaluated in double), identical for both copies
// Without either define the shader writes no depth (early depth testing stays on): the
// paper's rasterized depths, kept only to measure what the depth writes cost.
//
// A side seen edge-on (flagged by shared/side_plane.glsl: its plane contains the eye up to rounding)
// has rays lying in its plane, crossing it nowhere, so it must not count; its
// rasterized coverage is a sliver that the two copies of a shared side need not even cover
// alike. Its fragments get u_edge_on_depth, a depth that is never counted: the near plane for z-fail (the
// face passes: KEEP), the far plane for z-pass (it fails: KEEP).
//
// The far plane is u_far_clip_z as a window depth (1 standard; 0 with a reversed zero-to-one
// range).
#version 450 core

in vec3 e_corner;
flat in dvec4 e_side_plane[3];

uniform float u_far_clip_z;
uniform float u_edge_on_depth;

// The wide counter (src/counter.rs): +1 for a front face, -1 for a back face, summed by
// blending into an R32F buffer under Counter::Float32; under Counter::Stencil8 the colour
// write mask is off and this output is ignored.
layout(location = 0) out float o_count;

#ifdef UMBRA_CANONICAL_SIDES
// The depth side i's canonical plane gives this fragment (u_edge_on_depth for a side seen
// edge-on), evaluated in double.
float side_depth(int i) {
    dvec4 r = e_side_plane[i];
    return r.w != 0.0LF ? u_edge_on_depth : float(r.x * double(gl_FragCoord.x) + r.y * double(gl_FragCoord.y) + r.z);
}
#endif

void main() {
    o_count = gl_FrontFacing ? 1.0 : -1.0;
#if defined(UMBRA_CAPS_TO_FAR) || defined(UMBRA_CANONICAL_SIDES)
    // A fragment whose interpolated depth is NaN comes from a triangle the rasterizer could
    // not set up (llvmpipe computes the interpolation planes from the float area of the
    // triangle after clipping, lp_state_setup.c; where that area rounds to 0 while the
    // fixed-point coverage does not, every interpolant is 0 * inf). Its coverage and facing
    // come from the fixed-point edges, like every other triangle's, so the volume stays closed
    // only if it counts like the face it belongs to; but neither its face (e_corner is NaN too)
    // nor its depth is known. It gets, of the depths its face could give it (each side's
    // canonical plane or edge-on depth, the far plane of a cap), the one nearest to the depth
    // that never counts: it counts exactly when every face it could belong to would count it.
    // Found twice: Crytek Sponza (fly-through keyframe 3, 1920x1080, pixel (1659, 779): a 3 cm
    // caster whose sides are seen as a 1,400-pixel sliver, in front of the sample: counted, a
    // stray -1) and Conference (directional light, 640x360, pixel (177, 230): a 1 cm caster's
    // tube 600 units behind the sample, one back face of its sides: not counted when such
    // fragments never counted, a stray -1). Tests pinned_depths.rs,
    // ts_triangle_fragment_with_nan_depth_*.
    if (isnan(gl_FragCoord.z)) {
        float chosen = u_far_clip_z;
#ifdef UMBRA_CANONICAL_SIDES
        for (int i = 0; i < 3; ++i) {
            float d = side_depth(i);
            if (abs(d - u_edge_on_depth) < abs(chosen - u_edge_on_depth)) {
                chosen = d;
            }
        }
#else
        chosen = u_edge_on_depth;
#endif
        gl_FragDepth = chosen;
        return;
    }
    bool cap = e_corner.x != 0.0 && e_corner.y != 0.0 && e_corner.z != 0.0;
    float depth = gl_FragCoord.z;
#ifdef UMBRA_CAPS_TO_FAR
    // A light cap in front of the camera's near plane (its depth clamped to the near value:
    // 0 standard, 1 reversed-Z) belongs to a caster the scene pass cut away there, so samples
    // behind it are visible: it keeps its near depth and passes the test, i.e. it is not
    // counted (shared/depth.glsl, near-plane cut). Elsewhere it goes to the far plane.
    bool before_near = u_far_clip_z == 1.0 ? gl_FragCoord.z <= 0.0 : gl_FragCoord.z >= 1.0;
    if (cap && !before_near) {
        depth = u_far_clip_z;
    }
#endif
#ifdef UMBRA_CANONICAL_SIDES
    if (!cap) {
        // Component i + 2 == 0 <=> side of edge (i, i + 1) <=> plane i.
        depth = side_depth(e_corner.z == 0.0 ? 0 : (e_corner.x == 0.0 ? 1 : 2));
    }
#endif
    gl_FragDepth = depth;
#endif
}
