//! Band parts the light decides: FACING (a sample whose facing towards the light is within
//! rounding), ORIENTATION (an occluder edge-on to the light) and REFERENCE_EPS (a sample lit
//! only by the reference's segment epsilon).

use crate::{run, Scene};
use umbra_oracle::SampleClass;

#[test]
fn grazing_samples_are_band() {
    // Ground normal (0,1,0); directional light (1, ly, 0): |N.L| / |N||L| = ly / sqrt(1 + ly^2).
    // FACING: the lighting pass's f32 dot product is good to 2^-20 (~1e-6); the ground cell's
    // f32 orientation (legs 1 and sqrt 2, light length 1) to 32 2^-24 sqrt 2 ~ 2.7e-6. Below
    // that the method's facing is rounding; above it, it is not.
    let scene = Scene::with_ground();
    let pos = vec![[0.3f32, 0.0, 0.2]];
    let tri = vec![Scene::ground_triangle(0.3, 0.2)];
    for (ly, grazing) in [(0.0f32, true), (1e-6, true), (-1e-6, true), (1e-4, false), (-1e-4, false), (1.0, false)] {
        let r = run(&scene, &pos, &tri, 1, 1, [1.0, ly, 0.0, 0.0], [0.0, 5.0, 0.0]);
        assert_eq!(r.band[0], grazing, "ly = {ly}");
        assert_eq!(r.parts[0].contains(umbra_oracle::BandParts::FACING), grazing, "ly = {ly}");
    }
    // Point light in the ground's plane.
    let r = run(&scene, &pos, &tri, 1, 1, [5.0, 0.0, 5.0, 1.0], [0.0, 5.0, 0.0]);
    assert!(r.band[0]);
}

#[test]
fn sample_lit_only_by_the_epsilon_is_band() {
    // A tiny occluder 2e-5 above the ground sample (eps = 1e-5 of the scene's ~8.5 scale is
    // 8.5e-5): the segment meets it at t < eps, so the sample is lit, by tolerance only: band.
    let mut scene = Scene::with_ground();
    let h = 2e-5f32;
    scene.add([[0.2, h, 0.2], [0.4, h, 0.2], [0.3, h, 0.4]]);
    let s = [0.3f32, 0.0, 0.27];
    let tri = [Scene::ground_triangle(s[0], s[2])];
    let r = run(&scene, &[s], &tri, 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    assert_eq!((r.class[0], r.band[0]), (SampleClass::Lit, true));
    // Its edge passing 1e-6 beside the segment (no hit) within eps: the side face of that open
    // edge passes within the sample's envelope (2^-20 of ~21 units, 2e-5): band.
    let p = [0, 1, 2].map(|k| f64::from(s[k]) + f64::from(h) / 10.0 * ([0.0, 10.0, 0.0][k] - f64::from(s[k])));
    let x_edge = (p[0] + 1e-6) as f32;
    let mut scene = Scene::with_ground();
    scene.add([[x_edge, h, 0.2], [x_edge + 0.1, h, 0.3], [x_edge, h, 0.4]]);
    let r = run(&scene, &[s], &tri, 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    assert_eq!((r.class[0], r.band[0]), (SampleClass::Lit, true));
    // Lifted to 1e-3 (beyond eps) it shadows the sample, robustly: not band.
    let mut scene = Scene::with_ground();
    scene.add([[0.2, 1e-3, 0.2], [0.4, 1e-3, 0.2], [0.3, 1e-3, 0.4]]);
    let r = run(&scene, &[s], &tri, 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    assert_eq!((r.class[0], r.band[0]), (SampleClass::Shadowed, false));
}

#[test]
fn occluder_edge_on_to_the_light_is_orientation_band() {
    use umbra_oracle::BandParts;
    // A wall in the plane x = 0 containing the point light (0, 5, 0): no f32 evaluation can
    // orient it towards the light, so a method may build its volume either way round. The
    // segment from a ground sample at x = 0 to the light runs inside the wall's plane and
    // crosses it: ORIENTATION. At x = 0.5 the segment stays clear of it.
    let parts_at = |x: f32| {
        let mut scene = Scene::with_ground();
        scene.add([[0.0, 0.5, -1.0], [0.0, 2.5, -1.0], [0.0, 0.5, 1.0]]);
        let r = run(
            &scene,
            &[[x, 0.0, 0.3]],
            &[Scene::ground_triangle(x, 0.3)],
            1,
            1,
            [0.0, 5.0, 0.0, 1.0],
            [5.0, 4.0, 6.0],
        );
        r.parts[0]
    };
    assert!(parts_at(0.0).contains(BandParts::ORIENTATION), "{:?}", parts_at(0.0).names());
    assert!(!parts_at(0.5).intersects(BandParts::ORIENTATION | BandParts::SIDE_FACE), "{:?}", parts_at(0.5).names());
}
