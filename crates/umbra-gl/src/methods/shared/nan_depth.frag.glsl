// The depth of NaN-depth fragments in the volume passes whose depth is rasterized (gs-triangle,
// vs-triangle, gs-silhouette, ts-silhouette and their -3edge variants with the silhouette caps,
// cpu-silhouette, cs-silhouette, and vs-silhouette in GLSL 4.50).
// Paper 001, Section 2.3 (depths set in the fragment shader). No #version line: spliced into
// the fragment shader after "#version 450 core".
//
// Why (issue 16; docs/exactness.md): llvmpipe computes a triangle's interpolation planes from
// the float area of the clipped triangle (lp_state_setup.c); where that area rounds to 0 while
// its fixed-point (8 sub-pixel bit) coverage does not, every interpolant is 0 * inf = NaN,
// gl_FragCoord.z included. The fragment's coverage and facing are right, so the volume stays
// closed only if it counts like its face; but a NaN depth fails every depth test. Found:
// Conference, directional light, 2560x1440, z-fail, pixel (686, 1010): a 3 mm x 1.29 m
// caster's volume lies behind the floor sample and one of its faces there came as NaN-depth
// fragments; z-fail did not count them: 1 false-shadow sample in gs-triangle, vs-triangle,
// gs-silhouette, ts-silhouette (and -3edge). Test method_per_triangle.rs,
// rasterized_depth_fragment_with_nan_depth_behind_the_sample_counts.
//
// So the stage that knows the face passes its window depth function f, flat
// (shared/side_plane.glsl: a side's plane, u_edge_on_depth for a side seen edge-on, the far
// plane for caps), and such a fragment gets z = f.x x + f.y y + f.z, evaluated in double (with
// reversed-Z the depths of distant samples are tiny values a float sum would lose).
//
// depth_unchanged (GL 4.2 / ARB_conservative_depth): every finite fragment keeps
// gl_FragCoord.z, so an implementation that honours the qualifier may keep early depth and
// stencil testing; only the NaN fragments, whose depth test is garbage anyway, get a new
// value (a GPU that tested its interpolated depth early under the qualifier would skip that
// repair, which is only known to be needed on llvmpipe). llvmpipe ignores the qualifier: Mesa's
// lp_state_fs.c (generate_fs_loop) picks a late depth test for every shader that writes
// gl_FragDepth, whatever its layout, and tests the written value: the reproduction above is
// exact with the qualifier (checked, Mesa 22.3.6), and the volume pass pays the late depth test
// (docs/exactness.md has the cost).

layout(depth_unchanged) out float gl_FragDepth;

// The face's window depth function (shared/side_plane.glsl); doubles must be flat.
flat in dvec3 face_window_depth;

void umbra_repair_nan_depth() {
    if (isnan(gl_FragCoord.z)) {
        dvec3 f = face_window_depth;
        gl_FragDepth = float(f.x * double(gl_FragCoord.x) + f.y * double(gl_FragCoord.y) + f.z);
    } else {
        gl_FragDepth = gl_FragCoord.z;
    }
}
