//! Procedural scenes: counts, closedness, outward winding, spheres:N:T budgets, parse
//! errors, determinism.

use std::collections::HashMap;
use umbra_geom::scene::{self, SceneError, SceneSpec};
use umbra_geom::Mesh;

/// Exact-position weld (test-local, independent of `umbra_geom::weld`).
fn welded_triangles(mesh: &Mesh) -> Vec<[u32; 3]> {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let remap: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p.map(f32::to_bits)).or_insert(next)
        })
        .collect();
    mesh.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect()
}

/// Every edge shared by exactly two triangles, traversed in opposite directions.
fn assert_closed(mesh: &Mesh, what: &str) {
    let tris = welded_triangles(mesh);
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &tris {
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "{what}: degenerate triangle {t:?}");
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        assert_eq!(count, 1, "{what}: directed edge {a}->{b} used {count} times");
        assert_eq!(directed.get(&(b, a)), Some(&1), "{what}: edge {a}-{b} has no opposite half");
    }
}

fn signed_volume(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
            // a . (b x c) / 6
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

fn normals_are_unit(mesh: &Mesh) {
    let n = mesh.normals.as_ref().expect("normals");
    assert_eq!(n.len(), mesh.positions.len());
    for v in n {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((l - 1.0).abs() < 1e-5, "normal {v:?} has length {l}");
    }
}

#[test]
fn uv_sphere_counts_closed_outward() {
    for (slices, stacks) in [(3, 2), (4, 3), (18, 10), (64, 32), (7, 13)] {
        let m = scene::uv_sphere([1.0, -2.0, 0.5], 2.0, slices, stacks);
        assert_eq!(m.positions.len() as u32, 2 + slices * (stacks - 1));
        assert_eq!(m.triangles.len() as u64, scene::sphere_triangle_count(slices, stacks));
        assert_closed(&m, &format!("sphere {slices}x{stacks}"));
        let v = signed_volume(&m);
        assert!(v > 0.0, "sphere {slices}x{stacks} volume {v}");
        assert!(v < 4.0 / 3.0 * std::f64::consts::PI * 8.0 + 1e-3);
        normals_are_unit(&m);
        // normal points from the centre to the vertex
        for (p, n) in m.positions.iter().zip(m.normals.as_ref().unwrap()) {
            let d = [p[0] - 1.0, p[1] + 2.0, p[2] - 0.5];
            for k in 0..3 {
                assert!((d[k] / 2.0 - n[k]).abs() < 1e-5, "p {p:?} n {n:?}");
            }
        }
    }
    let fine = scene::uv_sphere([0.0; 3], 1.0, 256, 128);
    let v = signed_volume(&fine);
    assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 2e-3, "fine sphere volume {v}");
}

#[test]
fn uv_sphere_clamps_degenerate_tessellation() {
    let m = scene::uv_sphere([0.0; 3], 1.0, 0, 0);
    assert_eq!(m.triangles.len(), 6);
    assert_closed(&m, "clamped sphere");
}

#[test]
fn ground_plane_faces_up() {
    let g = scene::ground_plane([1.0, 2.0, 3.0], 4.0);
    assert_eq!(g.triangles.len(), 2);
    for t in &g.triangles {
        let [a, b, c] = t.map(|i| g.positions[i as usize]);
        let e1 = [b[0] - a[0], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[2] - a[2]];
        // y component of e1 x e2 = z1*x2 - x1*z2
        let ny = e1[1] * e2[0] - e1[0] * e2[1];
        assert!(ny > 0.0, "triangle {t:?} faces down");
    }
    assert!(g.positions.iter().all(|p| p[1] == 2.0));
    let xs: Vec<f32> = g.positions.iter().map(|p| p[0]).collect();
    assert_eq!(xs.iter().cloned().fold(f32::MAX, f32::min), -3.0);
    assert_eq!(xs.iter().cloned().fold(f32::MIN, f32::max), 5.0);
    assert_eq!(g.normals, Some(vec![[0.0, 1.0, 0.0]; 4]));
}

#[test]
fn add_ground_is_ten_times_the_horizontal_extent_at_lowest_y() {
    let mut m = scene::uv_sphere([10.0, 5.0, -3.0], 2.0, 8, 4);
    let before = m.triangles.len();
    scene::add_ground(&mut m);
    assert_eq!(m.triangles.len(), before + 2);
    let ground: Vec<[f32; 3]> = m.triangles[before..].iter().flatten().map(|&i| m.positions[i as usize]).collect();
    assert!(ground.iter().all(|p| p[1] == 3.0), "{ground:?}");
    let min_x = ground.iter().map(|p| p[0]).fold(f32::MAX, f32::min);
    let max_x = ground.iter().map(|p| p[0]).fold(f32::MIN, f32::max);
    let min_z = ground.iter().map(|p| p[2]).fold(f32::MAX, f32::min);
    let max_z = ground.iter().map(|p| p[2]).fold(f32::MIN, f32::max);
    assert!((max_x - min_x - 40.0).abs() < 1e-3, "{min_x} {max_x}");
    assert!((max_z - min_z - 40.0).abs() < 1e-3);
    assert!(((min_x + max_x) / 2.0 - 10.0).abs() < 1e-3);
    assert!(((min_z + max_z) / 2.0 + 3.0).abs() < 1e-3);
    assert!(m.normals.is_some(), "both had normals, normals kept");
}

#[test]
fn add_ground_on_vertical_segment_and_empty_mesh() {
    // zero horizontal extent: a degenerate vertical triangle
    let mut m = Mesh {
        positions: vec![[0.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 2.0, 0.0]],
        triangles: vec![[0, 1, 2]],
        normals: None,
    };
    scene::add_ground(&mut m);
    let g = &m.positions[3..];
    let width = g.iter().map(|p| p[0]).fold(f32::MIN, f32::max) - g.iter().map(|p| p[0]).fold(f32::MAX, f32::min);
    assert!(width > 0.0 && width.is_finite(), "width {width}");
    assert!(g.iter().all(|p| p[1] == 0.0));

    let mut empty = Mesh::default();
    scene::add_ground(&mut empty);
    assert_eq!(empty.triangles.len(), 2);
}

#[test]
fn box_is_closed_cube() {
    let m = scene::build(&scene::parse("box").unwrap()).unwrap();
    assert_eq!(m.triangles.len(), 12);
    assert_closed(&m, "box");
    assert!((signed_volume(&m) - 8.0).abs() < 1e-9);
    normals_are_unit(&m);
}

#[test]
fn torus_and_tetrahedron_closed_outward() {
    let t = scene::torus([1.0, 2.0, 3.0], 2.0, 0.5, 32, 12);
    assert_eq!(t.triangles.len(), 2 * 32 * 12);
    assert_closed(&t, "torus");
    let v = signed_volume(&t);
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25;
    assert!(v > 0.9 * exact && v < exact, "torus volume {v} vs {exact}");
    normals_are_unit(&t);

    let h = scene::tetrahedron([0.0, 1.0, 0.0], 1.0);
    assert_eq!(h.triangles.len(), 4);
    assert_closed(&h, "tetrahedron");
    assert!(signed_volume(&h) > 0.0);
    normals_are_unit(&h);
}

#[test]
fn default_scene_is_small_with_ground_below() {
    let spec = scene::parse("default").unwrap();
    let m = scene::build(&spec).unwrap();
    assert!(m.triangles.len() > 100 && m.triangles.len() < 20_000, "{}", m.triangles.len());
    assert_eq!(spec.triangle_count(), Some(m.triangles.len() as u64));
    normals_are_unit(&m);
    // the first two triangles are the ground at y = 0; everything else is above it and closed
    assert!(m.triangles[..2].iter().flatten().all(|&i| m.positions[i as usize][1] == 0.0));
    let objects = Mesh { positions: m.positions.clone(), triangles: m.triangles[2..].to_vec(), normals: None };
    assert_closed(&objects, "default objects");
    assert!(signed_volume(&objects) > 0.0);
    assert!(objects.triangles.iter().flatten().all(|&i| m.positions[i as usize][1] >= 0.0));
}

#[test]
fn spheres_n_default_tessellation_matches_paper_table_3() {
    let spec = scene::parse("spheres:10").unwrap();
    assert_eq!(spec, SceneSpec::Spheres { n: 10, slices: 18, stacks: 10, target_triangles: None });
    let m = scene::build(&spec).unwrap();
    assert_eq!(m.triangles.len(), 32_400 + 2);
    assert_eq!(m.positions.len(), 100 * (2 + 18 * 9) + 4);
    assert_eq!(spec.triangle_count(), Some(32_402));
    let spheres = Mesh { positions: m.positions.clone(), triangles: m.triangles[2..].to_vec(), normals: None };
    assert_closed(&spheres, "spheres:10");
    assert!(signed_volume(&spheres) > 0.0);
    // every sphere floats above the ground at y = 0, which is wider than the grid
    let ground_y = m.positions[m.triangles[0][0] as usize][1];
    assert_eq!(ground_y, 0.0);
    assert!(spheres.triangles.iter().flatten().all(|&i| m.positions[i as usize][1] > 0.5));
    let gx = m.triangles[..2].iter().flatten().map(|&i| m.positions[i as usize][0]).fold(f32::MIN, f32::max);
    let sx = spheres.triangles.iter().flatten().map(|&i| m.positions[i as usize][0]).fold(f32::MIN, f32::max);
    assert!(gx > sx);
    normals_are_unit(&m);
}

#[test]
fn spheres_one_has_one_sphere() {
    let m = scene::load_scene("spheres:1").unwrap();
    assert_eq!(m.triangles.len(), 324 + 2);
}

#[test]
fn spheres_n_t_is_within_two_percent() {
    for n in [1u32, 3, 10, 20] {
        for t in [32_400u64, 100_000, 1_000_000, 4_000_000, 250_000, 67_600] {
            let spec_str = format!("spheres:{n}:{t}");
            let spec = scene::parse(&spec_str).unwrap_or_else(|e| panic!("{spec_str}: {e}"));
            let count = spec.triangle_count().unwrap();
            let rel = (count as f64 - t as f64).abs() / t as f64;
            assert!(rel <= 0.02, "{spec_str}: {count} triangles, {rel}");
            let SceneSpec::Spheres { slices, stacks, .. } = spec else { panic!() };
            // sensible quads: not absurdly thin slivers
            let ratio = slices as f64 / (2.0 * (stacks - 1) as f64);
            assert!((0.25..=4.0).contains(&ratio), "{spec_str}: {slices}x{stacks}");
        }
    }
}

#[test]
fn spheres_n_t_built_counts_match() {
    for spec_str in ["spheres:10:32400", "spheres:10:100000", "spheres:10:1000000", "spheres:3:1M", "spheres:7:100k"] {
        let spec = scene::parse(spec_str).unwrap();
        let m = scene::build(&spec).unwrap();
        assert_eq!(Some(m.triangles.len() as u64), spec.triangle_count(), "{spec_str}");
        let SceneSpec::Spheres { target_triangles: Some(t), .. } = spec else { panic!() };
        let rel = (m.triangles.len() as f64 - t as f64).abs() / t as f64;
        assert!(rel <= 0.02, "{spec_str}: {}", m.triangles.len());
    }
}

#[test]
fn spheres_n_t_small_budget_uses_coarse_spheres() {
    // 6 triangles per sphere is the coarsest: 100 * 6 + 2 = 602
    let spec = scene::parse("spheres:10:602").unwrap();
    assert_eq!(spec.triangle_count(), Some(602));
}

#[test]
fn bad_specs_are_clear_errors() {
    for bad in [
        "spheres:0",
        "spheres:abc",
        "spheres:3:5",
        "spheres:",
        "spheres:3:",
        "spheres:-1",
        "spheres:10:abc",
        "spheres:1:2:3",
        "spheres:100000",
        "spheres:10:999999999999",
        "spheres:10:700",
        "spheres:99999999999999999999999",
        "spheres:4294967295",
        "spheres:4294967296",
        "spheres:1:k",
        "   ",
    ] {
        match scene::parse(bad) {
            Err(e @ SceneError::InvalidSpec { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(bad.trim()) || bad.trim().is_empty(),
                    "{bad}: message {msg:?} does not name the spec"
                );
            }
            other => panic!("{bad}: expected InvalidSpec, got {other:?}"),
        }
    }
}

#[test]
fn other_specs_are_files() {
    assert_eq!(scene::parse("a/b/scene.obj.gz").unwrap(), SceneSpec::File("a/b/scene.obj.gz".into()));
    assert_eq!(scene::parse("./box").unwrap(), SceneSpec::File("./box".into()));
    match scene::load_scene("/nonexistent/dir/missing-mesh.obj") {
        Err(e @ SceneError::Load(_)) => assert!(e.to_string().contains("missing-mesh.obj"), "{e}"),
        other => panic!("expected a load error, got {other:?}"),
    }
}

#[test]
fn scenes_are_deterministic() {
    for spec in ["default", "box", "spheres:4", "spheres:5:50000"] {
        let a = scene::load_scene(spec).unwrap();
        let b = scene::load_scene(spec).unwrap();
        let bits = |m: &Mesh| m.positions.iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b), "{spec}");
        assert_eq!(a.triangles, b.triangles, "{spec}");
    }
}

#[test]
fn triangle_counts_never_overflow() {
    let max = scene::MAX_SEGMENTS as u64;
    assert_eq!(scene::sphere_triangle_count(u32::MAX, u32::MAX), 2 * max * (max - 1));
    assert_eq!(scene::spheres_triangle_count(u32::MAX, u32::MAX, u32::MAX), u64::MAX);
    assert_eq!(scene::tessellation_for_target(u32::MAX, u64::MAX), None);
    assert_eq!(scene::tessellation_for_target(0, 1000), None);
}

#[test]
fn book_has_one_spine_with_every_page_on_it() {
    for pages in [3, 40] {
        let mesh = umbra_geom::weld::weld(&scene::book(pages));
        assert_eq!((mesh.triangles.len(), mesh.degenerate_triangles), (2 * pages, 0));
        let adj = umbra_geom::EdgeAdjacency::build(&mesh);
        // The spine, and per page its two sides, its diagonal and its outer edge.
        assert_eq!(adj.len(), 1 + 4 * pages);
        assert_eq!(adj.max_opposites(), pages);
        assert_eq!((0..adj.len()).filter(|&e| adj.opposites(e).len() == pages).count(), 1, "one spine");
        assert_eq!(adj.nonmanifold_edges(), 1);
    }
}
