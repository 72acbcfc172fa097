//! The envelope's size in a raster view: the depth margin along the view ray and the
//! lateral bound of snapping and plane equations.

use crate::clip_from_world_looking;

#[test]
fn depth_margin_is_two_depth_steps_along_the_view_ray() {
    use umbra_oracle::envelope::DEPTH_STEPS;
    use umbra_oracle::{DepthFormat, RasterView};
    // Standard infinite projection: window depth 1 - near / d on the axis, d(depth)/dd =
    // near / d^2. DEPTH24: r = 2^-24; a float buffer: r = 2^-23 for a face that may reach
    // depth 1 (GL 4.5 Section 14.6.5). The margin is DEPTH_STEPS r d^2 / near.
    let (eye, near) = ([0.0, 0.0, 0.0], 0.1);
    let mut view = RasterView::new(clip_from_world_looking(eye, [0.0, 0.0, -1.0], 60.0, 1.0, near));
    for (format, r) in [(DepthFormat::Fixed(24), 2f64.powi(-24)), (DepthFormat::Float32, 2f64.powi(-23))] {
        view.depth = format;
        for d in [1.0, 10.0, 100.0] {
            let expected = DEPTH_STEPS * r * d * d / near;
            let m = view.depth_margin([0.0, 0.0, -d], eye);
            assert!((m / expected - 1.0).abs() < 1e-6, "d = {d}: margin {m}, expected {expected}");
        }
    }
    // Behind the eye: no depth, no margin.
    assert_eq!(view.depth_margin([0.0, 0.0, 5.0], eye), 0.0);
}

#[test]
fn lateral_bound_is_the_snapping_and_llvmpipes_plane_equations() {
    use umbra_oracle::RasterView;
    let mut view = RasterView::new(clip_from_world_looking([0.0; 3], [0.0, 0.0, -1.0], 60.0, 16.0 / 9.0, 0.1));
    view.subpixel_bits = 8;
    // Two primitives snapped to 1/256 pixel: 2 sqrt 2 / 512; two plane equations with 8 f32
    // roundings of |grad z| (W + H) each: 16 2^-24 (W + H).
    let expected = 2.0 * 2f64.sqrt() / 512.0 + 16.0 * 2f64.powi(-24) * (1920.0 + 1080.0);
    assert!((view.lateral_pixels(1920, 1080) - expected).abs() < 1e-15);
    assert!(view.lateral_pixels(1920, 1080) < 0.01, "far below a pixel");
    // The footprint of a pixel 10 units down the axis: 2 tan(30 deg) 10 / 1080.
    let fp = view.footprint([0.0, 0.0, -10.0], 1920, 1080);
    assert!((fp - 2.0 * 30f64.to_radians().tan() * 10.0 / 1080.0).abs() < 1e-12, "{fp}");
}
