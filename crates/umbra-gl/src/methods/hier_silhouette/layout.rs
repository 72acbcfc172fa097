//! hier-silhouette's memory: the shared view-sample hierarchy
//! ([`crate::methods::hier::layout`], nodes with their own point: 64 bytes each), the mesh's
//! edge records (per scene), and one buffer of per-light counts (the idea of the seed authors'
//! RSSV in dormon/Shadows: a count per bridge, i.e. per node, and per sample).
//!
//! Faces: every triangle is a possible light cap and every edge record a possible side quad,
//! so a scene of `t` triangles and `r` edge records has `t + r` faces, numbered caps first; the
//! queues and redo lists hold face numbers.

use crate::methods::hier::layout::Layout;
pub use crate::methods::hier::layout::{fallback_passes, FALLBACK_STEPS, PLACE_NODE_BITS};

/// Bytes of one edge record (A, B, first opposite, opposite count).
pub const EDGE_RECORD_BYTES: usize = 16;
/// Words at the start of the counts buffer: the counters of unsure decisions (faces.glsl).
pub const COUNTERS: usize = 4;
/// Most opposites one edge record holds: the multiplicity loop stays far below llvmpipe's
/// 65,535 loop iterations per shader invocation, all loops together (as cs-silhouette's
/// records).
pub const MAX_OPPOSITES_PER_RECORD: u32 = 16_384;

/// The faces of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Faces {
    /// Triangles: light caps 0 .. triangles - 1.
    pub triangles: usize,
    /// Edge records: side quads triangles .. triangles + records - 1.
    pub records: usize,
    /// Opposite vertices over all records.
    pub opposites: usize,
}

impl Faces {
    /// Faces in all.
    pub fn count(&self) -> usize {
        self.triangles + self.records
    }

    /// Bytes of the edge buffer: the records, then the opposite vertices (one word each).
    pub fn edge_bytes(&self) -> usize {
        EDGE_RECORD_BYTES * self.records + 4 * self.opposites
    }

    /// Word index of the first opposite vertex in the edge buffer.
    pub fn opposites_offset(&self) -> usize {
        4 * self.records
    }
}

/// Where each region of the counts buffer starts (in 32-bit words).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    /// Per node: the crossings of the bridge into it.
    pub bridges: usize,
    /// Per pixel: the crossings from its leaf's point to the sample, then its count W.
    pub partial: usize,
    /// Per top node: W at its point.
    pub top: usize,
    /// Per triangle: its orientation towards the light.
    pub orient: usize,
    /// Per edge record: its multiplicity.
    pub mult: usize,
    /// Words in all.
    pub words: usize,
}

impl Counts {
    /// The regions for `layout`'s frame and `faces`.
    pub fn new(layout: &Layout, faces: &Faces) -> Counts {
        let bridges = COUNTERS;
        let partial = bridges + layout.nodes() as usize;
        let top = partial + layout.width as usize * layout.height as usize;
        let orient = top + layout.top().nodes() as usize;
        let mult = orient + faces.triangles;
        Counts { bridges, partial, top, orient, mult, words: mult + faces.records }
    }

    /// Words cleared for every light: counters, bridges, samples, top nodes (the weights are
    /// written for every face by each light's setup).
    pub fn cleared_words(&self) -> usize {
        self.orient
    }

    /// Bytes of the counts buffer.
    pub fn bytes(&self) -> usize {
        4 * self.words
    }
}

/// Bytes per frame size: the hierarchy ([`Layout::frame_bytes`]) and the counts.
pub fn frame_bytes(layout: &Layout, faces: &Faces) -> usize {
    layout.frame_bytes() + Counts::new(layout, faces).bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn count_regions_follow_each_other() {
        let faces = Faces { triangles: 100, records: 160, opposites: 300 };
        let l = Layout::with_points(640, 360, faces.count(), 1.0);
        let c = Counts::new(&l, &faces);
        assert_eq!(c.bridges, COUNTERS);
        assert_eq!(c.partial, c.bridges + l.nodes() as usize);
        assert_eq!(c.top, c.partial + 640 * 360);
        assert_eq!(c.orient, c.top + 1);
        assert_eq!(c.mult, c.orient + 100);
        assert_eq!(c.words, c.mult + 160);
        assert_eq!(faces.edge_bytes(), 16 * 160 + 4 * 300);
        assert_eq!(l.node_bytes(), 64 * l.nodes() as usize);
        assert_eq!(l.state_words(), l.order_offset(), "no order region");
    }
}
