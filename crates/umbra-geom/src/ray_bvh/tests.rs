use super::*;
use crate::scene::load_scene;
use crate::weld::weld;

/// A small deterministic generator (xorshift), so the tests need no seed crate.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn point(&mut self, scale: f32) -> [f32; 3] {
        [0, 1, 2].map(|_| (self.next() - 0.5) * scale)
    }
}

fn soup(rng: &mut Rng, n: usize) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..n {
        let c = rng.point(10.0);
        for _ in 0..3 {
            let d = rng.point(1.5);
            positions.push([c[0] + d[0], c[1] + d[1], c[2] + d[2]]);
        }
        triangles.push([3 * i as u32, 3 * i as u32 + 1, 3 * i as u32 + 2]);
    }
    (positions, triangles)
}

/// Every node's structure: the root at 0 without a parent, every inner node's children
/// adjacent (the left one odd) with their parent's index, each id once among the records, each
/// record in exactly one leaf, and every box holding its children's boxes and its triangles.
fn check_structure(bvh: &RayBvh, expected_ids: &[u32]) {
    let n = bvh.node_count();
    let mut seen_records = vec![0u32; bvh.triangle_count()];
    let mut reached = vec![false; n];
    let mut stack = if n > 0 { vec![(0usize, NO_PARENT)] } else { Vec::new() };
    while let Some((i, parent)) = stack.pop() {
        assert!(!reached[i], "node {i} reached twice");
        reached[i] = true;
        let (lo, hi, p, word) = bvh.node(i);
        assert_eq!(p, parent, "node {i}'s parent");
        if word & LEAF_BIT == 0 {
            let left = (word >> 2) as usize;
            assert!(left % 2 == 1 && left + 1 < n && left > i, "node {i}'s children at {left}");
            assert!(word & 3 < 3, "node {i}'s axis");
            for c in [left, left + 1] {
                let (clo, chi, _, _) = bvh.node(c);
                for k in 0..3 {
                    assert!(lo[k] <= clo[k] && chi[k] <= hi[k], "node {c} pokes out of its parent {i}");
                }
                stack.push((c, i as u32));
            }
        } else {
            let first = ((word & !LEAF_BIT) >> LEAF_COUNT_BITS) as usize;
            let count = (word & ((1 << LEAF_COUNT_BITS) - 1)) as usize;
            assert!((1..=MAX_LEAF).contains(&count), "leaf {i} holds {count}");
            for (r, seen) in seen_records.iter_mut().enumerate().skip(first).take(count) {
                *seen += 1;
                let (v, _, _) = bvh.record(r);
                for p in v {
                    for k in 0..3 {
                        assert!(lo[k] <= p[k] && p[k] <= hi[k], "leaf {i} misses record {r}");
                    }
                }
            }
        }
    }
    assert!(reached.iter().all(|&r| r), "unreachable nodes");
    assert!(seen_records.iter().all(|&c| c == 1), "records not in exactly one leaf: {seen_records:?}");
    let mut ids: Vec<u32> = (0..bvh.triangle_count()).map(|r| bvh.record(r).1).collect();
    ids.sort_unstable();
    assert_eq!(ids, expected_ids, "the records' ids");
}

/// The traversal against every record tested one by one with the same ray test: the boxes and
/// skips never lose a hit, and never invent one.
fn brute_force(bvh: &RayBvh, o: [f32; 3], d: [f32; 3], near: f32, far: f32, skip_id: u32) -> bool {
    let ray = Ray::new(o, d);
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    (0..bvh.triangle_count()).any(|r| {
        let (v, id, edges) = bvh.record(r);
        id != skip_id && ray.hit(v, edges).is_some_and(|t| t * len > near && t * len < far)
    })
}

#[test]
fn every_triangle_is_reachable_and_every_box_holds_its_children() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for n in [1, 2, 3, 4, 5, 17, 100, 1000] {
        let (p, t) = soup(&mut rng, n);
        let bvh = build(&p, &t);
        assert_eq!(bvh.skipped, 0);
        check_structure(&bvh, &(0..n as u32).collect::<Vec<_>>());
    }
    let spheres = weld(&load_scene("spheres:20").unwrap());
    let bvh = build(&spheres.positions, &spheres.triangles);
    check_structure(&bvh, &(0..spheres.triangles.len() as u32).collect::<Vec<_>>());
    assert!(bvh.depth < 64, "depth {}", bvh.depth);
}

#[test]
fn traversal_finds_exactly_what_testing_every_triangle_finds() {
    let mut rng = Rng(12345);
    let (p, t) = soup(&mut rng, 400);
    let bvh = build(&p, &t);
    let mut hits = 0;
    for i in 0..3000 {
        let o = rng.point(14.0);
        // Segments to a point light, rays towards a directional one, and axis-aligned rays
        // (zero direction components: the box test's 1 / d).
        let d = match i % 3 {
            0 => rng.point(20.0),
            1 => {
                let d = rng.point(2.0);
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                d.map(|c| c / l)
            }
            _ => {
                let mut d = [0.0; 3];
                d[i % 3] = if rng.next() < 0.5 { -1.0 } else { 1.0 };
                d
            }
        };
        let (t_end, near, far) = if i % 3 == 0 { (1.0, 1e-4, 0.999) } else { (f32::MAX, 1e-4, f32::INFINITY) };
        let skip = (rng.next() * 400.0) as u32;
        let (got, _) = bvh.occluded(o, d, t_end, near, far, skip);
        assert_eq!(got, brute_force(&bvh, o, d, near, far, skip), "ray {i} from {o:?} along {d:?}");
        hits += usize::from(got);
    }
    // Both answers occur, or the comparison says nothing.
    assert!(hits > 300 && hits < 2700, "{hits} hits");
}

#[test]
fn rays_through_shared_edges_and_vertices_hit_the_surface() {
    // A 6 x 6 grid of quads in the plane z = 0, each split in two; welded (shared vertices).
    let n = 6;
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push([x as f32 * 0.37, y as f32 * 0.37, 0.0]);
        }
    }
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let mut triangles = Vec::new();
    for y in 0..n {
        for x in 0..n {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    let bvh = build(&positions, &triangles);
    let mut targets = Vec::new();
    for y in 1..n {
        for x in 1..n {
            let p = positions[id(x, y) as usize];
            // The vertex, the midpoints of its edges (and the quad's diagonal).
            targets.push(p);
            targets.push([p[0] + 0.185, p[1], 0.0]);
            targets.push([p[0], p[1] + 0.185, 0.0]);
            targets.push([p[0] + 0.185, p[1] + 0.185, 0.0]);
        }
    }
    let mut rng = Rng(777);
    for target in targets {
        for _ in 0..20 {
            let o = [target[0] + rng.next() - 0.5, target[1] + rng.next() - 0.5, 1.0 + rng.next()];
            let d = [target[0] - o[0], target[1] - o[1], target[2] - o[2]].map(|c| 2.0 * c);
            let (hit, _) = bvh.occluded(o, d, 1.0, 1e-6, f32::INFINITY, u32::MAX);
            assert!(hit, "the ray from {o:?} through {target:?} passed through the surface");
        }
    }
}

#[test]
fn degenerate_and_non_finite_triangles_are_left_out() {
    let nan = f32::NAN;
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0], // collinear with 0 and 1
        [nan, 0.0, 0.0],
        [f32::INFINITY, 1.0, 1.0],
        [1e-30, 1e-30, 0.0],
    ];
    let triangles = vec![
        [0, 1, 2],  // the one real triangle
        [0, 1, 3],  // zero area, collinear
        [0, 0, 2],  // zero area, repeated vertex
        [0, 1, 4],  // NaN
        [0, 1, 5],  // infinite
        [0, 1, 99], // index out of range
        [0, 6, 2],  // tiny but not zero
    ];
    let bvh = build(&positions, &triangles);
    assert_eq!(bvh.skipped, 5);
    check_structure(&bvh, &[0, 6]);
    assert!(bvh.nodes.iter().flatten().take(3).all(|c| c.is_finite()));
    // Nothing at all, and only bad input: an empty hierarchy no ray hits.
    for (p, t) in [(vec![], vec![]), (positions.clone(), vec![[0u32, 1, 3], [0, 1, 4]])] {
        let empty = build(&p, &t);
        assert_eq!((empty.node_count(), empty.triangle_count()), (0, 0));
        assert!(!empty.occluded([0.0; 3], [1.0, 0.0, 0.0], 1.0, 0.0, 2.0, u32::MAX).0);
    }
}

#[test]
fn many_triangles_with_one_centroid_are_split_into_small_leaves() {
    // 50 copies of one triangle: no SAH split separates them; the build halves them instead.
    let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let triangles = vec![[0, 1, 2]; 50];
    let bvh = build(&positions, &triangles);
    check_structure(&bvh, &(0..50).collect::<Vec<_>>());
    // Skipping one copy, the others still occlude.
    assert!(bvh.occluded([0.2, 0.2, 1.0], [0.0, 0.0, -2.0], 1.0, 0.0, 2.0, 7).0);
}

#[test]
fn builds_are_deterministic() {
    let spheres = weld(&load_scene("spheres:5").unwrap());
    let a = build(&spheres.positions, &spheres.triangles);
    let b = build(&spheres.positions, &spheres.triangles);
    let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.nodes), bits(&b.nodes));
    assert_eq!(bits(&a.triangles), bits(&b.triangles));
    assert_eq!(a.bytes(), 16 * (a.nodes.len() + a.triangles.len()));
}

#[test]
fn walks_stopped_by_a_small_budget_resume_to_the_same_answer_within_three_steps_per_node() {
    let spheres = weld(&load_scene("spheres:6").unwrap());
    let bvh = build(&spheres.positions, &spheres.triangles);
    let n = bvh.node_count();
    let mut rng = Rng(99);
    let mut resumed = 0;
    for i in 0..500 {
        let origin = rng.point(30.0);
        let dir = rng.point(60.0);
        let q = Query { origin, dir, t_end: 1.0, near: 1e-4, far: f32::INFINITY, skip_id: u32::MAX };
        let mut whole = Walk::default();
        let expected = bvh.walk(&q, START, usize::MAX, &mut whole);
        assert!(whole.steps <= 3 * n, "ray {i}: {} steps for {n} nodes", whole.steps);
        // The same walk in pieces of 1 + i % 7 steps, resumed from the parked state.
        let mut state = START;
        let mut pieces = Walk::default();
        let got = loop {
            match bvh.walk(&q, state, 1 + i % 7, &mut pieces) {
                Outcome::Unfinished(s) => {
                    state = s;
                    resumed += 1;
                }
                done => break done,
            }
        };
        assert_eq!(got, expected, "ray {i}");
        assert_eq!((pieces.nodes, pieces.triangles), (whole.nodes, whole.triangles), "ray {i}");
    }
    assert!(resumed > 1000);
}
