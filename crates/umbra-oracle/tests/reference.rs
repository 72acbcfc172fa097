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
        // Band: no sample. The nearest pixel centres lie 0.05 from the boundary, while without
        // a view the envelope is only the position's rounding (2^-20 of ~20 units): a whole
        // pixel next to a shadow boundary is judged like any other (the 3x3 rule of earlier
        // versions would have excused 176 of them).
        // (Pixel centres on a ground cell's diagonal are CANCELLING band: see
        // sample_on_its_own_triangles_edge_is_band_where_faces_are_drawn.)
        assert!(r.parts.iter().all(|p| !p.intersects(umbra_oracle::BandParts::SILHOUETTE)), "flip = {flip}");
        assert_eq!(umbra_oracle::boundary_band(60, 60, &expected, &[false; 3600]).iter().filter(|&&b| b).count(), 176);
        // Far samples: corner is lit and not band, centre is shadowed and not band.
        assert_eq!((r.class[0], r.band[0]), (SampleClass::Lit, false));
        let centre = 30 * 60 + 30;
        assert_eq!(r.class[centre], SampleClass::Shadowed);
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
    assert!(r.parts.iter().all(|p| !p.intersects(umbra_oracle::BandParts::SILHOUETTE)));
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
    // 20 x 20 pixel centres inside, none near the boundary: no band (but the cancelling faces
    // of the ground's own diagonals).
    assert_eq!(count(&r.class, SampleClass::Shadowed), 400);
    assert!(r.parts.iter().all(|p| !p.intersects(umbra_oracle::BandParts::SILHOUETTE)));
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
/// (class, band for a silhouette method) of a 1x1 image.
fn single_sample_under_square(x: f32, z: f32) -> (SampleClass, bool) {
    let mut scene = Scene::with_ground();
    scene.add_square_occluder(1.0, false);
    let r = run(&scene, &[[x, 0.0, z]], &[Scene::ground_triangle(x, z)], 1, 1, [0.0, 10.0, 0.0, 1.0], [0.0, 20.0, 5.0]);
    (r.class[0], r.parts[0].intersects(umbra_oracle::BandParts::SILHOUETTE))
}

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

#[test]
fn crease_within_the_envelope_is_surface_band() {
    use umbra_oracle::BandParts;
    // A wall x = 0 standing on the ground; the light on the -x side, so ground samples at
    // x < 0 are lit. A sample 1e-6 from the crease (within 2^-20 of ~7 units, 7e-6) could be
    // seen on either surface by the depth pass, and the wall's light cap pushed to the far
    // plane assumes it hides what lies behind it: SURFACE. 1e-3 away it is plain.
    let band_at = |x: f32| {
        let mut scene = Scene::with_ground();
        let wall = [[0.0, 0.0, -3.0], [0.0, 0.0, 3.0], [0.0, 3.0, 3.0], [0.0, 3.0, -3.0]];
        scene.add([wall[0], wall[1], wall[2]]);
        scene.add([wall[0], wall[2], wall[3]]);
        let r = run(
            &scene,
            &[[x, 0.0, 0.3]],
            &[Scene::ground_triangle(x, 0.3)],
            1,
            1,
            [-1.0, 1.0, 0.0, 0.0],
            [-5.0, 5.0, 0.0],
        );
        (r.class[0], r.parts[0])
    };
    let (class, parts) = band_at(-1e-6);
    assert_eq!(class, SampleClass::Lit);
    assert!(parts.contains(BandParts::SURFACE), "{:?}", parts.names());
    let (class, parts) = band_at(-1e-3);
    assert_eq!((class, parts.intersects(BandParts::SURFACE)), (SampleClass::Lit, false), "{:?}", parts.names());
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

#[test]
fn sample_on_a_wall_seen_at_a_grazing_angle_has_a_stretched_envelope() {
    use umbra_oracle::{reference_in_view, BandParts, RasterView};
    // Crytek Sponza, torture pose 2 at 240 x 180 (eye 0.0099 outside a wall): pixel (116, 56)
    // holds a sample of a wall (triangle 63483, plane z = -1.5635) seen at ~6 degrees, 0.0007
    // pixel from the wall's edge x = -6.1289 on the screen but, along the wall, 4.7e-4 units
    // beyond it: inside the corner, where the perpendicular wall (triangle 63681, x = -6.1289)
    // shadows it. The rasterizer's snapping of the wall alone moves a sample that far: band. A
    // round envelope (lateral bound times the pixel's footprint, 4.6e-4 here) missed it by 2 %.
    let wall = [[-5.984375f32, 3.251953, -1.563476], [-6.128906, 3.251953, -1.563476], [-6.128906, 4.125, -1.563476]];
    let corner = [[-6.128906f32, 4.125, -1.563476], [-6.128906, 3.251953, -1.563476], [-6.128906, 3.251953, -1.419922]];
    let mut scene = Scene::new();
    let t = scene.add(wall);
    scene.add(corner);
    let mesh = scene.mesh();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles).unwrap();
    let eye = [5.431641f32, 4.555811, -0.2421875];
    let mut clip_from_world = clip_from_world_looking(
        eye.map(f64::from),
        [-5.0273436, 1.1539064, -1.671875],
        60.0,
        240.0 / 180.0,
        0.028966757,
    );
    // Reversed-Z with a float buffer, as rendered: clip z = near, window depth near / d.
    (clip_from_world[2], clip_from_world[6], clip_from_world[10], clip_from_world[14]) = (0.0, 0.0, 0.0, 0.028966757);
    let mut view = RasterView::new(clip_from_world);
    view.subpixel_bits = 8;
    let (w, h) = (240u32, 180u32);
    let (px, py) = (116usize, 56usize);
    let mut pos = vec![[0.0f32; 3]; (w * h) as usize];
    let mut tri = vec![BG; (w * h) as usize];
    pos[py * w as usize + px] = [-6.129376, 3.387719, -1.5634769];
    tri[py * w as usize + px] = t;
    let samples = Samples { width: w, height: h, world_pos: &pos, triangle: &tri };
    let r =
        reference_in_view(&mesh, &bvh, &samples, [-0.37890625, 4.0698245, -0.2421875, 1.0], eye, Some(&view)).unwrap();
    let i = py * w as usize + px;
    assert_eq!(r.class[i], SampleClass::Shadowed);
    assert!(r.parts[i].contains(BandParts::SURFACE), "{:?}", r.parts[i].names());
}
