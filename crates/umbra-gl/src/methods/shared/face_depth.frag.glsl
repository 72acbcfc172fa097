// The depth of every fragment of the volume passes whose depth was rasterized (gs-triangle,
// vs-triangle, gs-silhouette, ts-silhouette and their -3edge variants with the silhouette caps,
// cpu-silhouette, cs-silhouette, and vs-silhouette in GLSL 4.50): its face's exact plane depth,
// not the rasterizer's interpolated one.
// Paper 001, Section 2.3 (depths set in the fragment shader). No #version line: spliced into
// the fragment shader after "#version 450 core".
//
// Why (docs/exactness.md): llvmpipe sets a triangle's interpolation planes up in f32
// from the clipped triangle (lp_state_setup.c), anchored at its first vertex. Two ways that
// depth goes wrong on volume faces, both seen on the shared scenes and pinned by tests:
// * NaN. Where the float area rounds to 0 while the fixed-point (8 sub-pixel bit) coverage
//   does not, every interpolant is 0 * inf = NaN, gl_FragCoord.z included; a NaN depth fails
//   every depth test, so z-fail never counts the fragment. Pinned: Conference, directional
//   light, 2560x1440, z-fail, pixel (686, 1010): a 3 mm x 1.29 m caster's volume lies behind
//   the floor sample and one of its faces came as NaN-depth fragments: 1 false-shadow sample
//   in gs-triangle, vs-triangle, gs-silhouette, ts-silhouette (and -3edge). Test
//   pinned_depths.rs, rasterized_depth_fragment_with_nan_depth_behind_the_sample_counts.
// * Finite but wrong. On a needle-shaped side (a 0.6-pixel edge whose extrusion runs to a
//   vanishing point behind the eye, clipped 1,000 pixels away) the f32 gradient carries a
//   relative error of about 2^-24 L^2 / 2A (L the longest side, A the area), here the depth of
//   the plane 0.165 pixel away: 1.28e-6 nearer than the plane, and a side 9.5e-4 units behind
//   the sample counted as in front. Pinned: Crytek Sponza default view, point light, 2560x1440,
//   z-fail, pixel (1590, 147): 1 false-shadow sample in cpu-, vs- and cs-silhouette. Test
//   pinned_depths.rs, needle_side_behind_the_sample_counts_behind_it. A band term for it
//   (4 * 2^-24 L^3 / 2A pixels, branch band-wip) made the band ten times larger and was dropped.
//
// So the stage that knows the face passes its window depth function f, flat
// (shared/side_plane.glsl: a side's plane, u_edge_on_depth for a side seen edge-on, the far
// plane for caps), and every fragment gets z = f.x x + f.y y + f.z, evaluated in double (with
// reversed-Z the depths of distant samples are tiny values a float sum would lose) at its
// pixel centre: the depth of the face's plane of the f32 clip-space corners, to the last bit
// of the f32 depth buffer, whatever the rasterizer's setup (ts-triangle does the same for its
// sides, ts_triangle/side_depth.frag.glsl). Coverage and facing stay the rasterizer's.
//
// depth_unchanged (GL 4.2 / ARB_conservative_depth): the written value is the plane depth the
// interpolated one approximates (strictly the qualifier promises gl_FragCoord.z itself; the two
// differ by the setup error only), so an implementation that honours the qualifier may keep its
// early depth and stencil tests, on its own interpolated depth (a GPU rasterizer's, exact on
// the NVIDIA H100 runs without this shader: docs/exactness.md). llvmpipe ignores the
// qualifier: Mesa's lp_state_fs.c (generate_fs_loop) picks a late depth test for every shader
// that writes gl_FragDepth, whatever its layout, and tests the written value: both
// reproductions above are exact with the qualifier (checked, Mesa 22.3.6). The cost is the
// late depth test and two double multiply-adds per fragment (docs/benchmarks.md).

layout(depth_unchanged) out float gl_FragDepth;

// The face's window depth function (shared/side_plane.glsl); doubles must be flat.
flat in dvec3 face_window_depth;

// Called once by the fragment shader's main(); the only write of gl_FragDepth.
void umbra_write_face_depth() {
    dvec3 f = face_window_depth;
    gl_FragDepth = float(f.x * double(gl_FragCoord.x) + f.y * double(gl_FragCoord.y) + f.z);
}
