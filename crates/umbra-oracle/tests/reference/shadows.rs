//! Lit and shadowed samples on analytic scenes: point, homogeneous and directional lights,
//! occluders beyond the light, self-shadowing of coplanar and creased neighbours, the
//! background, typed errors on bad input, and the segment epsilon's scale.

use crate::{count, ground_samples, run, Scene, BG};
use umbra_oracle::{reference, segment_epsilon, Bvh, OracleError, SampleClass, Samples};

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
