//! The surface a depth pass of another precision sees at a pixel: what a mask drawn by another
//! rasterizer (the WebGL viewer's, judged with `umbra verify --external-mask`) is decided on.
//!
//! The reference classifies the samples of *one* depth pass (world position and triangle per
//! pixel, [`crate::Samples`]). A native method draws its volumes against those same samples,
//! so which surface a pixel shows is not part of its decision. A mask from another renderer
//! comes with that renderer's own depth pass, whose rasterizer snaps every vertex to its own
//! `GL_SUBPIXEL_BITS` (Chromium's SwiftShader: 4, `SUBPIXEL_PRECISION_BITS` under
//! `SWIFTSHADER_LEGACY_PRECISION`; llvmpipe: 8): where the projections of two surfaces pass
//! within that precision of a pixel centre, the two depth passes may show different surfaces
//! there, and the mask holds the decision of the surface *it* saw. Found on Crytek Sponza at
//! 320 x 180 (docs/web.md): every one of SwiftShader's 33 samples outside the band without
//! this part lies 0.0004-0.09 pixel from a crease between a triangle facing the light and one
//! facing away, from the silhouette of a nearer object, or from a free edge of its own
//! surface (pixel (119, 2): the reference's triangle 440 faces away from the light, its
//! neighbour 742 across an edge 0.0034 pixel from the centre faces it; SwiftShader's depth
//! pass showed 742, lit).
//!
//! Every primitive's projection moves by at most the lateral bound `δ`
//! ([`RasterView::lateral_pixels`]: both primitives' snapping, which is why it is computed
//! from the judged rasterizer's sub-pixel bits) in either depth pass, so another surface `X`
//! can be seen at pixel centre `c` only if its exact projection comes within `δ` of `c`, and
//! either `X` can lie in front of the sample's triangle `T` somewhere within `δ` of `c`, or
//! `T`'s own surface may not cover `c` (a *free* edge of it — one with no neighbour in its
//! plane across — passes within `δ`; then whatever lies behind may show, or the background).
//! Triangles in `T`'s plane are the same surface: the sample moves along it, which the
//! envelope's lateral term already covers ([`crate::envelope`]). The candidates:
//! * every triangle with an edge whose projection passes within `δ` of `c` (the edges of
//!   [`crate::edge_on`]'s walk), kept when not in `T`'s plane and when its plane's `1/w`
//!   (affine across the screen) can exceed `T`'s within `δ` of `c` by the sample's envelope
//!   radius, or when a free edge of `T`'s surface is within `δ`. The first kind make the
//!   sample SURFACE band for every method, native ones included ([`crate::nearer_contour`]:
//!   the volumes' snapped faces on that edge may cover the pixel), so only the second is left
//!   to this part;
//! * with a free edge within `δ`: every triangle the ray through the sample crosses behind it
//!   ([`segment_crosses`], by signs: a distance compared with 0 missed Sponza's (556, 461) at
//!   1280 x 720), and the background unless one of those covers every point within `δ` of `c`.
//!
//!
//! With front faces only ([`crate::envelope::RasterView::receivers`], both depth passes cull
//! back faces, as three.js draws a `FrontSide` material), a triangle that faces away from the
//! eye is never seen: it is no candidate, unless its facing is within the rasterizer's
//! precision ([`RasterView::facing_uncertain`]: its snapped vertices may wind either way, and
//! one pass may draw it while the other culls it). Such a triangle covers a pixel centre only
//! within `δ` of its edges (its inradius is at most twice the snapping), so the walk above
//! finds it. Behind a free edge, only a triangle that surely faces the eye covers the pixel
//! for every pass, and a coplanar neighbour continues `T`'s surface only when it is wound as
//! `T` ([`free_edge`]).
//!
//! The sample is [`crate::BandParts::SEEN_SURFACE`] when a candidate's own decision — its
//! class and band at the point where the pixel's ray meets its plane, with its own envelope
//! (which covers the rasterizer moving that point along it) — differs from the sample's or is
//! itself band, or when the background may show at a lit sample (a mask shows background as
//! shadow).

use rayon::prelude::*;
use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::vec3::{cross, dot, sub};
use umbra_geom::WeldedMesh;

use crate::edge_on::{clip_to_window, pixels_near_segment};
use crate::envelope::RasterView;

/// A triangle edge whose projection passes within `δ` of a pixel centre: `(pixel, triangle,
/// edge k)` (the edge from vertex `k` to vertex `k + 1`).
pub type NearEdge = (u32, u32, u8);

/// Every `(pixel, triangle, edge)` whose projected edge passes within [`RasterView::lateral_pixels`]
/// of the pixel centre, for the pixels `wanted` accepts; sorted by pixel.
pub fn near_edges(
    mesh: &WeldedMesh,
    view: &RasterView,
    (width, height): (u32, u32),
    wanted: impl Fn(usize) -> bool + Sync,
) -> Vec<NearEdge> {
    let delta = view.lateral_pixels(width, height);
    // One pixel of NDC margin, as the edge-on walk: an edge just outside the viewport still
    // reaches the border pixels' centres within delta.
    let margin = 2.0 / f64::from(width.min(height).max(1));
    let mut out: Vec<NearEdge> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .fold(Vec::new, |mut out, (t, tri)| {
            let clip = tri.map(|k| view.clip(mesh.positions[k as usize].map(f64::from)));
            for k in 0..3 {
                if let Some((p, q)) = clip_to_window(clip[k], clip[(k + 1) % 3], margin, width, height) {
                    pixels_near_segment(p, q, delta, width, height, |x, y| {
                        let i = y as usize * width as usize + x as usize;
                        if wanted(i) {
                            out.push((i as u32, t as u32, k as u8));
                        }
                    });
                }
            }
            out
        })
        .flatten()
        .collect();
    out.par_sort_unstable();
    out
}

/// `1/w` of the plane of `tri` along the ray through window point `c` (pixels, y down), and
/// the length of its gradient across the screen (per pixel): `1/w` of a plane is affine in
/// window coordinates. `None` when a vertex has `w = 0` or the plane passes through the eye
/// (its projection is a line), where no such bound exists.
pub fn inverse_w_plane(
    view: &RasterView,
    tri: [[f64; 3]; 3],
    c: [f64; 2],
    width: u32,
    height: u32,
) -> Option<(f64, f64)> {
    let mut p = [[0f64; 3]; 3];
    for (k, v) in tri.iter().enumerate() {
        let [x, y, w] = view.clip(*v);
        if w == 0.0 || !w.is_finite() {
            return None;
        }
        // Window x, y and 1/w (right for w < 0 too: the map is projective).
        p[k] = [(x / w + 1.0) * 0.5 * f64::from(width), (1.0 - y / w) * 0.5 * f64::from(height), 1.0 / w];
    }
    let (d1, d2) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let det = d1[0] * d2[1] - d2[0] * d1[1];
    let scale = (d1[0].abs() + d1[1].abs()) * (d2[0].abs() + d2[1].abs());
    // `!(x > y)` is meant: NaN gives no plane the same way.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(det.abs() > 1e-12 * scale) {
        return None;
    }
    let a = (d1[2] * d2[1] - d2[2] * d1[1]) / det;
    let b = (d1[0] * d2[2] - d2[0] * d1[2]) / det;
    let q = p[0][2] + a * (c[0] - p[0][0]) + b * (c[1] - p[0][1]);
    (q.is_finite() && a.is_finite() && b.is_finite()).then_some((q, a.hypot(b)))
}

/// Whether the segment `p0 p1` crosses the triangle `tri` (its point on the triangle's plane
/// has barycentrics in `[0, 1]`; a segment in the plane does not cross it). Unlike a distance,
/// which rounding keeps off zero, this tests the signs only.
pub fn segment_crosses(p0: [f64; 3], p1: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> bool {
    let (ab, ac) = (sub(b, a), sub(c, a));
    let n = cross(ab, ac);
    let (s0, s1) = (dot(n, sub(p0, a)), dot(n, sub(p1, a)));
    if !((s0 <= 0.0 && s1 >= 0.0) || (s0 >= 0.0 && s1 <= 0.0)) || s0 == s1 {
        return false;
    }
    let t = s0 / (s0 - s1);
    let x = [0, 1, 2].map(|k| p0[k] + t * (p1[k] - p0[k]));
    let ap = sub(x, a);
    let nn = dot(n, n);
    let v = dot(cross(ap, ac), n) / nn;
    let w = dot(cross(ab, ap), n) / nn;
    v >= 0.0 && w >= 0.0 && v + w <= 1.0
}

/// Every triangle's edges as it walks them, `[from, to, opposite]`, sorted: whether a triangle
/// on an edge is wound as its neighbour across it (it walks the edge the other way).
pub struct DirectedEdges(Vec<[u32; 3]>);

impl DirectedEdges {
    pub fn build(mesh: &WeldedMesh) -> DirectedEdges {
        let mut walks: Vec<[u32; 3]> =
            mesh.triangles.iter().flat_map(|t| (0..3).map(move |k| [t[k], t[(k + 1) % 3], t[(k + 2) % 3]])).collect();
        walks.par_sort_unstable();
        DirectedEdges(walks)
    }

    /// Whether some triangle walks the edge `from -> to` with `opposite` as its third vertex.
    pub fn walks(&self, from: u32, to: u32, opposite: u32) -> bool {
        self.0.binary_search(&[from, to, opposite]).is_ok()
    }
}

/// Whether the edge `k` of triangle `t` is *free* for its surface: no other triangle on it
/// lies in `t`'s plane (within `tolerance`, world units) on the other side of the edge. With
/// `front_only` (the depth passes cull back faces, [`crate::envelope::RasterView::receivers`])
/// only a neighbour wound as `t` continues it: one wound the other way faces away from the eye
/// wherever `t` faces it, and is culled.
pub fn free_edge(
    mesh: &WeldedMesh,
    adjacency: &EdgeAdjacency,
    t: u32,
    k: u8,
    tolerance: f64,
    front_only: Option<&DirectedEdges>,
) -> bool {
    let tri = mesh.triangles[t as usize];
    let (ia, ib, io) = (tri[k as usize], tri[(k as usize + 1) % 3], tri[(k as usize + 2) % 3]);
    let key = [ia.min(ib), ia.max(ib)];
    let Ok(e) = adjacency.edges.binary_search_by(|edge| [edge[0].min(edge[1]), edge[0].max(edge[1])].cmp(&key)) else {
        return true;
    };
    let pos = |v: u32| mesh.positions[v as usize].map(f64::from);
    let (a, b, o) = (pos(ia), pos(ib), pos(io));
    let n = cross(sub(b, a), sub(o, a));
    let nlen = dot(n, n).sqrt();
    // `!(x > 0.0)` is meant: a NaN normal has no plane either.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(nlen > 0.0) {
        return true;
    }
    // Which side of the edge, within the plane: the sign of (b - a) x (p - a) along n.
    let side = |p: [f64; 3]| dot(cross(sub(b, a), sub(p, a)), n);
    let own = side(o);
    !adjacency.opposites(e).iter().any(|&v| {
        let p = pos(v);
        (dot(n, sub(p, a)) / nlen).abs() <= tolerance
            && side(p) * own < 0.0
            && front_only.is_none_or(|walks| walks.walks(ib, ia, v))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envelope::BandParts;
    use crate::SampleClass;
    use umbra_geom::camera::Camera;

    /// Crytek Sponza (`/work/shared/scenes/crytek-sponza.obj.gz`), its default view and light
    /// (`umbra export`'s) at 320 x 180: a ledge whose underside (triangle 440, and 721, the
    /// same triangle the other way round) the eye sees facing away from the light, and its
    /// front (742) across the shared edge facing it. Pixel (119, 2): the reference's sample
    /// lies on 440, the pixel centre 0.0034 pixel from the edge; SwiftShader (1/16 pixel) and
    /// llvmpipe with every vertex on its grid showed 742 there, lit: a false light outside
    /// the band until the band had SEEN_SURFACE.
    use crate::pinned::PinnedView as Ledge;

    fn ledge() -> Ledge {
        let f = |b: [u32; 3]| b.map(f32::from_bits);
        // Welded vertices 399, 403, 405 and 629.
        let positions = [
            [3235463167, 1085636608, 3223535615],
            [1085169665, 1085636608, 3217866749],
            [3234390017, 1085636608, 3217866749],
            [3234390017, 1085726721, 3217866749],
        ]
        .map(f)
        .to_vec();
        Ledge {
            positions,
            // 440, 721, 742.
            triangles: vec![[0, 1, 2], [0, 2, 1], [3, 1, 2]],
            light: [2.1777349, 6.01377, 0.7585938, 1.0],
            // llvmpipe's interpolated position at (119, 2): (0.58920467, 5.671875, -1.5997431).
            sample: f([1058461214, 1085636608, 3217867874]),
            camera: Camera {
                eye: [-5.027343273162842, 3.5838383793830877, -0.2421875],
                target: [4.269531726837158, 2.1258792519569396, -0.2421875],
                up: [0.0, 1.0, 0.0],
                fov_y_degrees: 60.0,
                near: 0.028966756820678712,
                ..Camera::default()
            },
        }
    }

    /// Crytek Sponza at 1280 x 720, pixel (556, 461): a sample on triangle 116392, shadowed by
    /// 116370 in front of it towards the light, 0.0099 pixel from a free edge of its surface;
    /// behind it, through that edge, a lit surface (88854). SwiftShader's depth pass showed
    /// 88854, lit. The first seen-surface tested "what lies behind" with a point-to-plane
    /// distance compared with 0, which rounding missed: the sample stayed outside the band.
    fn sponza_free_edge() -> Ledge {
        let f = |b: [u32; 3]| b.map(f32::from_bits);
        // Welded vertices 64225, 64228, 64226 (116392), 64181, 64184, 64182 (116370) and
        // 48900, 48901, 48902 (88854).
        let positions = [
            [1078763522, 1062658057, 3215867903],
            [1078755326, 1062641666, 3216056319],
            [1078116353, 1068154877, 3216056319],
            [1078804479, 1062707197, 3215966209],
            [1078714369, 1062592508, 3215966209],
            [1078083583, 1068130307, 3215966209],
            [1084850176, 1066745859, 3217678332],
            [1084628991, 3162234633, 3218464764],
            [1084628991, 1066745859, 3218464764],
        ]
        .map(f)
        .to_vec();
        Ledge {
            positions,
            triangles: vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
            // llvmpipe's interpolated position: (3.1787035, 0.89245445, -1.3836548).
            sample: f([1078685665, 1063548901, 3216055194]),
            ..ledge()
        }
    }

    #[test]
    fn sponza_lit_surface_behind_a_free_edge_is_seen_surface_band() {
        let scene = sponza_free_edge();
        let (pixel, class, parts) = judged_at(&scene, 4, true, (1280, 720));
        assert_eq!(pixel, (556, 461));
        assert_eq!(class, SampleClass::Shadowed);
        assert!(!parts.intersects(BandParts::SILHOUETTE), "{:?}", parts.names());
        assert!(parts.contains(BandParts::SEEN_SURFACE), "{:?}", parts.names());
        assert_eq!(judged_at(&scene, 4, false, (1280, 720)).2, BandParts::NONE);
    }

    /// The pixel `scene`'s sample projects to, its class and band parts at `bits` sub-pixel
    /// bits, judged as an external mask (`other_depth_pass`) or as the samples' own method.
    fn judged(scene: &Ledge, bits: u32, other_depth_pass: bool) -> ((u32, u32), SampleClass, BandParts) {
        judged_at(scene, bits, other_depth_pass, (320, 180))
    }

    /// [`judged`] at `width x height`.
    fn judged_at(
        scene: &Ledge,
        bits: u32,
        other_depth_pass: bool,
        size: (u32, u32),
    ) -> ((u32, u32), SampleClass, BandParts) {
        scene.judged(bits, other_depth_pass, size)
    }

    #[test]
    fn sponza_ledge_crease_is_seen_surface_band_for_a_mask_of_another_depth_pass() {
        let scene = ledge();
        let (pixel, class, parts) = judged(&scene, 4, true);
        assert_eq!(pixel, (119, 2));
        // The underside faces away from the light as the eye sees it: shadowed by the plane
        // test, and nothing else about the decision is uncertain.
        assert_eq!(class, SampleClass::Shadowed);
        assert!(!parts.intersects(BandParts::SILHOUETTE), "{:?}", parts.names());
        assert!(parts.contains(BandParts::SEEN_SURFACE), "{:?}", parts.names());
        // The samples' own depth pass (a native method): not band.
        let (_, _, own) = judged(&scene, 4, false);
        assert_eq!(own, BandParts::NONE, "{:?}", own.names());
    }

    /// Crytek Sponza at 320 x 180, pixel (94, 0): a sample on triangle 223, lit, and the edge
    /// of a nearer object (triangles 109771 and 109772, at 0.94 of the sample's distance, one
    /// facing the light, one facing away) 0.0058 pixel from the pixel centre. SwiftShader's
    /// depth pass shows the nearer object there, in shadow: a false shadow outside the band
    /// but for SEEN_SURFACE (not the sample's facing disagreeing at SwiftShader's precision:
    /// its light lies 7e-7 off its plane along the segment, which the plane test does not
    /// see).
    fn sponza_top_row() -> Ledge {
        let f = |b: [u32; 3]| b.map(f32::from_bits);
        // Welded vertices 214, 212, 215 (triangle 223) and 60634, 60643, 60641, 60640.
        let positions = [
            [3217580035, 1083064319, 3218038782],
            [3217801217, 1085816831, 3218038782],
            [3215998975, 1083916287, 3218038782],
            [3219570685, 1084022785, 3217309695],
            [3219374081, 1084071935, 3217309695],
            [3218481156, 1083793409, 3217309695],
            [3218481156, 1083793409, 3220299772],
        ]
        .map(f)
        .to_vec();
        Ledge {
            positions,
            triangles: vec![[0, 1, 2], [3, 4, 5], [4, 6, 5]],
            // llvmpipe's interpolated position at (94, 0): (-1.4958781, 4.935857, -1.6201173).
            sample: f([3216996591, 1084093066, 3218038785]),
            ..ledge()
        }
    }

    #[test]
    fn sponza_nearer_silhouette_is_surface_band_for_every_depth_pass() {
        // First made band as SEEN_SURFACE (for another depth pass only); the same nearer edge
        // also decides whether the nearer object's volume covers the pixel in the samples' own
        // depth pass, so it is SURFACE band for every method (crate::nearer_contour).
        let scene = sponza_top_row();
        for other_depth_pass in [true, false] {
            let (pixel, class, parts) = judged(&scene, 4, other_depth_pass);
            assert_eq!(pixel, (94, 0));
            assert_eq!(class, SampleClass::Lit);
            assert!(parts.contains(BandParts::SURFACE), "{:?}", parts.names());
            // At llvmpipe's 8 bits the edge (0.0058 pixel away) is still within the lateral
            // bound (0.0061 pixel at 320 x 180): the band follows the judged rasterizer's bits.
            assert!(judged(&scene, 8, other_depth_pass).2.contains(BandParts::SURFACE));
        }
    }

    #[test]
    fn the_same_silhouette_behind_the_sample_is_not_band() {
        // The nearer object pushed along the eye's rays to 1.2 times its distance (0.94 -> 1.13
        // of the sample's): the same projection, 0.0058 pixel from the centre, but behind the
        // sample's own triangle, which covers every point within the lateral bound.
        let mut scene = sponza_top_row();
        let eye = scene.camera.eye;
        for p in &mut scene.positions[3..] {
            *p = std::array::from_fn(|k| (eye[k] + 1.2 * (f64::from(p[k]) - eye[k])) as f32);
        }
        let (pixel, class, parts) = judged(&scene, 4, true);
        assert_eq!(pixel, (94, 0));
        assert_eq!(class, SampleClass::Lit);
        assert_eq!(parts, BandParts::NONE, "{:?}", parts.names());
    }

    #[test]
    fn the_same_ledge_away_from_its_crease_is_not_band() {
        // 0.1 units further under the ledge (about 4 pixels from the edge on the screen).
        let mut scene = ledge();
        scene.sample[2] -= 0.1;
        let (pixel, class, parts) = judged(&scene, 4, true);
        assert_ne!(pixel, (119, 2));
        assert_eq!(class, SampleClass::Shadowed);
        assert_eq!(parts, BandParts::NONE, "{:?}", parts.names());
    }

    /// A view straight down -z from the origin, 90 degrees, 100 x 100 pixels (column-major).
    fn view() -> RasterView {
        // x_clip = x, y_clip = y, w = -z (near plane and depth row are irrelevant here).
        let mut m = [0.0; 16];
        m[0] = 1.0;
        m[5] = 1.0;
        m[11] = -1.0;
        m[10] = -1.0;
        m[14] = -0.1;
        RasterView::new(m)
    }

    #[test]
    fn inverse_w_is_affine_across_the_screen() {
        // A plane z = -2 - x: at the centre w = 2; at window x = 100 (x/w = 1, x = w = 2 + x
        // on the plane: no finite point), so take two columns and check linearity.
        let tri = [[-1.0, -1.0, -1.0], [1.0, -1.0, -3.0], [0.0, 1.0, -2.0]];
        let v = view();
        let (q, g) = inverse_w_plane(&v, tri, [50.0, 50.0], 100, 100).unwrap();
        assert!((q - 0.5).abs() < 1e-12, "{q}");
        // Along the ray through window (75, 50): x/w = 0.5, w = 2 + x = 2 + 0.5 w: w = 4.
        let (q2, _) = inverse_w_plane(&v, tri, [75.0, 50.0], 100, 100).unwrap();
        assert!((q2 - 0.25).abs() < 1e-12, "{q2}");
        assert!((g - 0.25 / 25.0).abs() < 1e-12, "{g}");
        // A plane through the eye has no such function.
        assert!(inverse_w_plane(&v, [[0.0, 0.0, -1.0], [0.0, 1.0, -1.0], [0.0, 0.0, -2.0]], [50.0, 50.0], 100, 100)
            .is_none());
    }

    #[test]
    fn a_segment_crosses_a_triangle_by_its_signs() {
        // A tilted triangle whose plane the f64 distance of the crossing point never reaches 0.
        let tri = [[0.1, 0.2, 0.3], [1.7, 0.1, 0.9], [0.3, 1.9, 1.3]];
        let through = [0.6, 0.6, 0.0];
        assert!(segment_crosses(through, [0.6, 0.6, 3.0], tri));
        assert!(!segment_crosses(through, [0.6, 0.6, 0.1], tri), "ends before the plane");
        assert!(!segment_crosses([3.0, 3.0, 0.0], [3.0, 3.0, 3.0], tri), "misses beside it");
    }

    #[test]
    fn an_edge_is_free_unless_a_coplanar_triangle_continues_the_surface_across_it() {
        // Two triangles of the plane z = 0 sharing edge 1-2, and a third on that edge folded up.
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
        let flat = WeldedMesh {
            positions: positions.clone(),
            triangles: vec![[0, 1, 2], [1, 3, 2]],
            source_triangle: vec![0, 1],
            degenerate_triangles: 0,
        };
        let adjacency = EdgeAdjacency::build(&flat);
        assert!(!free_edge(&flat, &adjacency, 0, 1, 1e-9, None), "edge 1-2 continues into triangle 1");
        assert!(free_edge(&flat, &adjacency, 0, 0, 1e-9, None), "edge 0-1 is the border");
        let folded = WeldedMesh {
            positions,
            triangles: vec![[0, 1, 2], [1, 4, 2]],
            source_triangle: vec![0, 1],
            degenerate_triangles: 0,
        };
        let adjacency = EdgeAdjacency::build(&folded);
        assert!(free_edge(&folded, &adjacency, 0, 1, 1e-9, None), "a crease: the neighbour is not in the plane");
    }

    #[test]
    fn with_front_faces_only_a_neighbour_wound_the_other_way_ends_the_surface() {
        // The plane z = 0 again, the second triangle wound as the first (it walks 2 -> 1) or
        // the other way round (1 -> 2): seen from +z it faces away from the eye, and is culled.
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        for (second, free) in [([1, 3, 2], false), ([1, 2, 3], true)] {
            let mesh = WeldedMesh {
                positions: positions.clone(),
                triangles: vec![[0, 1, 2], second],
                source_triangle: vec![0, 1],
                degenerate_triangles: 0,
            };
            let adjacency = EdgeAdjacency::build(&mesh);
            let walks = DirectedEdges::build(&mesh);
            assert!(!free_edge(&mesh, &adjacency, 0, 1, 1e-9, None), "both faces: {second:?} continues it");
            assert_eq!(free_edge(&mesh, &adjacency, 0, 1, 1e-9, Some(&walks)), free, "front faces only: {second:?}");
        }
    }
}
