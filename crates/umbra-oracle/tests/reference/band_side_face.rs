//! The SIDE_FACE band part: a sample a silhouette's side face passes through, laterally or
//! within the depth margin of the view, and a sample touching a side-casting edge.

use crate::{clip_from_world_looking, single_sample_under_square, Scene, BG};
use umbra_oracle::{Bvh, SampleClass, Samples};

#[test]
fn sample_on_a_shadow_boundary_is_band() {
    // The shadow boundary on the ground is x = 10/9: the segment from there to the light grazes
    // the occluder's edge x = 1, so the edge's side face passes through the sample. Nearest f32
    // to 10/9 lies within 1e-7 of it: band, whatever its class.
    let (_, band) = single_sample_under_square(10.0 / 9.0, 0.0);
    assert!(band, "a sample on the shadow boundary must be band");
    // 1e-3 away (far above the 2^-20 relative margin, ~2e-5 here): a plain sample again.
    assert_eq!(single_sample_under_square(10.0 / 9.0 + 1e-3, 0.0), (SampleClass::Lit, false));
    assert_eq!(single_sample_under_square(10.0 / 9.0 - 1e-3, 0.0), (SampleClass::Shadowed, false));
}

/// The ground sample (x, 0, 0.3) under the square occluder at y = 1, point light (0, 10, 0)
/// (shadow boundary x = 10/9), rasterized alone at its own pixel of a 64x64 view from
/// (0, 20, 5) with near plane `near`: (class, band) with the view.
fn depth_limited_sample(x: f32, near: f64) -> (SampleClass, bool) {
    use umbra_oracle::{reference_in_view, RasterView};
    let mut view = RasterView::new(clip_from_world_looking([0.0, 20.0, 5.0], [0.0, 0.0, 0.0], 60.0, 1.0, near));
    view.subpixel_bits = 8;
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let eye = [0.0f32, 20.0, 5.0];
    let clip_from_world = clip_from_world_looking(eye.map(f64::from), [0.0, 0.0, 0.0], 60.0, 1.0, near);
    let s = [x, 0.0, 0.3];
    // The pixel S projects to.
    let m = &clip_from_world;
    let row = |r: usize| m[r] * f64::from(s[0]) + m[4 + r] * f64::from(s[1]) + m[8 + r] * f64::from(s[2]) + m[12 + r];
    let (px, py) = (((row(0) / row(3) + 1.0) * 32.0) as usize, ((1.0 - row(1) / row(3)) * 32.0) as usize);
    let mut pos = vec![[0.0f32; 3]; 64 * 64];
    let mut tri = vec![BG; 64 * 64];
    pos[py * 64 + px] = s;
    tri[py * 64 + px] = Scene::ground_triangle(s[0], s[2]);
    let samples = Samples { width: 64, height: 64, world_pos: &pos, triangle: &tri };
    assert_eq!(view.clip_from_world, clip_from_world);
    let r = reference_in_view(&mesh, &bvh, &samples, [0.0, 10.0, 0.0, 1.0], eye, Some(&view)).unwrap();
    (r.class[py * 64 + px], r.band[py * 64 + px])
}

#[test]
fn depth_limited_sample_near_a_boundary_is_band() {
    // 5e-3 beyond the boundary x = 10/9 at ~20.6 units from the eye (the side face ~4.5e-3
    // away). A 0.01 near plane makes 2 float depth steps there 2 * 2^-23 * 20.6^2 / 0.01 ~
    // 1e-2 units: the depth test cannot say on which side of the face the sample lies: band.
    // (The lateral bound, 2 sqrt 2 / 512 pixel of ~0.37 units, adds 2e-3.)
    assert_eq!(depth_limited_sample(10.0 / 9.0 + 5e-3, 0.01), (SampleClass::Lit, true));
    assert_eq!(depth_limited_sample(10.0 / 9.0 - 5e-3, 0.01), (SampleClass::Shadowed, true));
    // A 1.0 near plane: 1e-4 units of depth, 2.1e-3 in all: a plain sample.
    assert_eq!(depth_limited_sample(10.0 / 9.0 + 5e-3, 1.0), (SampleClass::Lit, false));
    assert_eq!(depth_limited_sample(10.0 / 9.0 - 5e-3, 1.0), (SampleClass::Shadowed, false));
    // Far from the boundary nothing changes, whatever the near plane.
    assert_eq!(depth_limited_sample(1.5, 0.01), (SampleClass::Lit, false));
}

/// A ground triangle at y = 0 and, under it, a vertical quad x = 1, y in [-1, 0], whose top
/// edge lies in the ground's plane (a T-junction: an object's face meeting a floor). Point
/// light (0, 10, 0) above: the quad's top edge is open, so it casts a side face, down and
/// away from the light, passing through the ground's plane along that edge. The sample
/// (1 + delta, 0, 0.3) on the ground is lit (nothing above it); seen from (0, 20, 5) with near
/// plane `near` at its own pixel of a 64x64 view: (class, band).
fn t_junction_sample(delta: f32, near: f64, flat_neighbour: bool) -> (SampleClass, umbra_oracle::BandParts) {
    use umbra_oracle::{reference_in_view, RasterView};
    let mut scene = Scene::new();
    let ground = scene.add([[-3.0, 0.0, -3.0], [-3.0, 0.0, 3.0], [3.0, 0.0, -3.0]]);
    scene.add([[3.0, 0.0, -3.0], [-3.0, 0.0, 3.0], [3.0, 0.0, 3.0]]);
    if flat_neighbour {
        // Instead of the vertical quad: a ground-level quad sharing the edge x = 1 with
        // another coplanar one. Their shared edge casts nothing.
        scene.add([[1.0, 0.0, -2.0], [1.0, 0.0, 2.0], [0.0, 0.0, 0.0]]);
        scene.add([[1.0, 0.0, 2.0], [1.0, 0.0, -2.0], [2.0, 0.0, 0.0]]);
    } else {
        scene.add([[1.0, 0.0, -2.0], [1.0, -1.0, -2.0], [1.0, -1.0, 2.0]]);
        scene.add([[1.0, 0.0, -2.0], [1.0, -1.0, 2.0], [1.0, 0.0, 2.0]]);
    }
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let eye = [0.0f32, 20.0, 5.0];
    let clip_from_world = clip_from_world_looking(eye.map(f64::from), [0.0, 0.0, 0.0], 60.0, 1.0, near);
    let s = [1.0 + delta, 0.0, 0.3];
    let m = &clip_from_world;
    let row = |r: usize| m[r] * f64::from(s[0]) + m[4 + r] * f64::from(s[1]) + m[8 + r] * f64::from(s[2]) + m[12 + r];
    let (px, py) = (((row(0) / row(3) + 1.0) * 32.0) as usize, ((1.0 - row(1) / row(3)) * 32.0) as usize);
    let mut pos = vec![[0.0f32; 3]; 64 * 64];
    let mut tri = vec![BG; 64 * 64];
    pos[py * 64 + px] = s;
    // The sample lies on the first ground triangle (x + z <= 0 ... no: pick by the diagonal).
    tri[py * 64 + px] = if s[0] + s[2] <= 0.0 { ground } else { ground + 1 };
    let samples = Samples { width: 64, height: 64, world_pos: &pos, triangle: &tri };
    let mut view = RasterView::new(clip_from_world);
    view.subpixel_bits = 8;
    let r = reference_in_view(&mesh, &bvh, &samples, [0.0, 10.0, 0.0, 1.0], eye, Some(&view)).unwrap();
    (r.class[py * 64 + px], r.parts[py * 64 + px])
}

#[test]
fn sample_touching_a_side_casting_edge_within_the_envelope_is_band() {
    use umbra_oracle::BandParts;
    // 5e-3 from the T-junction's edge; 2 float depth steps at ~20.6 units are 1e-2 units with a
    // 0.01 near plane: the side face through the edge cannot be ordered against the sample,
    // nor the quad itself (SURFACE: it meets the ground there, not in its plane).
    let both = BandParts::SIDE_FACE | BandParts::SURFACE;
    assert_eq!(t_junction_sample(5e-3, 0.01, false), (SampleClass::Lit, both));
    // With a 1.0 near plane (1e-4 units, 2.1e-3 with the lateral bound) it can.
    assert_eq!(t_junction_sample(5e-3, 1.0, false), (SampleClass::Lit, BandParts::NONE));
    // Half a unit away: plain, whatever the near plane.
    assert_eq!(t_junction_sample(0.5, 0.01, false), (SampleClass::Lit, BandParts::NONE));
    // The same distance from an edge shared by two coplanar triangles facing the light: that
    // edge casts no side face and the triangles lie in the sample's plane: only a
    // per-triangle method's cancelling pair passes there.
    assert_eq!(t_junction_sample(5e-3, 0.01, true), (SampleClass::Lit, BandParts::CANCELLING));
}
