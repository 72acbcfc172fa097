//! The bound on books, stacked quads, spheres and the shared scenes; bad input.

use super::bound::bound_with_stop;
use super::footprint::cube_face_footprint;
use super::*;
use crate::scene::uv_sphere;

/// `n` triangles ("pages") around the shared edge (0,0,-1)-(0,0,1), their tips at radius 1
/// in the plane z = 0, at angles spread over (0, pi) around the z axis (so in y > 0).
fn book(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut p = vec![[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]];
    let mut t = Vec::new();
    for i in 0..n {
        let a = std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
        p.push([a.cos() as f32, a.sin() as f32, 0.0]);
        t.push([0, 1, 2 + i]);
    }
    (p, t)
}

/// `n` separate unit quads stacked along y at y = 0, 1, ..., n - 1.
fn stacked_quads(n: u32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for i in 0..n {
        let y = i as f32;
        let b = p.len() as u32;
        p.extend([[-1.0, y, -1.0], [1.0, y, -1.0], [1.0, y, 1.0], [-1.0, y, 1.0]]);
        t.push([b, b + 1, b + 2]);
        t.push([b, b + 2, b + 3]);
    }
    (p, t)
}

#[test]
fn book_seen_from_its_side_is_at_least_its_page_count_behind_it() {
    // Light on -y, below the fan (the fan is in y > 0): a ray passing just beside the spine
    // at x = +delta crosses every page with angle in (0, pi/2), so W reaches n / 2 there
    // and a sound bound must be at least that.
    let (p, t) = book(1000);
    let b = winding_bound(&p, &t, [0.0, -5.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert!(b.bound >= 1000 / 2, "bound {} below the real count", b.bound);
    assert!(b.bound <= 1000);
    assert!(!b.stencil8_exact());
    let d = winding_bound(&p, &t, [0.0, -1.0, 0.0, 0.0], &BoundOptions::default()).unwrap();
    assert!(d.bound >= 500 && d.bound <= 1000, "{:?}", d);
}

#[test]
fn book_seen_along_its_spine_is_small() {
    // Directional light along the spine (z): every page projects to a radial segment;
    // their bounding rectangles all contain the spine's point, so the bound is the page
    // count (the bound's looseness on thin footprints), but below 256.
    let (p, t) = book(64);
    let b = winding_bound(&p, &t, [0.0, 0.0, 1.0, 0.0], &BoundOptions::default()).unwrap();
    assert_eq!(b.bound, 64, "all pages meet at the spine");
    assert!(b.stencil8_exact());
}

#[test]
fn stacked_quads_bound_is_their_number() {
    let (p, t) = stacked_quads(300);
    // Light above: every vertical ray through the quads crosses all 300 (2 triangles each
    // touch the diagonal; away from it one per quad).
    let b = winding_bound(&p, &t, [0.0, 1000.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert!(b.bound >= 300 && b.bound <= 600, "{:?}", b);
    assert!(!b.stencil8_exact());
    // Directional from above: the same.
    let d = winding_bound(&p, &t, [0.0, 1.0, 0.0, 0.0], &BoundOptions::default()).unwrap();
    assert!(d.bound >= 300 && d.bound <= 600, "{:?}", d);
    // 100 quads: both triangles of a quad have the quad's bounding rectangle, so the bound
    // is 200 at most: < 256, proven exact.
    let (p, t) = stacked_quads(100);
    let b = winding_bound(&p, &t, [0.0, 1000.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert!(b.stencil8_exact() && b.bound >= 100, "{:?}", b);
}

#[test]
fn closed_sphere_bound_is_small() {
    // A closed convex mesh is crossed at most twice by a ray; a sound cell bound also counts
    // every triangle touching the cell of a vertex: up to the 64 triangles at a pole of
    // this UV sphere (twice when the light is on the polar axis), plus neighbours.
    let m = uv_sphere([0.0, 0.0, 0.0], 1.0, 64, 32);
    let o = BoundOptions::default();
    for light in [[0.0, 5.0, 0.0, 1.0], [3.0, 1.0, 2.0, 1.0], [1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]] {
        let b = winding_bound(&m.positions, &m.triangles, light, &o).unwrap();
        assert!(b.bound >= 1 && b.bound <= 160, "light {light:?}: {:?}", b);
        assert!(b.stencil8_exact());
    }
}

/// The bound on the shared scenes (`UMBRA_SCENES`, default ../shared/scenes beside the
/// workspace) with the CLI's default interior light, and what the cell that stopped the
/// refinement holds. `cargo test --release -p umbra-geom --lib winding_bound -- --ignored
/// --nocapture`.
#[test]
#[ignore = "needs the shared scenes; a measurement"]
fn shared_scenes_bounds() {
    let dir = std::env::var_os("UMBRA_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    for name in ["crytek-sponza.obj.gz", "conference.obj.gz", "sibenik.obj.gz"] {
        let path = dir.join(name);
        if !path.exists() {
            println!("SKIP {}: not found", path.display());
            continue;
        }
        let mesh = crate::scene::load_scene(&path.to_string_lossy()).expect("scene");
        let w = crate::weld::weld(&mesh);
        let b = mesh_bounds(&w.positions, &w.triangles);
        let (c, e) = (b.center(), b.extent());
        // The CLI's interior default light (umbra-cli config::default_light).
        let light = [c[0] + 0.11 * e[0], b.min[1] + 0.7 * e[1], c[2] + 0.07 * e[2], 1.0];
        let t = std::time::Instant::now();
        let (r, stop) = bound_with_stop(&w.positions, &w.triangles, light, &BoundOptions::default()).unwrap();
        println!(
            "{name}: {} triangles, light {light:?}: {r:?} in {:.0} ms",
            w.triangles.len(),
            t.elapsed().as_secs_f64() * 1e3
        );
        if let Some(stop) = stop {
            let finite: Vec<usize> = (0..w.triangles.len()).collect();
            let l = [light[0], light[1], light[2]].map(f64::from);
            let corners = |i: usize| w.triangles[i].map(|k| w.positions[k as usize].map(f64::from));
            let on_face: Vec<usize> = finite
                .iter()
                .copied()
                .filter(|&i| cube_face_footprint(&corners(i), l, stop.domain).is_some())
                .collect();
            let tris: Vec<usize> = stop.footprints.iter().map(|&f| on_face[f as usize]).collect();
            let mut verts: Vec<u32> = tris.iter().flat_map(|&i| w.triangles[i]).collect();
            verts.sort_unstable();
            verts.dedup();
            let mut valence = std::collections::HashMap::new();
            for &i in &tris {
                for v in w.triangles[i] {
                    *valence.entry(v).or_insert(0usize) += 1;
                }
            }
            let top = valence.values().copied().max().unwrap_or(0);
            let dist: Vec<f64> = tris
                .iter()
                .map(|&i| {
                    let p = corners(i)[0];
                    ((p[0] - l[0]).powi(2) + (p[1] - l[1]).powi(2) + (p[2] - l[2]).powi(2)).sqrt()
                })
                .collect();
            let (dmin, dmax) = dist.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &d| (a.min(d), b.max(d)));
            println!(
                "  stopped at face {} cell {:?}: {} triangles, {} distinct vertices, largest valence in it {top}, distance to the light {dmin:.3}..{dmax:.3}",
                stop.domain,
                stop.cell,
                tris.len(),
                verts.len()
            );
        }
    }
}

fn mesh_bounds(p: &[[f32; 3]], t: &[[u32; 3]]) -> crate::Aabb {
    let m = crate::Mesh { positions: p.to_vec(), triangles: t.to_vec(), normals: None };
    m.bounds().expect("non-empty")
}

#[test]
fn tiny_budget_stays_sound() {
    let (p, t) = stacked_quads(300);
    let o = BoundOptions { budget: 1, ..BoundOptions::default() };
    let b = winding_bound(&p, &t, [0.0, 1000.0, 0.0, 1.0], &o).unwrap();
    assert!(b.budget_exhausted);
    assert!(b.bound >= 300, "{:?}", b);
}

#[test]
fn triangle_through_the_light_covers_every_face() {
    let p = vec![[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]];
    let t = vec![[0, 1, 2]];
    let b = winding_bound(&p, &t, [0.0, 0.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert_eq!(b.bound, 1);
}

#[test]
fn non_finite_vertex_counts_everywhere() {
    let p =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f32::NAN, 0.0], [5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]];
    let t = vec![[0, 1, 2], [3, 4, 5]];
    let b = winding_bound(&p, &t, [0.0, 0.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert_eq!(b.bound, 2);
}

#[test]
fn bad_input_is_a_typed_error() {
    let p = vec![[0.0, 0.0, 0.0]];
    let e = winding_bound(&p, &[[0, 0, 7]], [0.0, 1.0, 0.0, 1.0], &BoundOptions::default()).unwrap_err();
    assert_eq!(e, BoundError::IndexOutOfRange { triangle: 0, index: 7, vertices: 1 });
    for light in [[0.0, f32::NAN, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.5]] {
        assert!(matches!(winding_bound(&p, &[], light, &BoundOptions::default()), Err(BoundError::BadLight { .. })));
    }
}

#[test]
fn empty_mesh_bound_is_zero() {
    let b = winding_bound(&[], &[], [0.0, 1.0, 0.0, 1.0], &BoundOptions::default()).unwrap();
    assert_eq!(b.bound, 0);
    assert!(b.stencil8_exact());
}
