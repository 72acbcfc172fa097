//! [`ClearanceIndex`]: per-mesh cluster boxes, and the two questions asked of them per frame:
//! is the near-plane light pyramid clear ([`ClearanceIndex::is_clear`]), and the one count
//! `W0` every point of it has ([`ClearanceIndex::near_winding`]).

use super::crossing::crossing;
use super::hull::Hull;
use crate::vec3::{norm, sub};
use crate::{Aabb, EdgeAdjacency, Light, WeldedMesh};

/// Triangles per cluster.
pub const CLUSTER: usize = 32;

/// Relative margin: a separating gap must exceed this fraction of the scene's scale.
pub const MARGIN: f64 = 1e-6;

type V3 = [f64; 3];

/// Per-mesh data of the clearance test: one box per cluster of [`CLUSTER`] triangles.
#[derive(Clone, Debug)]
pub struct ClearanceIndex {
    boxes: Vec<([f64; 3], [f64; 3])>,
    bounds: Option<Aabb>,
    triangles: usize,
}

impl ClearanceIndex {
    /// Builds the cluster boxes of `mesh` (once per mesh).
    pub fn build(mesh: &WeldedMesh) -> ClearanceIndex {
        let p = &mesh.positions;
        let boxes = mesh
            .triangles
            .chunks(CLUSTER)
            .map(|chunk| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for t in chunk {
                    for &i in t {
                        let v = p.get(i as usize).copied().unwrap_or([f32::NAN; 3]);
                        for a in 0..3 {
                            let c = f64::from(v[a]);
                            if c.is_finite() {
                                lo[a] = lo[a].min(c);
                                hi[a] = hi[a].max(c);
                            } else {
                                // Unknown: the cluster spans everything.
                                lo[a] = f64::NEG_INFINITY;
                                hi[a] = f64::INFINITY;
                            }
                        }
                    }
                }
                (lo, hi)
            })
            .collect();
        // Bounds of the finite vertices the triangles use.
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for v in mesh.triangles.iter().flatten().filter_map(|&i| p.get(i as usize)) {
            if v.iter().all(|c| c.is_finite()) {
                for a in 0..3 {
                    lo[a] = lo[a].min(v[a]);
                    hi[a] = hi[a].max(v[a]);
                }
            }
        }
        let bounds = (lo[0] <= hi[0]).then_some(Aabb { min: lo, max: hi });
        ClearanceIndex { boxes, bounds, triangles: mesh.triangles.len() }
    }

    /// Whether no triangle of `mesh` (the mesh this index was built from) meets the convex hull
    /// of `points` (the eye and the near-plane rectangle's corners, world space) and the light:
    /// for a point light (w != 0) its position, for a directional light (w = 0) every point
    /// swept towards the light (`+xyz`) beyond the scene's bounds. `true` proves that z-pass
    /// counts every visible sample exactly as z-fail does; `false` may be conservative.
    pub fn is_clear(
        &self,
        mesh: &WeldedMesh,
        adjacency: Option<&EdgeAdjacency>,
        points: &[[f64; 3]],
        light: Light,
    ) -> bool {
        self.near_winding(mesh, adjacency, points, light) == Some(0)
    }

    /// The count `W0` every point of the hull of `points` (the eye and the near-plane corners)
    /// has — the number of triangles between it and the light — when it is provably the same
    /// for all of them (see the module doc); `Some(0)` is [`ClearanceIndex::is_clear`]. None:
    /// unknown (some volume face may cross the pyramid, or bad input).
    pub fn near_winding(
        &self,
        mesh: &WeldedMesh,
        adjacency: Option<&EdgeAdjacency>,
        points: &[[f64; 3]],
        light: Light,
    ) -> Option<u32> {
        if mesh.triangles.len() != self.triangles || points.is_empty() {
            return None;
        }
        let Some(bounds) = self.bounds else {
            // No finite vertex: either no triangle (no volume) or only unknown ones.
            return (self.triangles == 0).then_some(0);
        };
        let l = light.map(f64::from);
        if !l.iter().all(|c| c.is_finite()) || points.iter().flatten().any(|c| !c.is_finite()) {
            return None;
        }
        let (blo, bhi) = (bounds.min.map(f64::from), bounds.max.map(f64::from));
        let diag = norm(sub(bhi, blo));
        let mut far = 0.0f64;
        for p in points {
            far = far.max(norm(sub(*p, blo))).max(norm(sub(*p, bhi)));
        }
        let mut hull_points: Vec<V3> = points.to_vec();
        // The far end of each point's segment towards the light.
        let mut ends: Vec<V3> = Vec::with_capacity(points.len());
        if l[3] != 0.0 {
            let light_pos = [l[0] / l[3], l[1] / l[3], l[2] / l[3]];
            far = far.max(norm(sub(light_pos, blo))).max(norm(sub(light_pos, bhi)));
            hull_points.push(light_pos);
            ends.extend(points.iter().map(|_| light_pos));
        } else {
            let len = norm([l[0], l[1], l[2]]);
            if !(len > 0.0) {
                return None;
            }
            // Far enough that the swept points lie beyond every triangle.
            let reach = 2.0 * (far + diag) + 1.0;
            let d = [l[0] / len * reach, l[1] / len * reach, l[2] / len * reach];
            for p in points {
                hull_points.push([p[0] + d[0], p[1] + d[1], p[2] + d[2]]);
                ends.push([p[0] + d[0], p[1] + d[1], p[2] + d[2]]);
            }
            far += reach;
        }
        let margin = MARGIN * (far + diag).max(1e-30);
        let hull = Hull::new(hull_points, margin);
        let pyramid = Hull::new(points.to_vec(), margin);
        let p = &mesh.positions;
        // Per point: triangles its segment crosses strictly, and whether any was ambiguous.
        let mut crossed = vec![0u32; points.len()];
        let mut ambiguous = vec![false; points.len()];
        for (c, (lo, hi)) in self.boxes.iter().enumerate() {
            if hull.box_apart(*lo, *hi) {
                continue;
            }
            let start = c * CLUSTER;
            let end = (start + CLUSTER).min(mesh.triangles.len());
            for t in &mesh.triangles[start..end] {
                let mut v = [[0.0; 3]; 3];
                for (k, &i) in t.iter().enumerate() {
                    match p.get(i as usize) {
                        Some(q) if q.iter().all(|c| c.is_finite()) => v[k] = q.map(f64::from),
                        _ => return None,
                    }
                }
                if hull.triangle_apart(v) {
                    continue;
                }
                // A triangle in the pyramid itself: the eye's own position changes W.
                if !pyramid.triangle_apart(v) {
                    return None;
                }
                let mut all = true;
                for (k, (a, b)) in points.iter().zip(&ends).enumerate() {
                    match crossing(*a, *b, v) {
                        Some(true) => crossed[k] = crossed[k].checked_add(1)?,
                        Some(false) => all = false,
                        None => {
                            ambiguous[k] = true;
                            all = false;
                        }
                    }
                }
                if all {
                    continue;
                }
                // Partly crossed: fine only when none of its edges of nonzero multiplicity
                // meets the hull (a degenerate triangle a, b, b tests the segment), and only
                // for volumes without faces on edges of multiplicity 0 (adjacency given).
                let adjacency = adjacency?;
                for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                    let (a, b) = (t[i], t[j]);
                    if hull.triangle_apart([v[i], v[j], v[j]]) {
                        continue;
                    }
                    let key = (a.min(b), a.max(b));
                    let e = adjacency.edges.binary_search_by_key(&key, |e| (e[0].min(e[1]), e[0].max(e[1]))).ok()?;
                    let opposites = adjacency.opposites(e);
                    if crate::multiplicity::edge_multiplicity(p, adjacency.edges[e], opposites, light) != 0 {
                        return None;
                    }
                }
            }
        }
        // W0 from the points whose crossings were all unambiguous; they must agree.
        let mut unambiguous = crossed.iter().zip(&ambiguous).filter(|(_, a)| !**a).map(|(c, _)| *c);
        let w0 = unambiguous.next()?;
        unambiguous.all(|c| c == w0).then_some(w0)
    }
}
