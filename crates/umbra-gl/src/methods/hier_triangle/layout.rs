//! The view-sample cluster hierarchy of hier-triangle for one frame size: how many levels,
//! how many nodes per level, where each level lives in the node, flag and queue arrays, and
//! how many bytes all of it takes (Sintorn, Kämpe, Olsson, Assarsson, "Per-Triangle Shadow
//! Volumes Using a View-Sample Cluster Hierarchy", I3D 2014, Section 4: a hierarchy over the
//! depth buffer's samples with 3-D bounds, built per frame).
//!
//! Level 0 holds the leaves: tiles of [`LEAF_SIDE`] x [`LEAF_SIDE`] pixels (64 samples, one
//! 64-bit "shadowed" mask each). Every level above groups [`BRANCH_SIDE`] x [`BRANCH_SIDE`]
//! nodes of the level below (16 children), up to the first level with at most
//! [`MAX_TOP_NODES`] nodes (or [`MAX_UPPER_LEVELS`] levels above the leaves, whichever comes
//! first): each triangle tests every top node, then descends. Tiles are counted from the
//! bottom-left pixel (GL's window coordinates); the last tile of a row or column may be cut.
//!
//! Queues hold (triangle, node) pairs whose node the triangle's shadow frustum cuts (neither
//! misses nor covers it); level `l`'s queue feeds the pass that tests the children of those
//! nodes. Their capacity is fixed per frame size and scene ([`queue_capacity`]): a pair that
//! does not fit is processed at once by the invocation that found it (slower, never wrong).

/// Side of a leaf tile in pixels (64 samples per leaf).
pub const LEAF_SIDE: u32 = 8;
/// Samples per leaf.
pub const LEAF_SAMPLES: u32 = LEAF_SIDE * LEAF_SIDE;
/// Side of the block of children of an inner node (16 children).
pub const BRANCH_SIDE: u32 = 4;
/// Children per inner node.
pub const CHILDREN: u32 = BRANCH_SIDE * BRANCH_SIDE;
/// Most levels above the leaves (the shaders' fallback chain is generated for this many).
pub const MAX_UPPER_LEVELS: usize = 5;
/// Most levels in all, leaves included.
pub const MAX_LEVELS: usize = MAX_UPPER_LEVELS + 1;
/// Levels are added until the top one has at most this many nodes.
pub const MAX_TOP_NODES: u32 = 64;
/// Words (u32) of the control block at the start of the state buffer: per level, the queue's
/// entry count and a DispatchIndirectCommand (x, y, z).
pub const CONTROL_WORDS: usize = 4 * MAX_LEVELS;
/// Queue capacity per level: this many pairs per triangle of the scene ...
pub const QUEUE_PAIRS_PER_TRIANGLE: usize = 2;
/// ... plus this many per node of the level.
pub const QUEUE_PAIRS_PER_NODE: usize = 16;
/// Bytes of one sample (world position xyz as f32 bits, triangle id).
pub const SAMPLE_BYTES: usize = 16;
/// Bytes of one node's bounds (min xyz + sample count, max xyz + unused).
pub const NODE_BYTES: usize = 32;
/// Bytes of one queue entry (triangle, node).
pub const PAIR_BYTES: usize = 8;
/// Bytes of one triangle's four planes (oriented triangle plane, three edge planes).
pub const PLANE_BYTES: usize = 64;

/// One level's grid of nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Level {
    /// Nodes per row.
    pub width: u32,
    /// Rows of nodes.
    pub height: u32,
    /// Index of the level's first node in the arrays of all nodes (bounds, covered flags).
    pub first_node: u32,
    /// Index of the level's first entry in the queue array.
    pub first_pair: u32,
    /// Entries the level's queue holds.
    pub queue_capacity: u32,
}

impl Level {
    /// Nodes in the level.
    pub fn nodes(&self) -> u32 {
        self.width * self.height
    }
}

/// The hierarchy of a `width x height` frame for a scene of `triangles` triangles.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Level 0 = leaves, last = top.
    pub levels: Vec<Level>,
}

/// Pairs level `nodes`' queue holds for a scene of `triangles` triangles.
pub fn queue_capacity(triangles: usize, nodes: u32) -> usize {
    QUEUE_PAIRS_PER_TRIANGLE * triangles + QUEUE_PAIRS_PER_NODE * nodes as usize
}

impl Layout {
    /// The layout of a `width x height` frame (both > 0) with queue capacities for
    /// `triangles` triangles, each scaled by `queue_scale` (1.0 normally; tests shrink the
    /// queues to exercise the fallback). Capacities are capped so that every index fits u32.
    pub fn new(width: u32, height: u32, triangles: usize, queue_scale: f64) -> Layout {
        let mut levels = Vec::with_capacity(MAX_LEVELS);
        let (mut w, mut h) = (width.div_ceil(LEAF_SIDE), height.div_ceil(LEAF_SIDE));
        let mut first_node = 0u32;
        loop {
            levels.push(Level { width: w, height: h, first_node, first_pair: 0, queue_capacity: 0 });
            first_node = first_node.saturating_add(w * h);
            if levels.len() >= 2 && w * h <= MAX_TOP_NODES || levels.len() == MAX_LEVELS {
                break;
            }
            (w, h) = (w.div_ceil(BRANCH_SIDE), h.div_ceil(BRANCH_SIDE));
        }
        let mut first_pair = 0u64;
        for level in &mut levels {
            let scaled = (queue_capacity(triangles, level.nodes()) as f64 * queue_scale).ceil();
            let capacity = scaled.clamp(1.0, f64::from(u32::MAX / 4)) as u64;
            let capacity = capacity.min(u64::from(u32::MAX) - first_pair) as u32;
            level.first_pair = first_pair as u32;
            level.queue_capacity = capacity;
            first_pair += u64::from(capacity);
        }
        Layout { width, height, levels }
    }

    /// Number of leaves.
    pub fn leaves(&self) -> u32 {
        self.levels[0].nodes()
    }

    /// Nodes over all levels.
    pub fn nodes(&self) -> u32 {
        self.levels.iter().map(Level::nodes).sum()
    }

    /// The top level.
    pub fn top(&self) -> &Level {
        &self.levels[self.levels.len() - 1]
    }

    /// Bytes of the per-pixel sample buffer.
    pub fn sample_bytes(&self) -> usize {
        SAMPLE_BYTES * self.width as usize * self.height as usize
    }

    /// Bytes of the node bounds.
    pub fn node_bytes(&self) -> usize {
        NODE_BYTES * self.nodes() as usize
    }

    /// Words of the state buffer: control, one covered flag per node, two mask words per leaf.
    pub fn state_words(&self) -> usize {
        CONTROL_WORDS + self.nodes() as usize + 2 * self.leaves() as usize
    }

    /// Index of the first covered flag in the state buffer.
    pub fn covered_offset(&self) -> usize {
        CONTROL_WORDS
    }

    /// Index of the first leaf mask word in the state buffer.
    pub fn bits_offset(&self) -> usize {
        CONTROL_WORDS + self.nodes() as usize
    }

    /// Bytes of the state buffer.
    pub fn state_bytes(&self) -> usize {
        4 * self.state_words()
    }

    /// Entries of all queues.
    pub fn queue_pairs(&self) -> usize {
        self.levels.iter().map(|l| l.queue_capacity as usize).sum()
    }

    /// Bytes of the queues.
    pub fn queue_bytes(&self) -> usize {
        PAIR_BYTES * self.queue_pairs()
    }

    /// Bytes of everything that depends on the frame size (samples, bounds, state, queues).
    pub fn frame_bytes(&self) -> usize {
        self.sample_bytes() + self.node_bytes() + self.state_bytes() + self.queue_bytes()
    }
}

/// Bytes of the per-triangle planes of a scene of `triangles` triangles.
pub fn plane_bytes(triangles: usize) -> usize {
    PLANE_BYTES * triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_of_common_sizes() {
        let l = Layout::new(1920, 1080, 0, 1.0);
        let dims: Vec<(u32, u32)> = l.levels.iter().map(|v| (v.width, v.height)).collect();
        // 8-pixel leaves, then 32, 128 and 512 pixels: 4 x 3 top nodes.
        assert_eq!(dims, vec![(240, 135), (60, 34), (15, 9), (4, 3)]);
        assert_eq!(l.levels[1].first_node, 240 * 135);
        assert_eq!(l.nodes(), 240 * 135 + 60 * 34 + 15 * 9 + 12);
        let small = Layout::new(640, 360, 0, 1.0);
        assert_eq!(small.top().nodes(), 5 * 3, "128-pixel top nodes");
        let tiny = Layout::new(1, 1, 0, 1.0);
        assert_eq!(tiny.levels.len(), 2, "always one level above the leaves");
        assert_eq!(tiny.top().nodes(), 1);
        let huge = Layout::new(16384, 16384, 0, 1.0);
        assert_eq!((huge.levels.len(), huge.top().nodes()), (5, 64), "2048-pixel top nodes");
        let strip = Layout::new(1 << 20, 8, 0, 1.0);
        assert_eq!(strip.levels.len(), MAX_LEVELS, "capped");
        assert_eq!(strip.top().nodes(), 128, "more top nodes than MAX_TOP_NODES once capped");
    }

    #[test]
    fn queues_are_contiguous_and_scale() {
        let l = Layout::new(1920, 1080, 1000, 1.0);
        let mut next = 0;
        for level in &l.levels {
            assert_eq!(level.first_pair, next);
            assert_eq!(level.queue_capacity as usize, queue_capacity(1000, level.nodes()));
            next += level.queue_capacity;
        }
        let tiny = Layout::new(1920, 1080, 1000, 1e-9);
        assert!(tiny.levels.iter().all(|v| v.queue_capacity == 1));
    }

    #[test]
    fn bytes_per_resolution() {
        // The numbers docs/benchmarks.md states (a 262,267-triangle Crytek Sponza).
        let t = 262_267;
        for (w, h, mib) in [(640, 360, 32.2), (1920, 1080, 69.3), (3840, 2160, 181.2)] {
            let l = Layout::new(w, h, t, 1.0);
            let got = (l.frame_bytes() + plane_bytes(t)) as f64 / (1 << 20) as f64;
            assert!((got - mib).abs() < 0.1, "{w}x{h}: {got:.1} MiB");
        }
    }
}
