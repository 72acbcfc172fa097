//! hier-triangle's memory: the shared view-sample hierarchy ([`crate::methods::hier::layout`],
//! re-exported here; hier-triangle uses its samples, node bounds and state, and no queues), the
//! per-triangle planes of each light's shadow frusta (Sintorn, Kämpe, Olsson, Assarsson,
//! "Per-Triangle Shadow Volumes Using a View-Sample Cluster Hierarchy", I3D 2014, Section 3: a
//! triangle's shadow frustum as four planes) and the persistent traversal's job buffer.

pub use crate::methods::hier::layout::*;

/// Bytes of one triangle's data per light: the oriented triangle plane and three edge planes,
/// each also over the view's rays, and the bound of its directions from the light
/// (frustum.glsl).
pub const PLANE_BYTES: usize = 144;

/// Workgroups of the persistent traversal (traverse.comp.glsl), at most: each takes triangles
/// from the job counter until none is left, and owns one slot of saved traversal state.
pub const WORKGROUPS: usize = 1024;

/// Words of the job buffer before the triangle order: the job counter, the count of workgroups
/// a dispatch left unfinished, the length of the job list, one spare.
pub const JOB_HEADER_WORDS: usize = 4;

/// Words of one workgroup's saved traversal (traverse.comp.glsl): triangle + 1 (0: idle), stack
/// depth, then per stack entry its node and its mask of children still to enter.
pub const SLOT_WORDS: usize = 2 + 2 * (MAX_LEVELS + 1);

/// The job buffer's layout for a scene of `triangles` triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Jobs {
    /// Triangles (jobs).
    pub triangles: usize,
    /// Persistent workgroups: [`WORKGROUPS`], fewer for a small scene.
    pub workgroups: usize,
}

impl Jobs {
    /// The layout for `triangles` triangles.
    pub fn new(triangles: usize) -> Jobs {
        Jobs { triangles, workgroups: triangles.clamp(1, WORKGROUPS) }
    }

    /// Index of the triangle order (ids, largest area first).
    pub fn order_offset(&self) -> usize {
        JOB_HEADER_WORDS
    }

    /// Index of the job list: per job (a triangle whose frustum cuts a top node) the triangle
    /// and the mask of the top nodes it cuts.
    pub fn list_offset(&self) -> usize {
        JOB_HEADER_WORDS + self.triangles
    }

    /// Index of the first workgroup's slot.
    pub fn slots_offset(&self) -> usize {
        self.list_offset() + 2 * self.triangles
    }

    /// Words of the job buffer.
    pub fn words(&self) -> usize {
        self.slots_offset() + SLOT_WORDS * self.workgroups
    }

    /// Bytes of the job buffer.
    pub fn bytes(&self) -> usize {
        4 * self.words()
    }
}

/// Cells along a side of each of the receiver map's six cube faces (a point light;
/// receivers.glsl `RECEIVER_SIDE`).
pub const RECEIVER_SIDE: usize = 512;
/// Cells along a side of a directional light's receiver map (receivers.glsl `RECEIVER_FLAT`).
pub const RECEIVER_FLAT: usize = 512;
/// Cells of the receiver map (receivers.glsl): six faces of [`RECEIVER_SIDE`]²; a directional
/// light uses [`RECEIVER_FLAT`]² of them.
pub const RECEIVER_CELLS: usize = 6 * RECEIVER_SIDE * RECEIVER_SIDE;
const _: () = assert!(RECEIVER_FLAT * RECEIVER_FLAT <= RECEIVER_CELLS);
/// Bytes of the receiver map: one word per cell, then the directional grid's box (4 words).
pub const RECEIVER_BYTES: usize = 4 * (RECEIVER_CELLS + 4);

/// Bytes of the per-triangle planes of a scene of `triangles` triangles.
pub fn plane_bytes(triangles: usize) -> usize {
    PLANE_BYTES * triangles
}

/// The hierarchy hier-triangle allocates for a `width x height` frame: no queues (capacity 1
/// per level, the least the shared layout allows) and no items of its own in the state buffer
/// (the order lives in the job buffer).
pub fn frame_layout(width: u32, height: u32) -> Layout {
    Layout::new(width, height, 0, 0.0)
}

/// Bytes per scene (planes, job buffer and receiver map) of `triangles` triangles.
pub fn scene_bytes(triangles: usize) -> usize {
    plane_bytes(triangles.max(1)) + Jobs::new(triangles).bytes() + RECEIVER_BYTES
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_per_resolution() {
        // The numbers docs/benchmarks.md states (a 262,267-triangle Crytek Sponza).
        let t = 262_267;
        for (w, h, mib) in [(640, 360, 49.8), (1920, 1080, 87.7), (2560, 1440, 120.8), (3840, 2160, 215.4)] {
            let got = (frame_layout(w, h).frame_bytes() + scene_bytes(t)) as f64 / (1 << 20) as f64;
            assert!((got - mib).abs() < 0.1, "{w}x{h}: {got:.1} MiB");
        }
    }

    #[test]
    fn jobs_regions_follow_each_other() {
        let j = Jobs::new(100);
        assert_eq!(j.workgroups, 100);
        assert_eq!(j.order_offset(), JOB_HEADER_WORDS);
        assert_eq!(j.list_offset(), JOB_HEADER_WORDS + 100);
        assert_eq!(j.slots_offset(), JOB_HEADER_WORDS + 300);
        assert_eq!(j.words(), JOB_HEADER_WORDS + 300 + 100 * SLOT_WORDS);
        assert_eq!(Jobs::new(1 << 20).workgroups, WORKGROUPS);
        assert_eq!(Jobs::new(0).workgroups, 1);
    }
}
