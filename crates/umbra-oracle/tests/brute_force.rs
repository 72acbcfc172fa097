//! BVH queries against brute force over every triangle with the same watertight test: the BVH
//! may only prune, never change an answer.

use proptest::prelude::*;
use umbra_oracle::watertight::ShearedRay;
use umbra_oracle::{Bvh, OracleError};

/// Closest hit by testing every triangle; ties (equal t) keep the lowest id.
fn brute_closest(
    p: &[[f32; 3]],
    t: &[[u32; 3]],
    o: [f64; 3],
    d: [f64; 3],
    t_min: f64,
    t_max: f64,
) -> Option<(f64, u32)> {
    let ray = ShearedRay::new(o, d);
    let mut best: Option<(f64, u32)> = None;
    for (i, tri) in t.iter().enumerate() {
        let [a, b, c] = tri.map(|k| p[k as usize]);
        if let Some(h) = ray.intersect(a, b, c, t_min, t_max) {
            if best.is_none_or(|(bt, _)| h < bt) {
                best = Some((h, i as u32));
            }
        }
    }
    best
}

fn brute_any(p: &[[f32; 3]], t: &[[u32; 3]], o: [f64; 3], d: [f64; 3], t_min: f64, t_max: f64, ignore: u32) -> bool {
    let ray = ShearedRay::new(o, d);
    t.iter().enumerate().any(|(i, tri)| {
        let [a, b, c] = tri.map(|k| p[k as usize]);
        i as u32 != ignore && ray.intersect(a, b, c, t_min, t_max).is_some()
    })
}

/// Checks one ray against brute force: same closest t, a triangle that really is hit at that t,
/// and the same any-hit answer with and without an ignored triangle.
fn check_ray(
    bvh: &Bvh,
    p: &[[f32; 3]],
    t: &[[u32; 3]],
    o: [f64; 3],
    d: [f64; 3],
    t_min: f64,
    t_max: f64,
) -> Result<(), TestCaseError> {
    let expected = brute_closest(p, t, o, d, t_min, t_max);
    let got = bvh.intersect(o, d, t_min, t_max);
    match (expected, got) {
        (None, None) => {}
        (Some((et, _)), Some(h)) => {
            prop_assert_eq!(h.t, et);
            let [a, b, c] = t[h.triangle as usize].map(|k| p[k as usize]);
            prop_assert_eq!(ShearedRay::new(o, d).intersect(a, b, c, t_min, t_max), Some(et));
        }
        (e, g) => prop_assert!(false, "brute force {:?}, bvh {:?}", e, g),
    }
    prop_assert_eq!(bvh.occluded(o, d, t_min, t_max, u32::MAX), expected.is_some());
    if let Some((_, id)) = expected {
        prop_assert_eq!(bvh.occluded(o, d, t_min, t_max, id), brute_any(p, t, o, d, t_min, t_max, id));
    }
    Ok(())
}

fn soup(n: usize) -> impl Strategy<Value = (Vec<[f32; 3]>, Vec<[u32; 3]>)> {
    // Small triangles scattered in a box: each triangle has its own three vertices, plus some
    // shared-vertex fans (index reuse) to mimic welded meshes.
    let coord = -10.0f32..10.0;
    let vert = [coord.clone(), coord.clone(), coord];
    (prop::collection::vec(vert, 3 * n), prop::collection::vec(any::<u32>(), n)).prop_map(move |(v, shared)| {
        let mut p: Vec<[f32; 3]> = v;
        let mut t = Vec::with_capacity(n);
        for (i, &share) in shared.iter().enumerate() {
            let base = 3 * i as u32;
            // Shrink the triangle around its first vertex so they do not all overlap.
            for k in 1..3 {
                let a = p[base as usize];
                let q = &mut p[(base + k) as usize];
                for c in 0..3 {
                    q[c] = a[c] + (q[c] - a[c]) * 0.2;
                }
            }
            let first = if share % 4 == 0 && i > 0 { share % base } else { base };
            t.push([first, base + 1, base + 2]);
        }
        (p, t)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]


    #[test]
    fn bvh_matches_brute_force(
        (p, t) in soup(300),
        o in [-12.0f64..12.0, -12.0f64..12.0, -12.0f64..12.0],
        targets in prop::collection::vec([-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0], 20),
        t_min in prop_oneof![Just(0.0), 0.0f64..0.5],
        t_max in prop_oneof![Just(f64::INFINITY), 0.5f64..2.0],
    ) {
        let bvh = Bvh::build(&p, &t).unwrap();
        prop_assert_eq!(bvh.triangle_count(), t.len());
        for target in targets {
            let d = [target[0] - o[0], target[1] - o[1], target[2] - o[2]];
            check_ray(&bvh, &p, &t, o, d, t_min, t_max)?;
        }
        // Rays aimed at vertices (rays through shared vertices of the fans).
        for &v in p.iter().step_by(7) {
            let d = [v[0] as f64 - o[0], v[1] as f64 - o[1], v[2] as f64 - o[2]];
            check_ray(&bvh, &p, &t, o, d, 0.0, f64::INFINITY)?;
        }
    }

    #[test]
    fn axis_parallel_rays_match_brute_force(
        (p, t) in soup(100),
        o in [-12.0f64..12.0, -12.0f64..12.0, -12.0f64..12.0],
        axis in 0usize..3,
        sign in prop_oneof![Just(1.0f64), Just(-1.0f64)],
    ) {
        // Zero direction components exercise the infinite / NaN slabs of the box test.
        let bvh = Bvh::build(&p, &t).unwrap();
        let mut d = [0.0; 3];
        d[axis] = sign;
        check_ray(&bvh, &p, &t, o, d, 0.0, f64::INFINITY)?;
        // Origin exactly on a vertex's coordinate plane: slab (min - o) * inf = NaN.
        let v = p[0];
        let o2 = [v[0] as f64, v[1] as f64, v[2] as f64];
        let o2 = [0, 1, 2].map(|k| if k == axis { o[k] } else { o2[k] });
        check_ray(&bvh, &p, &t, o2, d, 0.0, f64::INFINITY)?;
    }
}

#[test]
fn large_soup_built_in_parallel_matches_brute_force() {
    // More triangles than the parallel build threshold, to exercise rayon::join subtrees.
    let mut s = 0x2545f4914f6cdd1du64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut p = Vec::new();
    let mut t = Vec::new();
    for i in 0..20_000u32 {
        let a = [next() * 100.0, next() * 100.0, next() * 100.0];
        p.push(a);
        p.push([a[0] + 4.0 * next(), a[1] + 4.0 * next(), a[2]]);
        p.push([a[0], a[1] + 4.0 * next(), a[2] + 4.0 * next()]);
        t.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let bvh = Bvh::build(&p, &t).unwrap();
    assert!(bvh.node_count() > 2 * t.len() / 8);
    let mut hits = 0;
    for _ in 0..300 {
        let o = [next() as f64 * 100.0, next() as f64 * 100.0, -1.0];
        let d = [next() as f64 - 0.5, next() as f64 - 0.5, 1.0];
        let e = brute_closest(&p, &t, o, d, 0.0, f64::INFINITY);
        let g = bvh.intersect(o, d, 0.0, f64::INFINITY);
        assert_eq!(e.map(|h| h.0), g.map(|h| h.t));
        assert_eq!(bvh.occluded(o, d, 0.0, f64::INFINITY, u32::MAX), e.is_some());
        hits += e.is_some() as usize;
    }
    // The soup is dense enough that most rays hit: the comparison is not vacuous.
    assert!(hits > 100, "{hits}");
}

#[test]
fn non_finite_triangles_are_left_out_and_counted() {
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, f32::INFINITY, 0.0]];
    let t = vec![[0, 1, 2], [3, 1, 2], [0, 4, 1]];
    let bvh = Bvh::build(&p, &t).unwrap();
    assert_eq!(bvh.triangle_count(), 3);
    assert_eq!(bvh.skipped_triangles(), 2);
    let h = bvh.intersect([0.2, 0.2, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY).unwrap();
    assert_eq!((h.t, h.triangle), (1.0, 0));
}

#[test]
fn out_of_range_vertex_is_a_typed_error() {
    let p = vec![[0.0; 3]; 3];
    let err = Bvh::build(&p, &[[0, 1, 2], [0, 1, 3]]).unwrap_err();
    assert_eq!(err, OracleError::VertexOutOfRange { triangle: 1, vertex: 3, vertices: 3 });
}

#[test]
fn empty_bvh_never_hits() {
    let bvh = Bvh::build(&[], &[]).unwrap();
    assert_eq!(bvh.intersect([0.0; 3], [1.0, 0.0, 0.0], 0.0, f64::INFINITY), None);
    assert!(!bvh.occluded([0.0; 3], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, u32::MAX));
}

#[test]
fn identical_centroids_still_build_a_valid_tree() {
    // 1000 copies of the same triangle: no SAH split exists, the builder falls back to halving.
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let t = vec![[0, 1, 2]; 1000];
    let bvh = Bvh::build(&p, &t).unwrap();
    let h = bvh.intersect([0.25, 0.25, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY).unwrap();
    assert_eq!(h.t, 1.0);
    // Ignoring one copy, the others still occlude.
    assert!(bvh.occluded([0.25, 0.25, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY, h.triangle));
}
