//! The two outputs, [`extract`] and [`extract_indexed`], against the straightforward serial
//! emission, bit for bit; buffer reuse and re-entrance of the per-thread scratch.

use super::emit::SCRATCH;
use super::volume::point;
use super::*;
use crate::multiplicity::triangle_orientation;
use crate::weld::tests::{reference_inputs, reference_lights};
use crate::weld::weld;

/// The straightforward serial emission (one edge after another, one triangle after
/// another) that [`extract`] must reproduce exactly.
fn reference_extract(mesh: &WeldedMesh, adj: &EdgeAdjacency, light: Light, caps: bool) -> VolumeGeometry {
    let mut out = VolumeGeometry::default();
    let p = &mesh.positions;
    for e in 0..adj.len() {
        let [a, b] = adj.edges[e];
        let m = edge_multiplicity(p, [a, b], adj.opposites(e), light);
        let (a, b) = (p[a as usize], p[b as usize]);
        let (a_inf, b_inf) = (extrude(a, light), extrude(b, light));
        let (a, b) = (point(a), point(b));
        let quad = if m > 0 { [b, a, a_inf, b, a_inf, b_inf] } else { [a, b, b_inf, a, b_inf, a_inf] };
        for _ in 0..m.unsigned_abs() {
            out.sides.extend_from_slice(&quad);
        }
    }
    if caps {
        for &tri in &mesh.triangles {
            let s = triangle_orientation(p, tri, light);
            if s == 0 {
                continue;
            }
            let [i0, i1, i2] = if s > 0 { tri } else { [tri[0], tri[2], tri[1]] };
            let [p0, p1, p2] = [i0, i1, i2].map(|i| p[i as usize]);
            out.light_caps.extend_from_slice(&[point(p0), point(p1), point(p2)]);
            if light[3] != 0.0 {
                out.dark_caps.extend_from_slice(&[extrude(p0, light), extrude(p2, light), extrude(p1, light)]);
            }
        }
    }
    out
}

/// Bit patterns, so that `-0.0 != 0.0` and NaN == NaN.
fn bits(v: &VolumeGeometry) -> [Vec<[u32; 4]>; 3] {
    [&v.sides, &v.light_caps, &v.dark_caps].map(|l| l.iter().map(|x| x.map(f32::to_bits)).collect())
}

/// Many chunks, multiplicities up to ±n on non-manifold edges, edge-on triangles, both
/// light kinds, caps on and off; one `out` reused across all of it, growing and
/// shrinking: the parallel two-pass emission equals the serial one bit for bit.
#[test]
fn extract_matches_serial_reference_with_reused_output() {
    let mut out = VolumeGeometry::default();
    let mut indexed = IndexedVolume::default();
    let (mut nonempty, mut with_caps, mut degenerate) = (0, 0, 0);
    for mesh in reference_inputs() {
        let w = weld(&mesh);
        let adj = EdgeAdjacency::build(&w);
        let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
        for light in reference_lights(&w) {
            for caps in [true, false] {
                extract(&w, &adj, light, caps, &mut out);
                let expected = reference_extract(&w, &adj, light, caps);
                assert!(bits(&out) == bits(&expected), "light {light:?} caps {caps}");
                nonempty += !out.sides.is_empty() as usize;
                // The indexed caps stand for the very same vertices, plus degenerate caps
                // exactly for the edge-on triangles.
                extract_indexed(&w, &adj, &slots, light, caps, &mut indexed);
                assert_eq!(indexed.sides, expected.sides, "indexed sides, light {light:?}");
                assert_eq!(indexed.caps.len(), if caps { w.triangles.len() } else { 0 });
                for (&cap, &tri) in indexed.caps.iter().zip(&w.triangles) {
                    let edge_on = triangle_orientation(&w.positions, tri, light) == 0;
                    assert_eq!(is_degenerate_cap(cap), edge_on, "{tri:?} {cap:?}");
                    degenerate += edge_on as usize;
                }
                let drawn = IndexedVolume {
                    sides: indexed.sides.clone(),
                    caps: indexed.caps.iter().copied().filter(|&c| !is_degenerate_cap(c)).collect(),
                    far_caps: Vec::new(),
                };
                assert!(bits(&drawn.expand(&w.positions, light)) == bits(&expected), "indexed, light {light:?}");
                with_caps += drawn.caps.len();
            }
        }
    }
    assert!(nonempty >= 8, "the inputs must cast silhouettes ({nonempty})");
    assert!(
        with_caps > 1000 && degenerate > 0,
        "the inputs must have caps ({with_caps}) and edge-on triangles ({degenerate})"
    );
}

/// A warmed-up frame of the same size reuses every buffer: the output's and the
/// per-thread scratch's (no reallocation, hence no allocation of ours).
#[test]
fn extract_reuses_buffers_when_warm() {
    let w = weld(&reference_inputs()[1]);
    let adj = EdgeAdjacency::build(&w);
    let light = reference_lights(&w)[0];
    let mut out = VolumeGeometry::default();
    extract(&w, &adj, light, true, &mut out);
    assert!(!out.sides.is_empty() && !out.light_caps.is_empty() && !out.dark_caps.is_empty());
    let buffers = |out: &VolumeGeometry| {
        let s = SCRATCH.with(|cell| {
            let s = cell.borrow();
            [
                s.multiplicity.as_ptr() as usize,
                s.orientation.as_ptr() as usize,
                s.side_offsets.as_ptr() as usize,
                s.cap_offsets.as_ptr() as usize,
            ]
        });
        [
            out.sides.as_ptr() as usize,
            out.light_caps.as_ptr() as usize,
            out.dark_caps.as_ptr() as usize,
            s[0],
            s[1],
            s[2],
            s[3],
        ]
    };
    let warm = buffers(&out);
    for caps in [true, false, true] {
        extract(&w, &adj, light, caps, &mut out);
        assert_eq!(buffers(&out), warm, "caps {caps}");
    }
    // The indexed variant reuses its own output the same way (its scratch is that of the
    // rayon worker that runs it).
    let mut indexed = IndexedVolume::default();
    let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
    extract_indexed(&w, &adj, &slots, light, true, &mut indexed);
    assert!(!indexed.caps.is_empty());
    let warm_indexed = [indexed.sides.as_ptr() as usize, indexed.caps.as_ptr() as usize];
    for caps in [true, false, true] {
        extract_indexed(&w, &adj, &slots, light, caps, &mut indexed);
        assert_eq!([indexed.sides.as_ptr() as usize, indexed.caps.as_ptr() as usize], warm_indexed);
    }
}

/// An extraction running inside another one on the same thread (a rayon worker picks up
/// a second frame's job while it waits) gets its own scratch instead of a borrow panic.
#[test]
fn extract_reentrant_on_one_thread() {
    let mesh = &reference_inputs()[0];
    let w = weld(mesh);
    let adj = EdgeAdjacency::build(&w);
    let light = reference_lights(&w)[0];
    let expected = reference_extract(&w, &adj, light, true);
    SCRATCH.with(|cell| {
        let _held = cell.borrow_mut();
        let mut out = VolumeGeometry::default();
        extract(&w, &adj, light, true, &mut out);
        assert!(bits(&out) == bits(&expected));
    });
}

/// Every directed edge of the clamped volume's triangles (sides, light caps, far caps), by the
/// bits of its endpoints, appears as often as its reverse: the surface is closed, so every
/// sample's count is its winding number (docs/exactness.md).
fn assert_closed(v: &IndexedVolume, positions: &[[f32; 3]], caps: bool) {
    use std::collections::HashMap;
    let key = |p: [f32; 4]| p.map(f32::to_bits);
    let mut count: HashMap<([u32; 4], [u32; 4]), i64> = HashMap::new();
    let mut add = |t: [[f32; 4]; 3]| {
        for i in 0..3 {
            let (a, b) = (key(t[i]), key(t[(i + 1) % 3]));
            *count.entry((a, b)).or_default() += 1;
            *count.entry((b, a)).or_default() -= 1;
        }
    };
    for t in v.sides.chunks_exact(3).chain(v.far_caps.chunks_exact(3)) {
        add([t[0], t[1], t[2]]);
    }
    if caps {
        for &c in v.caps.iter().filter(|&&c| !is_degenerate_cap(c)) {
            add(c.map(|i| point(positions[i as usize])));
        }
    }
    assert!(count.values().all(|&n| n == 0), "the clamped volume is not closed");
}

/// [`extract_clamped`] with every triangle kept and every far end at infinity is
/// [`extract_indexed`]; with triangles dropped and finite far ends it is a closed surface
/// whose sides are the silhouette of the kept triangles.
/// The orthographic views' volumes (`receivers::clamp_beyond_box`): every far end finite, every
/// volume closed, the far caps those of every cap-drawing triangle.
#[test]
fn volumes_closed_beyond_the_box_are_finite_and_closed() {
    let mut checked = 0;
    for mesh in reference_inputs() {
        let w = weld(&mesh);
        let Some(bounds) = mesh.bounds() else { continue };
        let adj = EdgeAdjacency::build(&w);
        let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
        for light in reference_lights(&w) {
            let mut clamp = VolumeClamp::default();
            if crate::receivers::clamp_beyond_box(&w, light, bounds, &mut clamp).is_err() {
                continue;
            }
            let mut volume = IndexedVolume::default();
            extract_clamped(&w, &adj, &slots, light, true, &clamp, &mut volume);
            assert!(volume.sides.iter().chain(&volume.far_caps).all(|v| v[3] == 1.0), "finite far ends");
            let capped = w
                .triangles
                .iter()
                .zip(&clamp.keep)
                .filter(|&(&t, &k)| k && triangle_orientation(&w.positions, t, light) != 0)
                .count();
            assert_eq!(volume.far_caps.len(), 3 * capped);
            assert_closed(&volume, &w.positions, true);
            checked += usize::from(!volume.far_caps.is_empty());
        }
    }
    assert!(checked > 5, "the inputs must exercise the check: {checked} volumes with far caps");
}

#[test]
fn extract_clamped_is_extract_indexed_unclamped_and_closed_when_clamped() {
    for mesh in reference_inputs() {
        let w = weld(&mesh);
        let adj = EdgeAdjacency::build(&w);
        let slots = TriangleSlots::build(&w, &adj).expect("the adjacency of the mesh");
        for light in reference_lights(&w) {
            let mut plain = IndexedVolume::default();
            extract_indexed(&w, &adj, &slots, light, true, &mut plain);
            let open = VolumeClamp::unclamped(light, w.triangles.len(), w.positions.len());
            let mut clamped = IndexedVolume::default();
            extract_clamped(&w, &adj, &slots, light, true, &open, &mut clamped);
            assert_eq!(clamped.sides, plain.sides);
            assert_eq!(clamped.caps, plain.caps);
            // Far caps all at infinity: the dark caps, bit for bit, where the unclamped volume
            // draws them (z-fail, point light), none elsewhere.
            let dark = plain.expand(&w.positions, light).dark_caps;
            let drawn_dark: Vec<[f32; 4]> = plain
                .caps
                .iter()
                .zip(dark.chunks_exact(3))
                .filter(|(&c, _)| !is_degenerate_cap(c))
                .flat_map(|(_, d)| d.iter().copied())
                .collect();
            assert!(
                bits(&VolumeGeometry { dark_caps: clamped.far_caps.clone(), ..Default::default() })
                    == bits(&VolumeGeometry { dark_caps: drawn_dark, ..Default::default() })
            );
            extract_clamped(&w, &adj, &slots, light, false, &open, &mut clamped);
            assert!(clamped.far_caps.is_empty(), "z-pass draws no cap at infinity");
            // Drop every third triangle and give the vertices finite far ends of their own.
            let mut clamp = open.clone();
            for (t, k) in clamp.keep.iter_mut().enumerate() {
                *k = t % 3 != 1;
            }
            for (i, f) in clamp.far.iter_mut().enumerate() {
                *f = if light[3] != 0.0 { 2.0 + (i % 5) as f32 } else { 3.0 + (i % 7) as f32 };
            }
            for caps in [true, false] {
                extract_clamped(&w, &adj, &slots, light, caps, &clamp, &mut clamped);
                assert!(clamped.sides.iter().all(|v| v[3] == 1.0), "finite far ends");
                // The far caps close the volume whatever the counting (z-pass needs them too).
                let kept_caps = w
                    .triangles
                    .iter()
                    .zip(&clamp.keep)
                    .filter(|&(&t, &k)| k && triangle_orientation(&w.positions, t, light) != 0)
                    .count();
                assert_eq!(clamped.far_caps.len(), 3 * kept_caps);
                if caps {
                    assert_closed(&clamped, &w.positions, true);
                }
            }
        }
    }
}
