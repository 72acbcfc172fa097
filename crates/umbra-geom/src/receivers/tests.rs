//! The receiver map against brute force: every sample a triangle shadows keeps the triangle
//! and lies inside its clamped volume; named edge cases.

use super::*;
use crate::silhouette::VolumeClamp;

/// A small deterministic generator (xorshift), so the cases are the same on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn point(&mut self, lo: f64, hi: f64) -> [f32; 3] {
        [0; 3].map(|_| (lo + (hi - lo) * self.next()) as f32)
    }
}

/// Where the segment from `p` towards the light meets triangle `q`, strictly inside it and
/// strictly between the two: `Some((barycentrics, a))` with `p = L + a (x - L)` (point light)
/// or `p = x + a d` (directional, `d` the direction of travel), `x` the hit point. `None` when
/// it misses or the case is within 1e-9 of a boundary (the band's business, not the map's).
fn shadowed_by(p: [f64; 3], q: [[f64; 3]; 3], light: Light) -> Option<([f64; 3], f64)> {
    let (origin, dir) = if light[3] != 0.0 {
        let l = f64x3([light[0], light[1], light[2]]);
        (p, sub(l, p))
    } else {
        (p, f64x3([light[0], light[1], light[2]]))
    };
    // Möller-Trumbore in f64.
    let e1 = sub(q[1], q[0]);
    let e2 = sub(q[2], q[0]);
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let h = cross(dir, e2);
    let det = dot(e1, h);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = sub(origin, q[0]);
    let b1 = dot(s, h) / det;
    let qv = cross(s, e1);
    let b2 = dot(dir, qv) / det;
    let t = dot(e2, qv) / det;
    let b0 = 1.0 - b1 - b2;
    let eps = 1e-9;
    let upper = if light[3] != 0.0 { 1.0 - eps } else { f64::MAX };
    if b0 < eps || b1 < eps || b2 < eps || t < eps || t > upper {
        return None;
    }
    let x = [0, 1, 2].map(|j| origin[j] + dir[j] * t);
    let a = if light[3] != 0.0 {
        let l = f64x3([light[0], light[1], light[2]]);
        (dot(sub(p, l), sub(p, l)) / dot(sub(x, l), sub(x, l))).sqrt()
    } else {
        let d = travel(light);
        dot(sub(p, x), d)
    };
    Some(([b0, b1, b2], a))
}

/// The ray's parameter on the far cap `t'` of a triangle with far ends `k` (see clamp.rs):
/// the weighted harmonic mean (point light) or the weighted mean (directional).
fn far_parameter(b: [f64; 3], k: [f32; 3], point: bool) -> f64 {
    if point {
        1.0 / (0..3).map(|i| b[i] / k[i] as f64).sum::<f64>()
    } else {
        (0..3).map(|i| b[i] * k[i] as f64).sum()
    }
}

fn check_random_scene(light: Light, seed: u64) -> (usize, usize) {
    let mut rng = Rng(seed);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in 0..300u32 {
        let c = rng.point(-10.0, 10.0);
        for _ in 0..3 {
            let d = rng.point(-1.5, 1.5);
            positions.push([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
        }
        triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let mesh = WeldedMesh { positions, triangles, source_triangle: (0..300).collect(), degenerate_triangles: 0 };
    let samples: Vec<[f32; 3]> = (0..4000).map(|_| rng.point(-12.0, 12.0)).collect();
    let bounds = Aabb { min: [-12.0; 3], max: [12.0; 3] };
    let grid = ReceiverGrid::new(light, bounds, 32);
    let map = ReceiverMap::from_samples(grid, samples.iter().copied());
    let mut clamp = VolumeClamp::default();
    let stats = map.cull_and_clamp(&mesh, light, None, &mut clamp);
    assert_eq!(stats.kept, clamp.kept());
    let mut pairs = 0;
    for p in &samples {
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
            if let Some((b, a)) = shadowed_by(f64x3(*p), q, light) {
                pairs += 1;
                assert!(clamp.keep[t], "triangle {t} shadows the sample {p:?} but was dropped");
                let k = tri.map(|i| clamp.far[i as usize]);
                let end = far_parameter(b, k, light[3] != 0.0);
                assert!(a < end, "sample {p:?} at {a} is beyond triangle {t}'s far cap at {end} (far ends {k:?})");
            }
        }
    }
    (pairs, stats.kept)
}

#[test]
fn every_shadowed_sample_keeps_its_triangle_and_lies_inside_the_clamped_volume_point() {
    for seed in [1u64, 7, 12345] {
        let (pairs, kept) = check_random_scene([0.5, 3.0, -1.0, 1.0], seed);
        assert!(pairs > 500, "the scene must exercise the check: {pairs} pairs");
        assert!(kept < 300, "nothing was dropped: the test would not see a wrong drop");
    }
}

#[test]
fn every_shadowed_sample_keeps_its_triangle_and_lies_inside_the_clamped_volume_directional() {
    for seed in [3u64, 99] {
        let (pairs, _) = check_random_scene([0.3, 1.0, 0.2, 0.0], seed);
        assert!(pairs > 500, "the scene must exercise the check: {pairs} pairs");
    }
}

fn one_triangle() -> WeldedMesh {
    WeldedMesh {
        positions: vec![[-1.0, 5.0, -1.0], [1.0, 5.0, -1.0], [0.0, 5.0, 1.0]],
        triangles: vec![[0, 1, 2]],
        source_triangle: vec![0],
        degenerate_triangles: 0,
    }
}

#[test]
fn a_triangle_with_no_sample_behind_it_is_dropped() {
    let light = [0.0, 10.0, 0.0, 1.0];
    let bounds = Aabb { min: [-20.0; 3], max: [20.0; 3] };
    let mesh = one_triangle();
    // Samples beside the triangle's cone, and one in the cone but between light and triangle.
    let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), [[8.0, 0.0, 8.0], [0.0, 7.0, 0.0]]);
    let mut clamp = VolumeClamp::default();
    assert_eq!(map.cull_and_clamp(&mesh, light, None, &mut clamp).kept, 0);
    // A sample straight below it keeps it, with far ends beyond the sample.
    let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), [[0.0, 0.0, 0.0]]);
    assert_eq!(map.cull_and_clamp(&mesh, light, None, &mut clamp).kept, 1);
    // The sample is at distance 10, the triangle's nearest point at 5: k > 2 on every vertex.
    assert!(clamp.far.iter().all(|&k| k > 2.0 && k < 2.1), "{:?}", clamp.far);
}

#[test]
fn a_receiver_exactly_at_the_clamp_distance_and_one_an_ulp_beyond_are_both_enclosed() {
    // The farthest receiver decides the clamp; a second one an ulp farther in the same cell
    // raises the cell, so it is enclosed too.
    let light = [0.0, 10.0, 0.0, 1.0];
    let bounds = Aabb { min: [-20.0; 3], max: [20.0; 3] };
    let mesh = one_triangle();
    let at = [0.0f32, 0.0, 0.0];
    // One ulp of the distance 10 farther from the light.
    let beyond = [0.0f32, 10.0 - f32::from_bits(10.0f32.to_bits() + 1), 0.0];
    assert!(beyond[1] < 0.0);
    for samples in [vec![at], vec![at, beyond]] {
        let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), samples.clone());
        let mut clamp = VolumeClamp::default();
        map.cull_and_clamp(&mesh, light, None, &mut clamp);
        for p in samples {
            let q = mesh.triangles[0].map(|i| f64x3(mesh.positions[i as usize]));
            let (b, a) = shadowed_by(f64x3(p), q, light).expect("below the triangle");
            assert!(a < far_parameter(b, clamp.far.clone().try_into().unwrap(), true));
        }
    }
}

#[test]
fn a_cone_across_cube_faces_is_bounded_by_the_whole_map() {
    // A triangle around the light's +x/+y diagonal: its cone spans two faces, so its bound is
    // the largest value anywhere in the map: kept and clamped beyond it while a sample lies
    // beyond the triangle anywhere, dropped when every sample is nearer than the triangle.
    let light = [0.0, 0.0, 0.0, 1.0];
    let mesh = WeldedMesh {
        positions: vec![[5.0, 4.0, -1.0], [4.0, 5.0, -1.0], [4.5, 4.5, 1.0]],
        triangles: vec![[0, 1, 2]],
        source_triangle: vec![0],
        degenerate_triangles: 0,
    };
    let bounds = Aabb { min: [-20.0; 3], max: [20.0; 3] };
    let mut clamp = VolumeClamp::default();
    // Far from the cone (-z face), but farther than the triangle.
    let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), [[0.0, 0.0, -15.0], [9.0, 9.0, 0.0]]);
    let stats = map.cull_and_clamp(&mesh, light, None, &mut clamp);
    assert_eq!((stats.kept, stats.unclamped), (1, 0));
    let least = distance_to_triangle([0.0; 3], mesh.triangles[0].map(|i| f64x3(mesh.positions[i as usize])));
    assert!(clamp.far.iter().all(|&k| k as f64 > 15.0 / least), "{:?}", clamp.far);
    // Every sample nearer the light than the triangle: dropped.
    let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), [[0.0, 0.0, -2.0], [1.0, 1.0, 0.0]]);
    assert_eq!(map.cull_and_clamp(&mesh, light, None, &mut clamp).kept, 0);
}

#[test]
fn a_region_of_one_orientation_is_kept_whole_and_its_extra_triangles_enclose_nothing() {
    // A closed box over a sample, and a floor tile aside: only the box's triangles over the
    // sample need to cast, but the box's top is one region towards the light: it is kept
    // whole; the floor tile (no sample beyond it) is dropped.
    let light = [0.3, 10.0, 0.2, 1.0];
    let mut m = crate::scene::cuboid([0.0, 3.0, 0.0], [1.0, 0.5, 1.0]);
    m.append(&crate::scene::ground_plane([-3.5, 0.0, 0.0], 1.0));
    let mesh = crate::weld::weld(&m);
    let adj = crate::adjacency::EdgeAdjacency::build(&mesh);
    let slots = TriangleSlots::build(&mesh, &adj).expect("slots");
    let bounds = Aabb { min: [-5.0, -1.0, -5.0], max: [5.0, 5.0, 5.0] };
    // Under the box, on no geometry of the mesh (a receiver of another).
    let sample = [0.6f32, 0.0, 0.7];
    let map = ReceiverMap::from_samples(ReceiverGrid::new(light, bounds, 64), [sample]);
    let mut alone = VolumeClamp::default();
    let needed = map.cull_and_clamp(&mesh, light, None, &mut alone).kept;
    let mut whole = VolumeClamp::default();
    let kept = map.cull_and_clamp(&mesh, light, Some((&adj, &slots)), &mut whole).kept;
    assert!(needed > 0 && kept > needed, "needed {needed}, kept whole {kept}");
    let top: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&t| mesh.triangles[t].iter().all(|&v| mesh.positions[v as usize][1] > 3.4))
        .collect();
    assert_eq!(top.len(), 2);
    assert!(top.iter().all(|&t| whole.keep[t]), "the top is one region, kept whole");
    let floor: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&t| mesh.triangles[t].iter().all(|&v| mesh.positions[v as usize][1] == 0.0))
        .collect();
    assert!(floor.iter().all(|&t| !whole.keep[t]), "nothing lies beyond the floor");
    // Every triangle that shadows the sample keeps it inside its clamped volume.
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
        if let Some((b, a)) = shadowed_by(f64x3(sample), q, light) {
            assert!(whole.keep[t]);
            let k = tri.map(|i| whole.far[i as usize]);
            assert!(a < far_parameter(b, k, true), "triangle {t}");
        }
    }
    // Every vertex of a kept triangle has a far end beyond it.
    for (tri, &k) in mesh.triangles.iter().zip(&whole.keep) {
        if k {
            assert!(tri.iter().all(|&v| whole.far[v as usize] > 1.0), "{tri:?}");
        }
    }
}

#[test]
fn encode_preserves_order_and_decode_inverts_it() {
    let xs = [-1.0e30f32, -2.5, -0.0, 0.0, 1.0e-30, 3.0, 7.5e20];
    for w in xs.windows(2) {
        assert!(encode(w[0]) <= encode(w[1]), "{w:?}");
    }
    for x in xs {
        assert_eq!(decode(encode(x)).map(f32::to_bits), Some(x.to_bits()));
    }
    assert_eq!(decode(0), None);
}

#[test]
fn distance_to_triangle_matches_its_regions() {
    let q = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
    assert_eq!(distance_to_triangle([0.5, 0.5, 3.0], q), 3.0); // face
    assert_eq!(distance_to_triangle([-3.0, -4.0, 0.0], q), 5.0); // vertex a
    assert!((distance_to_triangle([1.0, -2.0, 0.0], q) - 2.0).abs() < 1e-12); // edge ab
    assert!((distance_to_triangle([2.0, 2.0, 0.0], q) - 2f64.sqrt()).abs() < 1e-12);
    // edge bc
}

/// [`clamp_beyond_box`]: every point of the box a triangle shadows lies inside its finite
/// volume, and no far end is infinite.
fn check_box_clamp(light: Light, seed: u64) -> usize {
    let mut rng = Rng(seed);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in 0..200u32 {
        let c = rng.point(-10.0, 10.0);
        for _ in 0..3 {
            let d = rng.point(-1.5, 1.5);
            positions.push([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
        }
        triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let mesh = WeldedMesh { positions, triangles, source_triangle: (0..200).collect(), degenerate_triangles: 0 };
    let bounds = Aabb { min: [-12.0; 3], max: [12.0; 3] };
    let mut clamp = VolumeClamp::default();
    let stats = clamp_beyond_box(&mesh, light, bounds, &mut clamp).expect("finite");
    assert_eq!(stats.kept, 200);
    assert!(clamp.far.iter().all(|f| f.is_finite() && *f > 0.0));
    let mut pairs = 0;
    // The box's corners and random points in it.
    let corners = (0..8).map(|c: u32| [0, 1, 2].map(|k| if c >> k & 1 == 0 { -12.0f32 } else { 12.0 }));
    let samples: Vec<[f32; 3]> = corners.chain((0..3000).map(|_| rng.point(-12.0, 12.0))).collect();
    for p in &samples {
        for tri in &mesh.triangles {
            let q = tri.map(|i| f64x3(mesh.positions[i as usize]));
            if let Some((b, a)) = shadowed_by(f64x3(*p), q, light) {
                pairs += 1;
                let k = tri.map(|i| clamp.far[i as usize]);
                let end = far_parameter(b, k, light[3] != 0.0);
                assert!(a < end, "box point {p:?} at {a} is beyond the far cap at {end} (far ends {k:?})");
            }
        }
    }
    pairs
}

#[test]
fn volumes_clamped_beyond_the_box_are_finite_and_hold_every_point_of_the_box_they_shadow() {
    for (light, seed) in [([0.5f32, 3.0, -1.0, 1.0], 5u64), ([20.0, 30.0, 5.0, 1.0], 6), ([0.3, 1.0, 0.2, 0.0], 8)] {
        let pairs = check_box_clamp(light, seed);
        assert!(pairs > 200, "the scene must exercise the check: {pairs} pairs");
    }
}

/// The GPU cull's uniform: the grid's parameters and side, faces, coarsest level and level
/// offsets where cull.wgsl reads them; the raised rectangle, face and value as
/// `hull_raise` gives them; a directional grid's widening twice `cells_of`'s.
#[test]
fn gpu_cull_words_lay_out_the_grid_the_raise_and_the_levels() {
    let bounds = Aabb { min: [-5.0, 0.0, -5.0], max: [5.0, 2.0, 5.0] };
    let cube = ReceiverGrid::new([0.5, 4.0, 0.5, 1.0], bounds, 256);
    let w = gpu_cull_words(&cube, None);
    assert_eq!(w[30..33], [256, 6, 8]);
    let offsets = gpu_cull_level_offsets(256);
    assert_eq!(offsets.len(), 10);
    assert_eq!(offsets[1], 6 * 256 * 256);
    assert_eq!(offsets[9], offsets[8] + 6, "the coarsest level: one cell per face");
    assert_eq!(w[36..45], offsets[..9]);
    assert_eq!(w[24..30], [0; 6], "nothing raised");
    let near = [[0.4, 1.0, 0.4], [0.6, 1.0, 0.4], [0.6, 1.0, 0.6], [0.4, 1.0, 0.6], [0.5, 1.2, 0.5]];
    let raise = cube.hull_raise(&near).expect("below the light: face -y bounds it");
    let w = gpu_cull_words(&cube, Some(raise));
    assert_eq!(w[24..28], raise.1);
    assert_eq!((w[28], decode(w[29])), (raise.0, Some(raise.2)));
    assert_eq!(raise.0, 3, "face -y");
    assert!(raise.2 > 3.0, "beyond the farthest point, 3.0 from the light");
    let flat = ReceiverGrid::new([0.3, 1.0, 0.2, 0.0], bounds, 128);
    let w = gpu_cull_words(&flat, None);
    assert_eq!(w[30..33], [128, 1, 7]);
    let ReceiverGrid::Flat { origin, travel, lo, scale, .. } = flat else { panic!("a directional grid") };
    assert_eq!(w[0..3], origin.map(f32::to_bits));
    assert_eq!(w[12..15], travel.map(f32::to_bits));
    assert_eq!(w[16..20], [lo[0], lo[1], scale[0], scale[1]].map(f32::to_bits));
    for j in 0..2 {
        let margin = f32::from_bits(w[20 + j]) as f64;
        let extent = 128.0 / scale[j] as f64;
        let cpu = (2.0 * extent + 2.0 * (lo[j] as f64).abs()) * RECEIVER_MARGIN;
        assert!((margin / cpu - 2.0).abs() < 1e-6, "axis {j}: {margin} against twice {cpu}");
    }
}
