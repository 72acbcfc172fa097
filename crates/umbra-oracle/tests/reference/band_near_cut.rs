//! The NEAR_CUT band part: the image of what the near plane cuts.

use crate::{clip_from_world_looking, Scene};
use umbra_oracle::{Bvh, Samples};

#[test]
fn cut_by_the_near_plane_marks_its_image() {
    use umbra_oracle::{reference_in_view, BandParts, RasterView};
    // Eye at the origin looking down -z, near plane 0.1. A back wall z = -10 fills the view
    // (every pixel a sample); a triangle crosses the near plane obliquely. Only pixels within
    // the lateral bound of the image of its cut are NEAR_CUT.
    let mut scene = Scene::new();
    let wall = scene.add([[-50.0, -50.0, -10.0], [50.0, -50.0, -10.0], [0.0, 50.0, -10.0]]);
    scene.add([[-0.03, -0.03, -0.05], [0.03, -0.01, -0.3], [0.005, 0.03, -0.15]]);
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let clip_from_world = clip_from_world_looking([0.0; 3], [0.0, 0.0, -1.0], 60.0, 1.0, 0.1);
    let view = RasterView::new(clip_from_world);
    let m = &clip_from_world;
    let row = |r: usize, p: [f64; 3]| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
    let (w, h) = (64u32, 64u32);
    let mut pos = Vec::new();
    for y in 0..h {
        for x in 0..w {
            // The wall point seen through pixel (x, y).
            let (nx, ny) = ((x as f64 + 0.5) / 32.0 - 1.0, 1.0 - (y as f64 + 0.5) / 32.0);
            let t = 10.0 * (30f64.to_radians()).tan();
            pos.push([(nx * t) as f32, (ny * t) as f32, -10.0]);
        }
    }
    let tri = vec![wall; (w * h) as usize];
    let samples = Samples { width: w, height: h, world_pos: &pos, triangle: &tri };
    let r = reference_in_view(&mesh, &bvh, &samples, [0.0, 5.0, 5.0, 1.0], [0.0; 3], Some(&view)).unwrap();
    // The cut: where the triangle's edges cross z = -0.1, projected.
    let v = [[-0.03, -0.03, -0.05], [0.03, -0.01, -0.3], [0.005, 0.03, -0.15]];
    let mut ends = Vec::new();
    for k in 0..3 {
        let (p, q): ([f64; 3], [f64; 3]) = (v[k], v[(k + 1) % 3]);
        let s = (-0.1 - p[2]) / (q[2] - p[2]);
        if (0.0..=1.0).contains(&s) {
            let c = [0, 1, 2].map(|i| p[i] + s * (q[i] - p[i]));
            ends.push([(row(0, c) / row(3, c) + 1.0) * 32.0, (1.0 - row(1, c) / row(3, c)) * 32.0]);
        }
    }
    assert_eq!(ends.len(), 2);
    let (a, b) = (ends[0], ends[1]);
    let reach = view.lateral_pixels(w, h);
    let mut marked = 0;
    for y in 0..h as usize {
        for x in 0..w as usize {
            let c = [x as f64 + 0.5, y as f64 + 0.5];
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let s = (((c[0] - a[0]) * dx + (c[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            let d = (c[0] - a[0] - s * dx).hypot(c[1] - a[1] - s * dy);
            let near_cut = r.parts[y * w as usize + x].contains(BandParts::NEAR_CUT);
            assert_eq!(near_cut, d <= reach, "pixel ({x}, {y}) {d} px from the cut");
            marked += near_cut as usize;
        }
    }
    assert!(marked > 0, "the cut crosses {:.0} pixels", (b[0] - a[0]).hypot(b[1] - a[1]));
}
