//! What a soak measured: one sample per cycle, the fixed frames' drift, what was left behind.

use crate::gl_objects::GlObjects;

/// One measurement, after the last frame of a cycle.
#[derive(Clone, Debug)]
pub(crate) struct Sample {
    pub(crate) block: usize,
    pub(crate) phase: usize,
    /// Frames rendered so far.
    pub(crate) frame: usize,
    /// VmRSS.
    pub(crate) rss_kib: u64,
    pub(crate) objects: GlObjects,
}

/// Everything a soak measured.
pub(crate) struct Record {
    pub(crate) samples: Vec<Sample>,
    pub(crate) frames_per_block: usize,
    /// Methods whose fixed frame differs between the start and the end.
    pub(crate) drift: Vec<String>,
    /// What was left after destroying everything, when more than the (at most 4) programs
    /// the driver still refers to.
    pub(crate) left_behind: Option<String>,
}
