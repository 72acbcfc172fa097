//! Watertightness of the BVH + Woop/Benthin/Wald triangle test on closed meshes: rays through
//! shared edges and vertices never slip between two triangles.

use std::collections::HashMap;

use umbra_oracle::Bvh;

/// Unit cube [0,1]^3 as 12 triangles with face diagonals; all coordinates exact small integers,
/// so rays aimed at edge points built from dyadic fractions hit them *exactly*.
fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut p = Vec::new();
    for i in 0..8u32 {
        p.push([(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]);
    }
    // Each face as a quad (a, b, c, d), split along a-c.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut t = Vec::new();
    for q in quads {
        t.push([q[0], q[1], q[2]]);
        t.push([q[0], q[2], q[3]]);
    }
    (p, t)
}

/// Icosphere: icosahedron subdivided `levels` times, vertices shared through a midpoint cache
/// (so the mesh is closed and neighbours share bit-identical vertices), f32 coordinates that
/// are *not* exactly on the sphere: realistic rounding.
fn icosphere(levels: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [(v[0] / l) as f32, (v[1] / l) as f32, (v[2] / l) as f32]
    };
    let mut p: Vec<[f32; 3]> = raw.iter().map(|&v| norm(v)).collect();
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut cache: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, p: &mut Vec<[f32; 3]>| {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (p[a as usize], p[b as usize]);
                p.push(norm([0, 1, 2].map(|k| (pa[k] as f64 + pb[k] as f64) / 2.0)));
                p.len() as u32 - 1
            })
        };
        let mut next = Vec::new();
        for [a, b, c] in t {
            let (ab, bc, ca) = (mid(a, b, &mut p), mid(b, c, &mut p), mid(c, a, &mut p));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    (p, t)
}

fn unique_edges(t: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> =
        t.iter().flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]]).map(|[a, b]| [a.min(b), a.max(b)]).collect();
    e.sort();
    e.dedup();
    e
}

fn f64v(p: [f32; 3]) -> [f64; 3] {
    p.map(|c| c as f64)
}

#[test]
fn cube_rays_through_exact_edge_points_always_hit() {
    let (p, t) = cube();
    let bvh = Bvh::build(&p, &t).unwrap();
    // Directions with small integer components: origin = target - 3 * direction is exact.
    let dirs: Vec<[f64; 3]> = (-2..=2i32)
        .flat_map(|x| (-2..=2i32).flat_map(move |y| (-2..=2i32).map(move |z| [x as f64, y as f64, z as f64])))
        .filter(|d| d != &[0.0; 3])
        .collect();
    let mut rays = 0;
    for [a, b] in unique_edges(&t) {
        let (pa, pb) = (f64v(p[a as usize]), f64v(p[b as usize]));
        for k in 0..=16 {
            // k/16 of the way along the edge: exact (coordinates are 0 or 1).
            let f = k as f64 / 16.0;
            let target = [0, 1, 2].map(|i| pa[i] + f * (pb[i] - pa[i]));
            for d in &dirs {
                let origin = [0, 1, 2].map(|i| target[i] - 3.0 * d[i]);
                // The target point is on the cube's surface; the ray's line meets the closed
                // cube there or earlier, so a hit at t <= 3 must be found (t = 3 exactly if the
                // ray arrives from outside through that point and nowhere earlier).
                let hit = bvh.intersect(origin, *d, 0.0, f64::INFINITY);
                let hit = hit
                    .unwrap_or_else(|| panic!("ray {origin:?} + t {d:?} slipped through edge {a}-{b} at {target:?}"));
                assert!(hit.t <= 3.0, "hit at {} beyond the surface point", hit.t);
                assert!(bvh.occluded(origin, *d, 0.0, 3.0 + 1e-9, u32::MAX));
                rays += 1;
            }
        }
    }
    assert!(rays > 10_000, "{rays}");
}

#[test]
fn cube_rays_from_inside_through_edges_and_vertices_always_hit() {
    let (p, t) = cube();
    let bvh = Bvh::build(&p, &t).unwrap();
    let origin = [0.5, 0.5, 0.5];
    for [a, b] in unique_edges(&t) {
        let (pa, pb) = (f64v(p[a as usize]), f64v(p[b as usize]));
        for k in 0..=64 {
            let f = k as f64 / 64.0;
            let target = [0, 1, 2].map(|i| pa[i] + f * (pb[i] - pa[i]));
            let d = [0, 1, 2].map(|i| target[i] - origin[i]);
            let hit = bvh.intersect(origin, d, 0.0, f64::INFINITY).expect("escaped the closed cube");
            // From inside a convex closed mesh the first hit is the exit point: t = 1.
            assert_eq!(hit.t, 1.0, "towards {target:?}");
        }
    }
}

#[test]
fn cube_rays_exactly_along_edges_hit_at_the_first_vertex() {
    let (p, t) = cube();
    let bvh = Bvh::build(&p, &t).unwrap();
    // Along the line of each cube edge and each face diagonal, from outside: the two triangles
    // containing the line are edge-on (no area seen, no hit), but the faces meeting at the first
    // vertex are crossed there, exactly at t = 1.
    for [a, b] in unique_edges(&t) {
        for (from, to) in [(a, b), (b, a)] {
            let (pf, pt) = (f64v(p[from as usize]), f64v(p[to as usize]));
            let d = [0, 1, 2].map(|i| pt[i] - pf[i]);
            let origin = [0, 1, 2].map(|i| pf[i] - d[i]);
            let hit = bvh
                .intersect(origin, d, 0.0, f64::INFINITY)
                .unwrap_or_else(|| panic!("ray along edge {from}->{to} missed"));
            assert_eq!(hit.t, 1.0, "ray along edge {from}->{to}");
            // The triangle hit contains the first vertex.
            assert!(t[hit.triangle as usize].contains(&from));
        }
    }
}

#[test]
fn icosphere_rays_through_shared_edges_and_vertices_always_hit() {
    let (p, t) = icosphere(3);
    assert_eq!(t.len(), 1280);
    let bvh = Bvh::build(&p, &t).unwrap();
    let mut rays = 0;
    // Targets: points along every edge (rounded to f32 like real data, so within rounding of the
    // edge, on either side) and every vertex exactly.
    let mut targets: Vec<[f64; 3]> = p.iter().map(|&v| f64v(v)).collect();
    for [a, b] in unique_edges(&t) {
        let (pa, pb) = (p[a as usize], p[b as usize]);
        for k in 1..8 {
            let f = k as f32 / 8.0;
            targets.push(f64v([0, 1, 2].map(|i| pa[i] + f * (pb[i] - pa[i]))));
        }
    }
    let offsets = [[0.0, 0.0, 0.0], [0.013, -0.007, 0.002], [-0.3, 0.1, 0.2]];
    for target in &targets {
        for o in &offsets {
            // From inside (near the centre): must leave through the surface.
            let d = [0, 1, 2].map(|i| target[i] - o[i]);
            let hit = bvh.intersect(*o, d, 0.0, f64::INFINITY);
            assert!(hit.is_some(), "escaped from {o:?} towards {target:?}");
            // From outside, aimed at the target: must enter.
            let origin = [0, 1, 2].map(|i| target[i] + 2.0 * d[i]);
            let back = d.map(|c| -c);
            assert!(bvh.occluded(origin, back, 0.0, f64::INFINITY, u32::MAX), "entered without hit at {target:?}");
            rays += 2;
        }
    }
    assert!(rays > 40_000, "{rays}");
}

#[test]
fn icosphere_random_rays_from_inside_always_hit() {
    let (p, t) = icosphere(4);
    let bvh = Bvh::build(&p, &t).unwrap();
    // A small deterministic generator (xorshift); directions cover the sphere densely.
    let mut s = 0x9e3779b97f4a7c15u64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for _ in 0..200_000 {
        let d = [next(), next(), next()];
        let o = [next() * 0.1, next() * 0.1, next() * 0.1];
        assert!(bvh.occluded(o, d, 0.0, f64::INFINITY, u32::MAX), "escaped from {o:?} along {d:?}");
    }
}
