//! The shadow reference on analytic scenes whose shadows can be computed by hand.

use umbra_geom::WeldedMesh;
use umbra_oracle::{reference, segment_epsilon, Bvh, OracleError, Reference, SampleClass, Samples};

const BG: u32 = u32::MAX;

struct Scene {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Scene {
    fn new() -> Scene {
        Scene { positions: Vec::new(), triangles: Vec::new() }
    }
    fn add(&mut self, p: [[f32; 3]; 3]) -> u32 {
        // Shared positions are given the same index (a welded mesh).
        let mut idx = [0u32; 3];
        for (k, v) in p.iter().enumerate() {
            idx[k] = match self.positions.iter().position(|q| q == v) {
                Some(i) => i as u32,
                None => {
                    self.positions.push(*v);
                    self.positions.len() as u32 - 1
                }
            };
        }
        self.triangles.push(idx);
        self.triangles.len() as u32 - 1
    }
    /// Ground: the square [-3,3]^2 at y = 0 as a 6x6 grid of unit cells, each split into two
    /// triangles along the diagonal from (x1, z0) to (x0, z1), normal +y. Triangle ids 0..72.
    fn with_ground() -> Scene {
        let mut s = Scene::new();
        for j in 0..6 {
            for i in 0..6 {
                let (x0, z0) = (i as f32 - 3.0, j as f32 - 3.0);
                let (x1, z1) = (x0 + 1.0, z0 + 1.0);
                s.add([[x0, 0.0, z0], [x0, 0.0, z1], [x1, 0.0, z0]]);
                s.add([[x1, 0.0, z0], [x0, 0.0, z1], [x1, 0.0, z1]]);
            }
        }
        s
    }
    /// Id of the ground triangle containing (x, z) (points on the diagonal go to the first).
    fn ground_triangle(x: f32, z: f32) -> u32 {
        let i = ((x + 3.0).floor() as i32).clamp(0, 5) as u32;
        let j = ((z + 3.0).floor() as i32).clamp(0, 5) as u32;
        let (fx, fz) = (x + 3.0 - i as f32, z + 3.0 - j as f32);
        2 * (j * 6 + i) + if fx + fz <= 1.0 { 0 } else { 1 }
    }
    /// The square [-1,1]^2 at height y, two triangles, wound either way.
    fn add_square_occluder(&mut self, y: f32, flip: bool) {
        let mut q = [[-1.0, y, -1.0], [1.0, y, -1.0], [1.0, y, 1.0], [-1.0, y, 1.0]];
        if flip {
            q.reverse();
        }
        self.add([q[0], q[1], q[2]]);
        self.add([q[0], q[2], q[3]]);
    }
    fn mesh(&self) -> WeldedMesh {
        WeldedMesh {
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            source_triangle: (0..self.triangles.len() as u32).collect(),
            degenerate_triangles: 0,
        }
    }
}

/// A 60x60 image of ground samples: pixel (px, py) is the point (x, 0, z) with
/// x = -3 + 0.1 (px + 0.5), z = -3 + 0.1 (py + 0.5) (top row = smallest z).
fn ground_samples() -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    for py in 0..60 {
        for px in 0..60 {
            let (x, z) = (-3.0 + 0.1 * (px as f32 + 0.5), -3.0 + 0.1 * (py as f32 + 0.5));
            pos.push([x, 0.0, z]);
            tri.push(Scene::ground_triangle(x, z));
        }
    }
    (pos, tri)
}

fn run(scene: &Scene, pos: &[[f32; 3]], tri: &[u32], w: u32, h: u32, light: [f32; 4], eye: [f32; 3]) -> Reference {
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let samples = Samples { width: w, height: h, world_pos: pos, triangle: tri };
    reference(&mesh, &bvh, &samples, light, eye).unwrap()
}

/// Expected band from an expected class image: 3x3 neighbourhood (clipped) holds both classes.
fn band_of(class: &[SampleClass], w: usize, h: usize) -> Vec<bool> {
    let mut band = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            if class[y * w + x] == SampleClass::Background {
                continue;
            }
            let mut seen = (false, false);
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    match class[ny * w + nx] {
                        SampleClass::Lit => seen.0 = true,
                        SampleClass::Shadowed => seen.1 = true,
                        SampleClass::Background => {}
                    }
                }
            }
            band[y * w + x] = seen.0 && seen.1;
        }
    }
    band
}

fn count(class: &[SampleClass], c: SampleClass) -> usize {
    class.iter().filter(|&&k| k == c).count()
}

#[test]
fn point_light_above_square_occluder() {
    // Occluder [-1,1]^2 at y = 1, light at (0, 10, 0): the shadow on y = 0 is the similar square
    // scaled by 10 / (10 - 1), |x|, |z| < 10/9 = 1.111. Pixel centres nearest that boundary are
    // 1.05 (inside) and 1.15 (outside), far from it compared to any rounding.
    for flip in [false, true] {
        let mut scene = Scene::with_ground();
        scene.add_square_occluder(1.0, flip);
        let (pos, tri) = ground_samples();
        let r = run(&scene, &pos, &tri, 60, 60, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
        let expected: Vec<SampleClass> = pos
            .iter()
            .map(|p| if p[0].abs().max(p[2].abs()) < 10.0 / 9.0 { SampleClass::Shadowed } else { SampleClass::Lit })
            .collect();
        assert_eq!(r.class, expected, "flip = {flip}");
        // Shadowed: pixel centres -1.05..=1.05 on both axes, 22 x 22 = 484.
        assert_eq!(count(&r.class, SampleClass::Shadowed), 484);
        // Band: the inner ring of the 22x22 square (22*4 - 4 = 84) and the ring around it
        // (24*4 - 4 = 92; its corners see the inner square's corners diagonally) = 176.
        assert_eq!(r.band, band_of(&expected, 60, 60));
        assert_eq!(r.band.iter().filter(|&&b| b).count(), 176);
        // Far samples: corner is lit and not band, centre is shadowed and not band.
        assert_eq!((r.class[0], r.band[0]), (SampleClass::Lit, false));
        let centre = 30 * 60 + 30;
        assert_eq!((r.class[centre], r.band[centre]), (SampleClass::Shadowed, false));
    }
}

#[test]
fn occluder_beyond_a_point_light_casts_no_shadow() {
    // Light at y = 0.5, below the occluder at y = 1: the segments from the ground to the light
    // end before reaching the occluder. Nothing is shadowed, nothing is band.
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let (pos, tri) = ground_samples();
    let r = run(&scene, &pos, &tri, 60, 60, [0.0, 0.5, 0.0, 1.0], [0.0, 20.0, 5.0]);
    assert_eq!(count(&r.class, SampleClass::Lit), 3600);
    assert!(r.band.iter().all(|&b| !b));
}

#[test]
fn homogeneous_point_light_with_w_not_one_is_divided() {
    // (0, 20, 0, 2) is the point (0, 10, 0): same shadow as in point_light_above_square_occluder.
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let (pos, tri) = ground_samples();
    let r = run(&scene, &pos, &tri, 60, 60, [0.0, 20.0, 0.0, 2.0], [0.0, 20.0, 5.0]);
    assert_eq!(count(&r.class, SampleClass::Shadowed), 484);
}

#[test]
fn directional_light_shifts_the_shadow() {
    // Light from direction (1, 2, 0): from (x, 0, z) the ray (x + s, 2 s, z) meets y = 1 at
    // s = 0.5, so the sample is shadowed iff |x + 0.5| < 1 and |z| < 1, i.e. x in (-1.5, 0.5).
    // Nearest pixel centres: x = -1.45 / -1.55, 0.45 / 0.55, z = +-0.95 / +-1.05.
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let (pos, tri) = ground_samples();
    let r = run(&scene, &pos, &tri, 60, 60, [1.0, 2.0, 0.0, 0.0], [0.0, 20.0, 5.0]);
    let expected: Vec<SampleClass> = pos
        .iter()
        .map(|p| if (p[0] + 0.5).abs() < 1.0 && p[2].abs() < 1.0 { SampleClass::Shadowed } else { SampleClass::Lit })
        .collect();
    assert_eq!(r.class, expected);
    // 20 x 20 pixel centres inside.
    assert_eq!(count(&r.class, SampleClass::Shadowed), 400);
    assert_eq!(r.band, band_of(&expected, 60, 60));
}

#[test]
fn side_facing_away_from_the_light_is_shadowed() {
    // A lone ground: no occluder at all, so only the plane test can shadow.
    let scene = Scene::with_ground();
    let pos = vec![[0.3, 0.0, 0.2]];
    let tri = vec![Scene::ground_triangle(0.3, 0.2)];
    let class = |light, eye| run(&scene, &pos, &tri, 1, 1, light, eye).class[0];
    // Seen from above, light below: the seen side faces away.
    assert_eq!(class([0.0, -5.0, 0.0, 1.0], [0.0, 5.0, 0.0]), SampleClass::Shadowed);
    assert_eq!(class([0.2, -1.0, 0.1, 0.0], [0.0, 5.0, 0.0]), SampleClass::Shadowed);
    // Seen from below with the light below: two-sided, the underside is lit.
    assert_eq!(class([0.0, -5.0, 0.0, 1.0], [1.0, -3.0, 0.0]), SampleClass::Lit);
    // Seen from below, light above.
    assert_eq!(class([0.0, 5.0, 0.0, 1.0], [1.0, -3.0, 0.0]), SampleClass::Shadowed);
    // Same side.
    assert_eq!(class([0.0, 5.0, 0.0, 1.0], [1.0, 3.0, 0.0]), SampleClass::Lit);
}

#[test]
fn no_self_shadowing_by_coplanar_neighbours() {
    // Samples exactly on shared grid vertices, cell edges and cell diagonals, given either
    // adjacent triangle's id, and samples a little off the plane (as GPU interpolation gives),
    // with a low light: 0.01 rad above the horizon (not grazing: 0.01 > 1e-4). The
    // segment to the light starts inside/on the neighbouring coplanar triangles; only the eps
    // and the projection onto the plane keep them from shadowing the sample. eps here is
    // 1e-5 * 8.49 ~ 8.5e-5, while a sample 1e-6 below the plane would meet its neighbour about
    // 1e-6 / 0.01 = 1e-4 > eps along the ray: it is the projection that saves it.
    let scene = Scene::with_ground();
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    for (x, z) in [(0.0f32, 0.0f32), (1.0, -2.0), (0.5, 0.0), (0.0, 0.25), (0.5, 0.5), (-1.25, -0.75)] {
        for dy in [0.0f32, 1e-6, -1e-6] {
            // Every triangle the point touches (on the closed triangle, in exact arithmetic).
            for (id, t) in scene.triangles.iter().enumerate() {
                let [a, b, c] = t.map(|k| scene.positions[k as usize]);
                let e = |p: [f32; 3], q: [f32; 3]| (q[0] - p[0]) * (z - p[2]) - (q[2] - p[2]) * (x - p[0]);
                let (u, v, w) = (e(a, b), e(b, c), e(c, a));
                if (u <= 0.0 && v <= 0.0 && w <= 0.0) || (u >= 0.0 && v >= 0.0 && w >= 0.0) {
                    pos.push([x, dy, z]);
                    tri.push(id as u32);
                }
            }
        }
    }
    // A grid vertex touches up to 6 triangles: plenty of samples sit on shared edges.
    assert!(pos.len() > 40, "{}", pos.len());
    for light in [[1.0, 0.01, 0.3, 0.0], [-300.0, 3.0, 100.0, 1.0]] {
        let r = run(&scene, &pos, &tri, pos.len() as u32, 1, light, [0.0, 4.0, 9.0]);
        for (i, c) in r.class.iter().enumerate() {
            assert_eq!(*c, SampleClass::Lit, "sample {:?} on triangle {} with light {light:?}", pos[i], tri[i]);
        }
    }
}

#[test]
fn concave_crease_neighbour_does_shadow() {
    // A wall in the plane x = 0 (z in [-3,3], y in [0,3]) standing on the ground, sharing the
    // crease x = 0, y = 0 with it. Light from direction (-1, 1, 0): a ground point (x, 0, z)
    // with 0 < x < 3 sends its ray (x - s, s, z) into the wall at height x < 3: shadowed,
    // even at x = 1e-3 (10 eps from the crease). Points with x < 0 are on the light's side.
    let mut scene = Scene::with_ground();
    let wall = [[0.0, 0.0, -3.0], [0.0, 0.0, 3.0], [0.0, 3.0, 3.0], [0.0, 3.0, -3.0]];
    let w0 = scene.add([wall[0], wall[1], wall[2]]);
    scene.add([wall[0], wall[2], wall[3]]);
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    let mut expected = Vec::new();
    for (x, shadowed) in [(1e-3f32, true), (0.01, true), (0.5, true), (2.9, true), (-1e-3, false), (-0.5, false)] {
        pos.push([x, 0.0, 0.3]);
        tri.push(Scene::ground_triangle(x, 0.3));
        expected.push(if shadowed { SampleClass::Shadowed } else { SampleClass::Lit });
    }
    // A wall sample seen from the +x side, light on the -x side: facing away, shadowed.
    pos.push([0.0, 1.0, 0.5]);
    tri.push(w0);
    expected.push(SampleClass::Shadowed);
    let n = pos.len() as u32;
    let r = run(&scene, &pos, &tri, n, 1, [-1.0, 1.0, 0.0, 0.0], [5.0, 5.0, 0.0]);
    assert_eq!(r.class, expected);
}

#[test]
fn grazing_samples_are_band() {
    // One-pixel images, so no neighbour can put the sample in the band: band == grazing.
    // Ground normal (0,1,0); directional light (1, ly, 0): |N.L| / |N||L| = ly / sqrt(1 + ly^2).
    let scene = Scene::with_ground();
    let pos = vec![[0.3f32, 0.0, 0.2]];
    let tri = vec![Scene::ground_triangle(0.3, 0.2)];
    for (ly, grazing) in [(0.0f32, true), (1e-5, true), (-1e-5, true), (1e-3, false), (1.0, false)] {
        let r = run(&scene, &pos, &tri, 1, 1, [1.0, ly, 0.0, 0.0], [0.0, 5.0, 0.0]);
        assert_eq!(r.band[0], grazing, "ly = {ly}");
    }
    // Point light in the ground's plane.
    let r = run(&scene, &pos, &tri, 1, 1, [5.0, 0.0, 5.0, 1.0], [0.0, 5.0, 0.0]);
    assert!(r.band[0]);
}

#[test]
fn background_is_neither_sample_nor_band() {
    let scene = Scene::with_ground();
    let pos = vec![[0.0; 3], [0.3, 0.0, 0.2], [0.0; 3]];
    let tri = vec![BG, Scene::ground_triangle(0.3, 0.2), BG];
    let r = run(&scene, &pos, &tri, 3, 1, [1.0, 1.0, 0.0, 0.0], [0.0, 5.0, 0.0]);
    assert_eq!(r.class, vec![SampleClass::Background, SampleClass::Lit, SampleClass::Background]);
    assert_eq!(r.band, vec![false; 3]);
}

#[test]
fn bad_input_gives_typed_errors() {
    let scene = Scene::with_ground();
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let pos = vec![[0.3f32, 0.0, 0.2]; 4];
    let tri = vec![0u32; 4];
    let ok_light = [0.0, 5.0, 0.0, 1.0];
    let eye = [0.0, 5.0, 0.0];

    let s = Samples { width: 2, height: 3, world_pos: &pos, triangle: &tri };
    assert_eq!(
        reference(&mesh, &bvh, &s, ok_light, eye).unwrap_err(),
        OracleError::SizeMismatch { what: "world_pos", expected: 6, actual: 4, width: 2, height: 3 }
    );
    let bad_tri = vec![0, 0, 0, 72];
    let s = Samples { width: 2, height: 2, world_pos: &pos, triangle: &bad_tri };
    assert_eq!(
        reference(&mesh, &bvh, &s, ok_light, eye).unwrap_err(),
        OracleError::TriangleOutOfRange { x: 1, y: 1, triangle: 72, triangles: 72 }
    );
    let mut nan_pos = pos.clone();
    nan_pos[2][1] = f32::NAN;
    let s = Samples { width: 2, height: 2, world_pos: &nan_pos, triangle: &tri };
    assert!(matches!(reference(&mesh, &bvh, &s, ok_light, eye), Err(OracleError::NonFiniteSample { x: 0, y: 1, .. })));
    let s = Samples { width: 2, height: 2, world_pos: &pos, triangle: &tri };
    for light in [[0.0, 0.0, 0.0, 0.0], [f32::NAN, 1.0, 0.0, 1.0]] {
        assert!(matches!(reference(&mesh, &bvh, &s, light, eye), Err(OracleError::InvalidLight { .. })));
    }
    assert!(matches!(
        reference(&mesh, &bvh, &s, ok_light, [f32::INFINITY, 0.0, 0.0]),
        Err(OracleError::InvalidEye { .. })
    ));
    let other = Bvh::build(&mesh.positions, &mesh.triangles[..10]).unwrap();
    assert_eq!(
        reference(&mesh, &other, &s, ok_light, eye).unwrap_err(),
        OracleError::BvhMismatch { bvh: 10, mesh: 72 }
    );
}

#[test]
fn epsilon_scales_with_the_scene() {
    // Diagonal of [-3,3]x[0,0]x[-3,3] = 8.485; largest coordinate 3: eps = 1e-5 * 8.485.
    let scene = Scene::with_ground();
    let eps = segment_epsilon(&scene.positions);
    assert!((eps - 1e-5 * 72f64.sqrt()).abs() < 1e-12, "{eps}");
    // Far from the origin the absolute coordinates dominate (f32 rounding grows with them).
    let far: Vec<[f32; 3]> = scene.positions.iter().map(|p| [p[0] + 1000.0, p[1], p[2]]).collect();
    assert!((segment_epsilon(&far) - 1e-5 * 1003.0).abs() < 1e-9);
    assert_eq!(segment_epsilon(&[]), 0.0);
}

/// One ground sample at (x, 0, z) under the square occluder at y = 1, point light (0, 10, 0):
/// (class, band) of a 1x1 image, where the 3x3 rule cannot put anything in the band.
fn single_sample_under_square(x: f32, z: f32) -> (SampleClass, bool) {
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let r = run(&scene, &[[x, 0.0, z]], &[Scene::ground_triangle(x, z)], 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    (r.class[0], r.band[0])
}

#[test]
fn near_boundary_sample_is_band_where_the_3x3_rule_sees_one_class() {
    // The shadow boundary on the ground is x = 10/9: the segment from there to the light grazes
    // the occluder's edge x = 1. Nearest f32 to 10/9 lies within 1e-7 of it: band, whatever
    // its class.
    let (_, band) = single_sample_under_square(10.0 / 9.0, 0.0);
    assert!(band, "a sample on the shadow boundary must be band");
    // 1e-3 away (far above the 2^-20 relative margin, ~2e-5 here): a plain sample again.
    assert_eq!(single_sample_under_square(10.0 / 9.0 + 1e-3, 0.0), (SampleClass::Lit, false));
    assert_eq!(single_sample_under_square(10.0 / 9.0 - 1e-3, 0.0), (SampleClass::Shadowed, false));
}

#[test]
fn ray_through_an_occluders_interior_edge_is_not_band() {
    // (0, 0, 0) -> light passes exactly through the occluder's diagonal (its two triangles'
    // shared edge): near an edge of each triangle, yet every nearby segment is occluded.
    assert_eq!(single_sample_under_square(0.0, 0.0), (SampleClass::Shadowed, false));
    assert_eq!(single_sample_under_square(0.5, 0.5), (SampleClass::Shadowed, false));
}

#[test]
fn snapped_samples_on_their_own_triangles_edge_are_band() {
    use umbra_oracle::{reference_in_view, RasterView};
    // Top-down orthographic view of ground_samples(): clip x = x / 3, clip y = -z / 3, w = 1,
    // so pixel centres are exactly the sample positions. Ground only, light above: all lit.
    let scene = Scene::with_ground();
    let (pos, tri) = ground_samples();
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let samples = Samples { width: 60, height: 60, world_pos: &pos, triangle: &tri };
    let mut clip_from_world = [0.0f64; 16];
    clip_from_world[0] = 1.0 / 3.0; // x_clip from x
    clip_from_world[9] = -1.0 / 3.0; // y_clip from z (column 2, row 1)
    clip_from_world[15] = 1.0; // w = 1
    let view = RasterView { clip_from_world };
    let light = [0.0, 10.0, 0.0, 1.0];
    let eye = [0.0, 20.0, 5.0];
    let plain = reference(&mesh, &bvh, &samples, light, eye).unwrap();
    assert!(plain.band.iter().all(|&b| !b), "without the view nothing is band");
    let r = reference_in_view(&mesh, &bvh, &samples, light, eye, Some(&view)).unwrap();
    assert_eq!(r.class, plain.class, "the view changes the band only");
    // Pixel centres on a cell's diagonal x + z = integer: px + py + 1 a multiple of 10. No
    // centre comes near a grid line x or z = integer (0.5 pixel away).
    for py in 0..60usize {
        for px in 0..60usize {
            let on_diagonal = (px + py + 1) % 10 == 0;
            assert_eq!(r.band[py * 60 + px], on_diagonal, "pixel ({px}, {py})");
        }
    }
}

/// GL's perspective with an infinite far plane (standard depth convention, NEGATIVE_ONE_TO_ONE)
/// looking from `eye` at `target` (up +y), column-major clip_from_world.
fn clip_from_world_looking(eye: [f64; 3], target: [f64; 3], fovy_degrees: f64, aspect: f64, near: f64) -> [f64; 16] {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let unit = |a: [f64; 3]| {
        let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|c| c / l)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let f = unit(sub(target, eye));
    let r = unit(cross(f, [0.0, 1.0, 0.0]));
    let u = cross(r, f);
    // view_from_world rows: r, u, -f; translation -R eye.
    let view = [r, u, f.map(|c| -c)];
    let t = [-dot(r, eye), -dot(u, eye), dot(f, eye)];
    let g = 1.0 / (fovy_degrees.to_radians() / 2.0).tan();
    // clip rows: x = g/aspect * xv, y = g * yv, z = -zv - 2 near, w = -zv.
    let mut m = [0.0; 16];
    for col in 0..4 {
        let v = |row: usize| if col < 3 { view[row][col] } else { t[row] };
        m[col * 4] = g / aspect * v(0);
        m[col * 4 + 1] = g * v(1);
        m[col * 4 + 2] = -v(2) - if col == 3 { 2.0 * near } else { 0.0 };
        m[col * 4 + 3] = -v(2);
    }
    m
}

#[test]
fn depth_margin_is_a_few_depth_steps_along_the_view_ray() {
    use umbra_oracle::{RasterView, DEPTH_QUANTA};
    // Standard infinite projection: window depth 1 - near / d on the axis, d(depth)/dd =
    // near / d^2, depth steps of 2^-24 (24-bit, and f32 just below 1): the margin is
    // DEPTH_QUANTA 2^-24 d^2 / near.
    let (eye, near) = ([0.0, 0.0, 0.0], 0.1);
    let view = RasterView { clip_from_world: clip_from_world_looking(eye, [0.0, 0.0, -1.0], 60.0, 1.0, near) };
    for d in [1.0, 10.0, 100.0] {
        let expected = DEPTH_QUANTA / 16_777_216.0 * d * d / near;
        let m = view.depth_margin([0.0, 0.0, -d], eye);
        assert!((m / expected - 1.0).abs() < 1e-6, "d = {d}: margin {m}, expected {expected}");
    }
    // Behind the eye: no depth, no margin.
    assert_eq!(view.depth_margin([0.0, 0.0, 5.0], eye), 0.0);
}

/// The ground sample (x, 0, 0.3) under the square occluder at y = 1, point light (0, 10, 0)
/// (shadow boundary x = 10/9), rasterized alone at its own pixel of a 64x64 view from
/// (0, 20, 5) with near plane `near`: (class, band) with the view.
fn depth_limited_sample(x: f32, near: f64) -> (SampleClass, bool) {
    use umbra_oracle::{reference_in_view, RasterView};
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
    let r = reference_in_view(&mesh, &bvh, &samples, [0.0, 10.0, 0.0, 1.0], eye, Some(&RasterView { clip_from_world }))
        .unwrap();
    (r.class[py * 64 + px], r.band[py * 64 + px])
}

#[test]
fn depth_limited_sample_near_a_boundary_is_band() {
    // 1e-3 beyond the boundary x = 10/9 at ~20.6 units from the eye. A 0.01 near plane makes
    // 4 depth steps there 4 * 2^-24 * 20.6^2 / 0.01 ~ 1e-2 units: the depth test cannot say on
    // which side of the volume's side face the sample lies: band.
    assert_eq!(depth_limited_sample(10.0 / 9.0 + 1e-3, 0.01), (SampleClass::Lit, true));
    assert_eq!(depth_limited_sample(10.0 / 9.0 - 1e-3, 0.01), (SampleClass::Shadowed, true));
    // A 1.0 near plane: 1e-4 units, far below 1e-3: a plain sample.
    assert_eq!(depth_limited_sample(10.0 / 9.0 + 1e-3, 1.0), (SampleClass::Lit, false));
    assert_eq!(depth_limited_sample(10.0 / 9.0 - 1e-3, 1.0), (SampleClass::Shadowed, false));
    // Far from the boundary nothing changes, whatever the near plane.
    assert_eq!(depth_limited_sample(1.5, 0.01), (SampleClass::Lit, false));
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
    // Its edge passing 1e-6 beside the segment (no hit) within eps: a method may still count
    // the sample in the occluder's volume (the probes moved by the ~2e-5 margin hit it): band.
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
fn side_face_seen_edge_on_marks_its_line() {
    use umbra_oracle::edge_on::{mark_edge_on, side_casting_edges, EDGE_ON_PIXELS};
    use umbra_oracle::RasterView;
    // The square occluder's edge x = 1 (y = 1) and the light (0, 10, 0) span the plane
    // x = 1 - (y - 1) / 9. An eye in that plane sees the edge's side face edge-on: its image
    // is a line of the 64x64 image; every sample pixel within EDGE_ON_PIXELS of it is marked.
    let mut scene = Scene::new();
    scene.add_square_occluder(1.0, false);
    let mesh = scene.mesh();
    let light = [0.0, 10.0, 0.0, 1.0];
    let run_at = |eye: [f64; 3]| {
        let clip_from_world = clip_from_world_looking(eye, [1.0, 0.0, 0.0], 60.0, 1.0, 0.1);
        let view = RasterView { clip_from_world };
        let mut band = vec![false; 64 * 64];
        let casting = side_casting_edges(&mesh, light);
        let faces = mark_edge_on(&mesh, &casting, light, eye, &view, 64, 64, &mut band, |_| true);
        (faces, band, clip_from_world)
    };
    let in_plane = [1.0 - 19.0 / 9.0, 20.0, 5.0];
    let (faces, band, m) = run_at(in_plane);
    assert_eq!(faces, 1, "only the x = 1 edge's side face is edge-on");
    // The plane's image: project two points of the plane (the wedge's foot on the ground lies
    // on it too), then compare per pixel. Only the face's own extent is marked.
    let project = |p: [f64; 3]| {
        let row = |r: usize| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
        [(row(0) / row(3) + 1.0) * 32.0, (1.0 - row(1) / row(3)) * 32.0]
    };
    let (a, b) = (project([10.0 / 9.0, 0.0, -3.0]), project([10.0 / 9.0, 0.0, 3.0]));
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy);
    let mut marked = 0;
    for y in 0..64 {
        for x in 0..64 {
            if band[y * 64 + x] {
                let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
                let d = ((cx - a[0]) * dy - (cy - a[1]) * dx).abs() / len;
                assert!(d < EDGE_ON_PIXELS + 1e-6, "pixel ({x}, {y}) marked {d} px from the line");
                marked += 1;
            }
        }
    }
    // Points of the face itself (L + s ((1, 1, 0) - L), s > 1): their pixels are marked.
    for s in [1.02, 1.05, 1.1] {
        let p = project([s, 10.0 - 9.0 * s, 0.0]);
        let (x, y) = (p[0] as usize, p[1] as usize);
        assert!(band[y * 64 + x], "face point s = {s} at pixel ({x}, {y}) not marked");
    }
    assert!(marked >= 20, "a piece of line: {marked} pixels");
    // One unit out of the plane, the face is seen at a visible angle: nothing is marked.
    let (faces, band, _) = run_at([in_plane[0] - 1.0, 20.0, 5.0]);
    assert_eq!(faces, 0);
    assert!(band.iter().all(|&b| !b));
}

/// A ground triangle at y = 0 and, under it, a vertical quad x = 1, y in [-1, 0], whose top
/// edge lies in the ground's plane (a T-junction: an object's face meeting a floor). Point
/// light (0, 10, 0) above: the quad's top edge is open, so it casts a side face, down and
/// away from the light, passing through the ground's plane along that edge. The sample
/// (1 + delta, 0, 0.3) on the ground is lit (nothing above it); seen from (0, 20, 5) with near
/// plane `near` at its own pixel of a 64x64 view: (class, band).
fn t_junction_sample(delta: f32, near: f64, flat_neighbour: bool) -> (SampleClass, bool) {
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
    let r = reference_in_view(&mesh, &bvh, &samples, [0.0, 10.0, 0.0, 1.0], eye, Some(&RasterView { clip_from_world }))
        .unwrap();
    (r.class[py * 64 + px], r.band[py * 64 + px])
}

#[test]
fn sample_touching_a_side_casting_edge_within_a_depth_step_is_band() {
    // 1e-3 from the T-junction's edge; 4 depth steps at ~20.6 units are 1e-2 units with a 0.01
    // near plane: the side face through the edge cannot be ordered against the sample.
    assert_eq!(t_junction_sample(1e-3, 0.01, false), (SampleClass::Lit, true));
    // With a 1.0 near plane (1e-4 units) it can: a plain sample.
    assert_eq!(t_junction_sample(1e-3, 1.0, false), (SampleClass::Lit, false));
    // Half a unit away: plain, whatever the near plane.
    assert_eq!(t_junction_sample(0.5, 0.01, false), (SampleClass::Lit, false));
    // The same distance from an edge shared by two coplanar triangles facing the light: that
    // edge casts no side face, so the sample is plain.
    assert_eq!(t_junction_sample(1e-3, 0.01, true), (SampleClass::Lit, false));
}
