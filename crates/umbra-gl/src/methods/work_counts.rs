//! Machine-independent work counts of a frame: how many compute dispatches a method issued and
//! how many hierarchy nodes and leaves its traversal tested. Counted only when asked
//! ([`crate::ShadowMethod::set_count_work`]): the GPU side adds to atomic counters, read back
//! with a stall ([`crate::ShadowMethod::work_counts`]); benchmarks report them next to the stage
//! times (`umbra bench --json`, key "work").

/// Work summed over every light drawn since counting was switched on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    /// Compute dispatches issued (direct and indirect, empty ones included).
    pub dispatches: u64,
    /// (item, node) tests: an item (a triangle's shadow frustum, a shadow-volume face) against
    /// a non-empty node of the view-sample hierarchy, leaves included.
    pub nodes_tested: u64,
    /// (item, leaf) pairs whose samples were tested one by one.
    pub leaves_tested: u64,
    /// Node tests that ended the descent there: the node lies outside the item's region, or
    /// (hier-triangle) wholly inside its shadow.
    pub nodes_pruned: u64,
}

impl WorkCounts {
    /// The counts as (JSON key, value), in a fixed order.
    pub fn entries(&self) -> [(&'static str, u64); 4] {
        [
            ("dispatches", self.dispatches),
            ("nodes_tested", self.nodes_tested),
            ("leaves_tested", self.leaves_tested),
            ("nodes_pruned", self.nodes_pruned),
        ]
    }
}
