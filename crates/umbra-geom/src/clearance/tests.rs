//! The clearance test and `W0` on small scenes, and its soundness against brute force.

use super::hull::Hull;
use super::*;
use crate::vec3::{cross, dot, sub};
use crate::{EdgeAdjacency, Light, WeldedMesh};

type V3 = [f64; 3];

fn mesh(tris: &[[[f32; 3]; 3]]) -> WeldedMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in tris {
        let b = positions.len() as u32;
        positions.extend_from_slice(t);
        triangles.push([b, b + 1, b + 2]);
    }
    let n = triangles.len();
    WeldedMesh { positions, triangles, source_triangle: (0..n as u32).collect(), degenerate_triangles: 0 }
}

/// Eye at the origin looking down -z, near rectangle 0.1 away, 0.2 wide.
fn near_points() -> Vec<[f64; 3]> {
    vec![[0.0, 0.0, 0.0], [-0.1, -0.1, -0.1], [0.1, -0.1, -0.1], [0.1, 0.1, -0.1], [-0.1, 0.1, -0.1]]
}

fn clear(tris: &[[[f32; 3]; 3]], light: Light) -> bool {
    let m = mesh(tris);
    ClearanceIndex::build(&m).is_clear(&m, Some(&EdgeAdjacency::build(&m)), &near_points(), light)
}

const FLOOR: [[f32; 3]; 3] = [[-5.0, -2.0, -5.0], [5.0, -2.0, -5.0], [0.0, -2.0, 5.0]];

#[test]
fn clear_when_the_occluder_is_beside_the_pyramid() {
    // Light straight up; the floor below the eye casts nothing onto the eye's pyramid.
    assert!(clear(&[FLOOR], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn blocked_by_a_roof_between_eye_and_light() {
    let roof = FLOOR.map(|p| [p[0], 2.0, p[2]]);
    assert!(!clear(&[FLOOR, roof], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn clear_when_the_occluder_is_behind_the_light() {
    let above = FLOOR.map(|p| [p[0], 8.0, p[2]]);
    assert!(clear(&[above], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn blocked_by_a_triangle_cutting_only_the_near_rectangle_corner() {
    // A small triangle near (0.1, 0.1, -0.1): only the pyramid's corner meets it.
    let t = [[0.09, 0.09, -0.1], [0.3, 0.09, -0.1], [0.09, 0.3, -0.1]];
    assert!(!clear(&[t], [0.0, 5.0, 0.0, 1.0]));
    // Moved just past the corner (but closer than the margin would allow? no: 1e-3 away).
    let t = t.map(|p| [p[0] + 0.011, p[1] + 0.011, p[2]]);
    assert!(clear(&[t], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn touching_within_the_margin_blocks() {
    // A triangle in the plane x = 0.1f32, 1.5e-9 beyond the hull's largest x (the near
    // corners at x = 0.1 in f64), far less than the margin: blocking. At x = 0.11: clear.
    let at = |x: f32| [[x, 0.1, -0.1], [x, -1.0, 2.0], [x, 1.0, -2.0]];
    assert!(!clear(&[at(0.1)], [0.0, 5.0, 0.0, 1.0]));
    assert!(clear(&[at(0.11)], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn directional_light_blocked_far_away_towards_the_light() {
    let roof = FLOOR.map(|p| [p[0], 400.0, p[2]]);
    assert!(!clear(&[FLOOR, roof], [0.0, 1.0, 0.0, 0.0]));
    // The same roof with the sun shining from below (towards -y) is no longer in the way.
    assert!(clear(&[roof], [0.0, -1.0, 0.0, 0.0]));
}

#[test]
fn degenerate_and_non_finite_triangles() {
    // A zero-area (collinear) triangle inside the pyramid blocks (conservative).
    let line = [[0.0, 1.0, -0.05], [0.0, 2.0, -0.05], [0.0, 3.0, -0.05]];
    assert!(!clear(&[line], [0.0, 5.0, 0.0, 1.0]));
    // A non-finite vertex anywhere blocks.
    let nan = [[f32::NAN, 0.0, 0.0], [50.0, 0.0, 0.0], [50.0, 1.0, 0.0]];
    assert!(!clear(&[FLOOR, nan], [0.0, 5.0, 0.0, 1.0]));
}

fn winding(tris: &[[[f32; 3]; 3]], light: Light) -> Option<u32> {
    let m = mesh(tris);
    ClearanceIndex::build(&m).near_winding(&m, Some(&EdgeAdjacency::build(&m)), &near_points(), light)
}

/// A welded mesh from shared vertices.
fn welded(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> WeldedMesh {
    let n = triangles.len();
    WeldedMesh { positions, triangles, source_triangle: (0..n as u32).collect(), degenerate_triangles: 0 }
}

#[test]
fn shared_edge_of_multiplicity_zero_across_the_pyramid_keeps_w0() {
    // A welded roof square split along x = z, consistently wound (both halves face down,
    // away from... whichever: the same way): its diagonal has multiplicity 0, so W = 1 on
    // both sides and across it. Soup halves (unwelded: open edges) stay unknown.
    let roof = welded(
        vec![[-5.0, 2.0, -5.0], [5.0, 2.0, -5.0], [5.0, 2.0, 5.0], [-5.0, 2.0, 5.0]],
        vec![[0, 3, 2], [0, 2, 1]],
    );
    let light = [0.0, 5.0, 0.0, 1.0];
    let adjacency = EdgeAdjacency::build(&roof);
    let index = ClearanceIndex::build(&roof);
    // The diagonal runs through the eye's pyramid when the eye is at the origin.
    assert_eq!(index.near_winding(&roof, Some(&adjacency), &near_points(), light), Some(1));
    // Without adjacency (per-triangle volumes: faces on every edge) the same is unknown.
    assert_eq!(index.near_winding(&roof, None, &near_points(), light), None);
    // The roof's outer edge (open: multiplicity != 0) across the pyramid: unknown.
    let edge =
        welded(vec![[0.0, 2.0, -5.0], [5.0, 2.0, -5.0], [5.0, 2.0, 5.0], [0.0, 2.0, 5.0]], vec![[0, 3, 2], [0, 2, 1]]);
    let (a, i) = (EdgeAdjacency::build(&edge), ClearanceIndex::build(&edge));
    assert_eq!(i.near_winding(&edge, Some(&a), &near_points(), light), None);
    // A triangle inside the pyramid itself: unknown.
    let inside = welded(vec![[-0.01, -0.01, -0.05], [0.01, -0.01, -0.05], [0.0, 0.01, -0.05]], vec![[0, 1, 2]]);
    let (a, i) = (EdgeAdjacency::build(&inside), ClearanceIndex::build(&inside));
    assert_eq!(i.near_winding(&inside, Some(&a), &near_points(), light), None);
}

#[test]
fn eye_inside_a_shadow_has_its_winding() {
    // One big roof triangle above the eye, light above it: the whole pyramid is behind it.
    let roof = [[-5.0, 2.0, -5.0], [5.0, 2.0, -5.0], [0.0, 2.0, 5.0]];
    assert_eq!(winding(&[FLOOR, roof], [0.0, 5.0, 0.0, 1.0]), Some(1));
    // A slab (two stacked roofs): 2.
    let lower = roof.map(|p| [p[0], 1.5, p[2]]);
    assert_eq!(winding(&[FLOOR, roof, lower], [0.0, 5.0, 0.0, 1.0]), Some(2));
    // A directional light from above: the same.
    assert_eq!(winding(&[FLOOR, roof, lower], [0.0, 1.0, 0.0, 0.0]), Some(2));
    assert!(!clear(&[FLOOR, roof], [0.0, 5.0, 0.0, 1.0]));
}

#[test]
fn shadow_edge_across_the_pyramid_is_unknown() {
    // A roof whose edge x = 0 (seen from the light) runs through the pyramid: part of the
    // near rectangle is in its shadow, part is not.
    let roof = [[0.0, 2.0, -5.0], [5.0, 2.0, -5.0], [0.0, 2.0, 5.0]];
    assert_eq!(winding(&[FLOOR, roof], [0.0, 5.0, 0.0, 1.0]), None);
    // Two roof halves sharing the diagonal through the pyramid: each covers only part.
    let other = [[0.0, 2.0, -5.0], [-5.0, 2.0, 5.0], [0.0, 2.0, 5.0]];
    assert_eq!(winding(&[FLOOR, roof, other], [0.0, 5.0, 0.0, 1.0]), None);
}

#[test]
fn empty_mesh_is_clear_and_a_foreign_mesh_is_not() {
    assert!(clear(&[], [0.0, 5.0, 0.0, 1.0]));
    let a = mesh(&[FLOOR]);
    let b = mesh(&[FLOOR, FLOOR]);
    assert!(!ClearanceIndex::build(&a).is_clear(
        &b,
        Some(&EdgeAdjacency::build(&b)),
        &near_points(),
        [0.0, 5.0, 0.0, 1.0]
    ));
}

/// Segment-triangle crossing without margins (closed barycentric range).
fn crosses_loosely(a: V3, b: V3, t: [V3; 3]) -> bool {
    let dir = sub(b, a);
    let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let pv = cross(dir, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return false;
    }
    let tv = sub(a, t[0]);
    let u = dot(tv, pv) / det;
    let qv = cross(tv, e1);
    let v = dot(dir, qv) / det;
    let s = dot(e2, qv) / det;
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&s)
}

/// Soundness against brute force: whenever the test says clear, no sampled point of any
/// triangle lies inside the hull (checked by its face planes); and a triangle with a sampled
/// point inside the hull is never called clear.
#[test]
fn clear_never_hides_a_triangle_point_inside_the_hull() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let light = [0.3f32, 3.0, -1.0, 1.0];
    let mut points = near_points();
    points.push([0.3, 3.0, -1.0]);
    // A tiny tolerance finds every face despite rounding (with 0, faces whose fourth
    // coplanar point rounds to the other side are missed and "inside" overcounts).
    let hull = Hull::new(points, 1e-12);
    let (mut said_clear, mut said_blocked, mut said_inside) = (0, 0, 0);
    for _ in 0..3000 {
        // Centres around the segment from the eye to the light, so both answers occur.
        let r = rnd() * 1.2 - 0.1;
        let c = [0.3 * r + (rnd() - 0.5) * 0.3, 3.0 * r + (rnd() - 0.5) * 0.3, -r + (rnd() - 0.5) * 0.3];
        let s = 0.05 + rnd() * 0.5;
        let t: [[f32; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|a| (c[a] + (rnd() - 0.5) * s) as f32));
        let inside = (0..=20).any(|i| {
            (0..=20 - i).any(|j| {
                let (a, b) = (i as f64 / 20.0, j as f64 / 20.0);
                let q: V3 = std::array::from_fn(|k| {
                    f64::from(t[0][k]) * (1.0 - a - b) + f64::from(t[1][k]) * a + f64::from(t[2][k]) * b
                });
                hull.faces.iter().all(|&(u, top)| dot(u, q) <= top)
            })
        });
        let is_clear = clear(&[t], light);
        // near_winding's W0: every sampled point of the pyramid crosses exactly W0
        // triangles (here 0 or 1) on its way to the light.
        if let Some(w0) = winding(&[t], light) {
            said_inside += w0;
            let pts = near_points();
            for _ in 0..20 {
                let mut wts: Vec<f64> = pts.iter().map(|_| rnd()).collect();
                let sum: f64 = wts.iter().sum();
                wts.iter_mut().for_each(|w| *w /= sum);
                let x: V3 = std::array::from_fn(|k| pts.iter().zip(&wts).map(|(p, w)| p[k] * w).sum());
                let tv = t.map(|q| q.map(f64::from));
                let crossed = u32::from(crosses_loosely(x, [0.3, 3.0, -1.0], tv));
                assert_eq!(crossed, w0, "point {x:?} of the pyramid, triangle {t:?}");
            }
        }
        assert!(!(inside && is_clear), "triangle {t:?} has a point inside the hull but was called clear");
        if is_clear {
            said_clear += 1;
        } else {
            said_blocked += 1;
        }
    }
    // The test must exercise both answers.
    assert!(said_clear > 300 && said_blocked > 300, "clear {said_clear}, blocked {said_blocked}");
    assert!(said_inside > 10, "W0 = 1 (pyramid inside the triangle's volume) {said_inside} times");
}
