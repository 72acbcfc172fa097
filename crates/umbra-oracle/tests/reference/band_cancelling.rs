//! The CANCELLING band part: two opposite faces of per-triangle volumes through a sample,
//! on an edge that casts nothing.

use crate::{ground_samples, run, single_sample_under_square, Scene};
use umbra_oracle::{reference, Bvh, SampleClass, Samples};

#[test]
fn ray_through_an_occluders_interior_edge_is_band_for_per_triangle_volumes_only() {
    use umbra_oracle::BandParts;
    // (0, 0, 0) -> light passes exactly through the occluder's diagonal (its two triangles'
    // shared edge, which casts nothing: both face the light). A silhouette method draws no
    // face there; a per-triangle method draws two opposite ones through the sample, which
    // cancel only if the depth test orders both alike: CANCELLING, nothing else.
    for (x, z) in [(0.0, 0.0), (0.5, 0.5)] {
        let mut scene = Scene::with_ground();
        scene.add_square_occluder(1.0, false);
        let r =
            run(&scene, &[[x, 0.0, z]], &[Scene::ground_triangle(x, z)], 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
        assert_eq!((r.class[0], r.parts[0]), (SampleClass::Shadowed, BandParts::CANCELLING), "({x}, {z})");
        assert!(!r.parts[0].intersects(BandParts::SILHOUETTE));
    }
    // Off the diagonal: nothing.
    assert_eq!(single_sample_under_square(0.5, 0.3), (SampleClass::Shadowed, false));
}

#[test]
fn sample_on_its_own_triangles_edge_is_band_where_faces_are_drawn() {
    use umbra_oracle::{reference_in_view, BandParts, RasterView};
    // Top-down orthographic view of ground_samples(): clip x = x / 3, clip y = -z / 3, w = 1,
    // so pixel centres are exactly the sample positions. Ground only, light above: all lit.
    // Pixel centres on a cell's diagonal lie on an edge shared by two ground triangles facing
    // the light: it casts nothing, but per-triangle methods draw two opposite faces through
    // it (CANCELLING). The ground's outer edges cast, but no centre comes within the lateral
    // bound of them (nor of a grid line x or z = integer: 0.5 pixel away).
    let scene = Scene::with_ground();
    let (pos, tri) = ground_samples();
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let samples = Samples { width: 60, height: 60, world_pos: &pos, triangle: &tri };
    let mut clip_from_world = [0.0f64; 16];
    clip_from_world[0] = 1.0 / 3.0; // x_clip from x
    clip_from_world[9] = -1.0 / 3.0; // y_clip from z (column 2, row 1)
    clip_from_world[15] = 1.0; // w = 1
    let view = RasterView::new(clip_from_world);
    let light = [0.0, 10.0, 0.0, 1.0];
    let eye = [0.0, 20.0, 5.0];
    let plain = reference(&mesh, &bvh, &samples, light, eye).unwrap();
    let r = reference_in_view(&mesh, &bvh, &samples, light, eye, Some(&view)).unwrap();
    assert_eq!(r.class, plain.class, "the view changes the band only");
    for py in 0..60usize {
        for px in 0..60usize {
            let on_diagonal = (px + py + 1) % 10 == 0;
            let parts = r.parts[py * 60 + px];
            assert_eq!(parts, if on_diagonal { BandParts::CANCELLING } else { BandParts::NONE }, "pixel ({px}, {py})");
        }
    }
}
