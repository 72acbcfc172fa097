//! The reference's tests of other surfaces at a pixel: SURFACE's nearer contours
//! ([`crate::nearer_contour`]) for every method, and SEEN_SURFACE ([`crate::seen_surface`]) for
//! masks decided on another depth pass. Both start from the edges whose projections pass within
//! the lateral bound of a pixel centre ([`crate::seen_surface::near_edges`]).

use rayon::prelude::*;
use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::vec3::{cross, dot, norm, sub};

use super::{to_f64, Context, Envelope, SampleClass, Samples};
use crate::envelope::{BandParts, RasterView};
use crate::nearer_contour::PixelSurface;
use crate::seen_surface::{free_edge, inverse_w_plane, segment_crosses, DirectedEdges, NearEdge};
use umbra_geom::frame::Receivers;

impl Context<'_> {
    /// SURFACE's nearer contours (crate::envelope): marks the samples at whose pixel the
    /// projected edge of another surface lying in front of the sample passes within
    /// [`RasterView::lateral_pixels`] of the centre. Whether the rasterizer covers the pixel
    /// with that triangle is then a precision question, and the volumes count it: its light
    /// cap, pushed to the far plane (paper 003 Eq. 6), counts under z-fail as if the triangle
    /// hid the sample, and its side on that edge, in front of the sample, counts under z-pass;
    /// the reference's exact ray misses the triangle. Found on Crytek Sponza, fly-through
    /// keyframe 0 at 2560 x 1440, pixel (629, 1413): the ray passes 0.001 pixel from the edge
    /// of a light-facing triangle 0.6 units in front of the sample; gs-triangle, gs- and
    /// ts-silhouette counted its cap (false shadow). `near`: [`crate::seen_surface::near_edges`] of the samples
    /// that are not band yet, sorted by pixel.
    pub(super) fn mark_nearer_contours(&self, samples: &Samples, near: &[NearEdge], parts: &mut [BandParts]) {
        let Some(view) = self.view else { return };
        let delta = self.lateral_pixels;
        let marked: Vec<usize> = near
            .chunk_by(|a, b| a.0 == b.0)
            .collect::<Vec<_>>()
            .par_iter()
            .filter_map(|group| {
                let i = group[0].0 as usize;
                let at = self.pixel_surface(samples, view, i);
                group
                    .iter()
                    .any(|&(_, id, k)| {
                        !at.same_surface(self.mesh, id)
                            && !at.across_own_edge(self.mesh, id, k)
                            && at.in_front(self.mesh, view, id, delta)
                    })
                    .then_some(i)
            })
            .collect();
        for i in marked {
            parts[i] |= BandParts::SURFACE;
        }
    }

    /// Which faces the depth passes show ([`RasterView::receivers`]; both without a view).
    fn receivers(&self) -> Receivers {
        self.view.map_or(Receivers::Both, |v| v.receivers)
    }

    /// Whether triangle `id` faces away from the eye (its counter-clockwise side, GL's front
    /// face, does not face it), and whether that is within the rasterizer's precision: its
    /// snapped vertices may wind either way ([`RasterView::facing_uncertain`], the same test
    /// as the samples' FACING part), or its plane passes through the eye.
    fn faces_away(&self, id: u32) -> (bool, bool) {
        let tri = self.mesh.triangles[id as usize].map(|k| self.vertex(k));
        let [a, b, c] = tri;
        let eye_side = dot(cross(sub(b, a), sub(c, a)), sub(self.eye_for(a), a));
        let uncertain = eye_side == 0.0
            || !eye_side.is_finite()
            || self.view.is_some_and(|v| v.facing_uncertain(tri, self.width, self.height));
        (eye_side < 0.0, uncertain)
    }

    /// Whether a depth pass may show triangle `id`: every triangle with both faces; with front
    /// faces only, not one that faces away from the eye beyond the rasterizer's precision.
    fn may_show(&self, id: u32) -> bool {
        match self.receivers() {
            Receivers::Both => true,
            Receivers::Front => {
                let (away, uncertain) = self.faces_away(id);
                !away || uncertain
            }
        }
    }

    /// Whether every depth pass draws triangle `id` (none culls it): with front faces only, it
    /// faces the eye beyond the rasterizer's precision.
    fn surely_shown(&self, id: u32) -> bool {
        match self.receivers() {
            Receivers::Both => true,
            Receivers::Front => {
                let (away, uncertain) = self.faces_away(id);
                !away && !uncertain
            }
        }
    }

    /// The sample at pixel `i` as the surface tests see it ([`PixelSurface`]).
    fn pixel_surface(&self, samples: &Samples, view: &RasterView, i: usize) -> PixelSurface {
        let (width, height) = (self.width, self.height);
        let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
        let c = [f64::from(x) + 0.5, f64::from(y) + 0.5];
        let t = samples.triangle[i];
        let tri = self.mesh.triangles[t as usize].map(|k| self.vertex(k));
        let [a, b, cc] = tri;
        let n = cross(sub(b, a), sub(cc, a));
        let nn = dot(n, n);
        let mut s = to_f64(samples.world_pos[i]);
        if nn > 0.0 {
            let k = dot(n, sub(s, a)) / nn;
            s = [s[0] - k * n[0], s[1] - k * n[1], s[2] - k * n[2]];
        }
        let m = &view.clip_from_world;
        PixelSurface {
            x,
            y,
            size: (width, height),
            centre: c,
            triangle: t,
            corner: a,
            normal: n,
            normal_len: nn.sqrt(),
            s,
            position: RasterView::position_margin(s, self.eye),
            radius: self.face_radius(tri, s),
            own: inverse_w_plane(view, tri, c, width, height),
            w_gradient: norm([m[3], m[7], m[11]]),
        }
    }

    /// SEEN_SURFACE ([`crate::seen_surface`]) of the samples another depth pass may show another
    /// surface at: marks `parts`, and returns the envelopes of the other surfaces whose own
    /// decision agrees with the sample's, for the edge-on faces (sorted by pixel).
    pub(super) fn seen_surfaces(
        &self,
        samples: &Samples,
        near: &[NearEdge],
        class: &[SampleClass],
        parts: &mut [BandParts],
    ) -> Vec<(usize, [f64; 3], f64)> {
        let delta = self.lateral_pixels;
        let adjacency = EdgeAdjacency::build(self.mesh);
        let walks = (self.receivers() == Receivers::Front).then(|| DirectedEdges::build(self.mesh));
        // The pixels of `near` still outside the band (SURFACE's nearer contours took some).
        let groups: Vec<&[NearEdge]> = near
            .chunk_by(|a, b| a.0 == b.0)
            .filter(|g| !parts[g[0].0 as usize].intersects(BandParts::SILHOUETTE))
            .collect();
        let results: Vec<(usize, bool, Vec<Envelope>)> = groups
            .par_iter()
            .map(|group| {
                let i = group[0].0 as usize;
                let (mark, others) = self.seen_at(samples, (&adjacency, walks.as_ref()), i, class[i], group, delta);
                (i, mark, others)
            })
            .collect();
        let mut others = Vec::new();
        for (i, mark, envelopes) in results {
            if mark {
                parts[i] |= BandParts::SEEN_SURFACE;
            } else {
                others.extend(envelopes.into_iter().map(|(s, r)| (i, s, r)));
            }
        }
        others
    }

    /// Whether another depth pass may show, at pixel `i` (sample of class `class`), a surface
    /// whose decision differs or is band; otherwise the envelopes of the surfaces it may show.
    /// `group`: the triangle edges whose projections pass within `delta` of the pixel centre.
    fn seen_at(
        &self,
        samples: &Samples,
        (adjacency, walks): (&EdgeAdjacency, Option<&DirectedEdges>),
        i: usize,
        class: SampleClass,
        group: &[NearEdge],
        delta: f64,
    ) -> (bool, Vec<Envelope>) {
        let Some(view) = self.view else { return (false, Vec::new()) };
        let (width, height) = (self.width, self.height);
        let at = self.pixel_surface(samples, view, i);
        let (x, y, t, s, radius) = (at.x, at.y, at.triangle, at.s, at.radius);
        let same_surface = |id: u32| at.same_surface(self.mesh, id);
        // T's surface may not cover the pixel centre: a free edge of it passes within delta.
        // (With front faces only, a coplanar neighbour wound the other way is culled: it does
        // not continue T's surface.)
        let free = group
            .iter()
            .any(|&(_, id, k)| same_surface(id) && free_edge(self.mesh, adjacency, id, k, at.position, walks));
        // (Most surfaces in front with an edge within delta made the pixel SURFACE band
        // already, mark_nearer_contours; not T's neighbour across T's own edge.)
        let in_front = |id: u32| at.in_front(self.mesh, view, id, delta);
        let mut candidates: Vec<u32> = group
            .iter()
            .map(|g| g.1)
            .filter(|&id| !same_surface(id) && self.may_show(id) && (free || in_front(id)))
            .collect();
        let mut background = false;
        if free {
            // What lies behind the sample along its ray, and whether one of those covers every
            // point within delta of the pixel centre (else the background may show).
            let eye = self.eye_for(s);
            let dir = sub(s, eye);
            let len = norm(dir);
            let far = 1.0 + (norm(sub(s, self.centre)) + self.half_diagonal) / len;
            let end = [0, 1, 2].map(|k| eye[k] + far * dir[k]);
            let mut covered = false;
            self.bvh.triangles_near_segment(eye, dir, 1.0 - radius / len, far, t, 0.0, |id, v| {
                let v = v.map(to_f64);
                if !same_surface(id) && self.may_show(id) && segment_crosses(s, end, v) {
                    candidates.push(id);
                    // Covers for sure only if no depth pass may cull it.
                    covered |= self.surely_shown(id)
                        && view.edge_distance_px(v, x, y, width, height).is_some_and(|d| d > delta);
                }
                false
            });
            background = !covered;
        }
        if background && class == SampleClass::Lit {
            return (true, Vec::new());
        }
        candidates.sort_unstable();
        candidates.dedup();
        let mut envelopes = Vec::new();
        for id in candidates {
            // The other surface's sample: where the pixel's ray meets its plane.
            let [p, q, r] = self.mesh.triangles[id as usize].map(|k| self.vertex(k));
            let m = cross(sub(q, p), sub(r, p));
            let eye = self.eye_for(s);
            let ray = sub(s, eye);
            let along = dot(m, sub(p, eye)) / dot(m, ray);
            if !(along > 0.0 && along.is_finite()) {
                return (true, Vec::new());
            }
            let at = [0, 1, 2].map(|k| (eye[k] + along * ray[k]) as f32);
            let (other_class, other_parts, envelope) = self.classify(id, at);
            if other_class != class || other_parts != BandParts::NONE {
                return (true, Vec::new());
            }
            envelopes.extend(envelope);
        }
        (false, envelopes)
    }
}
