//! The view-sample cluster hierarchy of hier-triangle and hier-silhouette for one frame size:
//! how many levels, how many nodes per level, where each level lives in the node, flag and
//! queue arrays, and how many bytes all of it takes (Sintorn, Kämpe, Olsson, Assarsson,
//! "Per-Triangle Shadow Volumes Using a View-Sample Cluster Hierarchy", I3D 2014, Section 4: a
//! hierarchy over the depth buffer's samples with 3-D bounds, built per frame).
//!
//! Level 0 holds the leaves: tiles of [`LEAF_SIDE`] x [`LEAF_SIDE`] pixels (16 samples, one
//! "shadowed" bit each). Every level above groups [`BRANCH_SIDE`] x [`BRANCH_SIDE`] nodes of
//! the level below (16 children), up to a single root (or [`MAX_UPPER_LEVELS`] levels above the
//! leaves, enough for 65,536 pixels). Tiles are counted from the bottom-left pixel (GL's window
//! coordinates); the last tile of a row or column may be cut.
//!
//! hier-triangle uses the samples, the node bounds and the per-node state words of this layout
//! and walks the hierarchy in its own persistent traversal (`hier_triangle/traverse.comp.glsl`,
//! [`Layout::new`] with no items and the least queues). The items hier-silhouette tests against
//! the hierarchy (its shadow-volume faces) are processed in batches of at most [`BATCH`]. Queues hold
//! (item, node) pairs whose node the item's test cuts; level `l`'s queue feeds the pass that
//! tests the children of those nodes, the leaves' queue is threaded into one list per leaf.
//! Their capacity is fixed per frame size ([`queue_capacity`]): a pair that does not fit sends
//! its item to the redo list (one entry per item at most), processed again by redo rounds and
//! at last whole by the fallback pass (slower, never wrong).

/// Side of a leaf tile in pixels (16 samples per leaf).
pub const LEAF_SIDE: u32 = 4;
/// Samples per leaf (at most 32: one mask word per leaf).
pub const LEAF_SAMPLES: u32 = LEAF_SIDE * LEAF_SIDE;
const _: () = assert!(LEAF_SAMPLES <= 32);
/// Side of the block of children of an inner node (16 children).
pub const BRANCH_SIDE: u32 = 4;
/// Children per inner node.
pub const CHILDREN: u32 = BRANCH_SIDE * BRANCH_SIDE;
/// Most levels above the leaves (the fallback walks' stacks hold MAX_LEVELS entries):
/// a root over 4 x 4^7 = 65,536 pixels.
pub const MAX_UPPER_LEVELS: usize = 7;
/// Most levels in all, leaves included.
pub const MAX_LEVELS: usize = MAX_UPPER_LEVELS + 1;
/// Levels are added until the top one has at most this many nodes.
pub const MAX_TOP_NODES: u32 = 1;
/// Most triangles per batch.
pub const BATCH: usize = 4096;
/// Triangles in the first batch; each next batch doubles, up to [`BATCH`]: the largest
/// triangles, whose frusta cut the most nodes, go in small batches.
pub const FIRST_BATCH: usize = 256;

/// The batches of a scene of `triangles` triangles, as ranges of positions in the
/// largest-first order: [`FIRST_BATCH`], then doubling up to [`BATCH`].
pub fn batches(triangles: usize) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let (mut start, mut size) = (0, FIRST_BATCH);
    while start < triangles {
        let end = (start + size).min(triangles);
        out.push(start..end);
        start = end;
        size = (2 * size).min(BATCH);
    }
    out
}
/// Steps of one fallback pass per item (walk.comp.glsl): llvmpipe gives a shader invocation
/// 65,535 loop iterations in all, every loop of the shader together, so a walk longer than that
/// goes on in further passes of at most this many steps.
pub const FALLBACK_STEPS: u32 = 49_152;
/// Bits of a global node index in a fallback walk's place (walk.comp.glsl): a frame whose
/// hierarchy has more nodes is refused (16,384 x 16,384 has about 2^24).
pub const PLACE_NODE_BITS: u32 = 27;

/// The fallback passes of `steps_per_pass` steps (> 0) that finish the longest walk `layout`
/// allows: one step per top node from the root and one to leave it, then per node one per child
/// (or per sample of a leaf) and one to leave it.
pub fn fallback_passes(layout: &Layout, steps_per_pass: u32) -> usize {
    let per_node = CHILDREN.max(LEAF_SAMPLES) as usize + 1;
    let steps = layout.top().nodes() as usize + 1 + layout.nodes() as usize * per_node;
    steps.div_ceil(steps_per_pass.max(1) as usize)
}

/// Words (u32) of the control block at the start of the state buffer: per level, the queue's
/// entry count and a DispatchIndirectCommand (x, y, z); then the same for the list of active
/// leaves and for the two redo lists.
pub const CONTROL_WORDS: usize = 4 * MAX_LEVELS + 12;
/// Index of the active-leaf list's count in the control block.
pub const ACTIVE_CONTROL: usize = 4 * MAX_LEVELS;
/// Index of redo list 0's count in the control block (list 1's follows 4 words later).
pub const REDO_CONTROL: usize = ACTIVE_CONTROL + 4;
/// Rounds over the redo lists, with the same passes as the batches, before the fallback.
pub const REDO_ROUNDS: usize = 2;
/// Queue capacity per level: this many pairs per node of the level ...
pub const QUEUE_PAIRS_PER_NODE: usize = 16;
/// ... and at least this many per triangle of a batch.
pub const QUEUE_PAIRS_PER_BATCH_TRIANGLE: usize = 64;
/// Bytes of one sample (world position xyz as f32 bits, triangle id).
pub const SAMPLE_BYTES: usize = 16;
/// Bytes of one node's bounds (world box with the clip-w range, the light-direction bound, the
/// depth occupancy): hier-triangle's nodes.
pub const NODE_BYTES: usize = 64;
/// Bytes of one node with its own point too (hier-silhouette's nodes, `LIFT`).
pub const NODE_BYTES_WITH_POINT: usize = 64;
/// Bytes of one queue entry (triangle, node).
pub const PAIR_BYTES: usize = 8;
/// Bytes of the work counters (hier/mod.rs WORK_WORDS words).
pub const WORK_BYTES: usize = 16;

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

/// The hierarchy of a `width x height` frame for `triangles` items.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Level 0 = leaves, last = top.
    pub levels: Vec<Level>,
    /// Items of the scene: hier-triangle's triangles, hier-silhouette's faces (the redo lists'
    /// capacity).
    pub triangles: usize,
    /// Bytes per node: [`NODE_BYTES`] or [`NODE_BYTES_WITH_POINT`].
    pub node_bytes_each: usize,
    /// Whether the state buffer ends with the items' order (hier-triangle's largest-first
    /// order, one word per item).
    pub with_order: bool,
}

/// Pairs the queue of a level of `nodes` nodes holds.
pub fn queue_capacity(nodes: u32) -> usize {
    (QUEUE_PAIRS_PER_NODE * nodes as usize).max(QUEUE_PAIRS_PER_BATCH_TRIANGLE * BATCH)
}

impl Layout {
    /// hier-triangle's layout of a `width x height` frame (both > 0) with queue capacities for
    /// `triangles` triangles, each scaled by `queue_scale` (1.0 normally; tests shrink the
    /// queues to exercise the fallback). Capacities are capped so that every index fits u32.
    pub fn new(width: u32, height: u32, triangles: usize, queue_scale: f64) -> Layout {
        Self::build(width, height, triangles, queue_scale, NODE_BYTES, true)
    }

    /// hier-silhouette's layout: as [`Layout::new`] for `faces` items, nodes with their own
    /// point ([`NODE_BYTES_WITH_POINT`]), no order region.
    pub fn with_points(width: u32, height: u32, faces: usize, queue_scale: f64) -> Layout {
        Self::build(width, height, faces, queue_scale, NODE_BYTES_WITH_POINT, false)
    }

    fn build(
        width: u32,
        height: u32,
        triangles: usize,
        queue_scale: f64,
        node_bytes_each: usize,
        with_order: bool,
    ) -> Layout {
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
            let scaled = (queue_capacity(level.nodes()) as f64 * queue_scale).ceil();
            let capacity = scaled.clamp(1.0, f64::from(u32::MAX / 4)) as u64;
            let capacity = capacity.min(u64::from(u32::MAX) - first_pair) as u32;
            level.first_pair = first_pair as u32;
            level.queue_capacity = capacity;
            first_pair += u64::from(capacity);
        }
        Layout { width, height, levels, triangles, node_bytes_each, with_order }
    }

    /// vec4 per node in the node buffer (the shaders' `NODE_VEC4S`).
    pub fn node_vec4s(&self) -> usize {
        self.node_bytes_each / 16
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

    /// Bytes of the node bounds (and points).
    pub fn node_bytes(&self) -> usize {
        self.node_bytes_each * self.nodes() as usize
    }

    /// Words of the state buffer cleared for every light: control, one covered flag per node,
    /// a mask word, a list head and an active-list entry per leaf, one redo flag per triangle
    /// (32 per word).
    pub fn light_words(&self) -> usize {
        self.redo_flags_offset() + self.triangles.div_ceil(32)
    }

    /// Index of the first leaf's mask of samples present (per frame) in the state buffer.
    pub fn valid_offset(&self) -> usize {
        self.light_words()
    }

    /// Index of the triangle order (per scene: ids, largest area first; hier-triangle) in the
    /// state buffer.
    pub fn order_offset(&self) -> usize {
        self.valid_offset() + self.leaves() as usize
    }

    /// Words of the state buffer.
    pub fn state_words(&self) -> usize {
        self.order_offset() + if self.with_order { self.triangles } else { 0 }
    }

    /// Index of the first leaf list head in the state buffer.
    pub fn heads_offset(&self) -> usize {
        self.bits_offset() + self.leaves() as usize
    }

    /// Index of the list of active leaves (those with pairs in this batch) in the state buffer.
    pub fn active_offset(&self) -> usize {
        self.heads_offset() + self.leaves() as usize
    }

    /// Index of the first redo flag word in the state buffer.
    pub fn redo_flags_offset(&self) -> usize {
        self.active_offset() + self.leaves() as usize
    }

    /// Index of redo list 0 in the queue array (after every level's queue; list 1 follows it,
    /// `triangles` entries each).
    pub fn redo_offset(&self) -> usize {
        self.levels.iter().map(|l| l.queue_capacity as usize).sum()
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

    /// Entries of all queues and the two redo lists.
    pub fn queue_pairs(&self) -> usize {
        self.redo_offset() + 2 * self.triangles
    }

    /// Bytes of the queues.
    pub fn queue_bytes(&self) -> usize {
        PAIR_BYTES * self.queue_pairs()
    }

    /// Bytes of everything that depends on the frame size (samples, bounds, state, queues,
    /// work counters).
    pub fn frame_bytes(&self) -> usize {
        self.sample_bytes() + self.node_bytes() + self.state_bytes() + self.queue_bytes() + WORK_BYTES
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_of_common_sizes() {
        let l = Layout::new(1920, 1080, 0, 1.0);
        let dims: Vec<(u32, u32)> = l.levels.iter().map(|v| (v.width, v.height)).collect();
        // 4-pixel leaves, then 16, 64, 256, 1024 and 4096 pixels: one root.
        assert_eq!(dims, vec![(480, 270), (120, 68), (30, 17), (8, 5), (2, 2), (1, 1)]);
        assert_eq!(l.levels[1].first_node, 480 * 270);
        assert_eq!(l.nodes(), 480 * 270 + 120 * 68 + 30 * 17 + 8 * 5 + 4 + 1);
        let tiny = Layout::new(1, 1, 0, 1.0);
        assert_eq!(tiny.levels.len(), 2, "always one level above the leaves");
        assert_eq!(tiny.top().nodes(), 1);
        let huge = Layout::new(16384, 16384, 0, 1.0);
        assert_eq!((huge.levels.len(), huge.top().nodes()), (7, 1));
        let strip = Layout::new(1 << 20, 4, 0, 1.0);
        assert_eq!(strip.levels.len(), MAX_LEVELS, "capped");
        assert_eq!(strip.top().nodes(), 16, "more than one top node once capped");
    }

    #[test]
    fn queues_are_contiguous_and_scale() {
        let l = Layout::new(1920, 1080, 1000, 1.0);
        let mut next = 0;
        for level in &l.levels {
            assert_eq!(level.first_pair, next);
            assert_eq!(level.queue_capacity as usize, queue_capacity(level.nodes()));
            next += level.queue_capacity;
        }
        assert_eq!(l.redo_offset(), next as usize);
        assert_eq!(l.queue_pairs(), next as usize + 2000, "two redo lists");
        let tiny = Layout::new(1920, 1080, 1000, 1e-9);
        assert!(tiny.levels.iter().all(|v| v.queue_capacity == 1));
    }

    #[test]
    fn state_regions_follow_each_other() {
        let l = Layout::new(640, 360, 100, 1.0);
        assert_eq!(l.covered_offset(), CONTROL_WORDS);
        assert_eq!(l.bits_offset(), CONTROL_WORDS + l.nodes() as usize);
        assert_eq!(l.heads_offset(), l.bits_offset() + l.leaves() as usize);
        assert_eq!(l.active_offset(), l.heads_offset() + l.leaves() as usize);
        assert_eq!(l.redo_flags_offset(), l.active_offset() + l.leaves() as usize);
        assert_eq!(l.light_words(), l.redo_flags_offset() + 4);
        assert_eq!(l.order_offset(), l.light_words() + l.leaves() as usize);
        assert_eq!(l.state_words(), l.order_offset() + 100);
    }

    #[test]
    fn batches_double_up_to_the_cap() {
        let b = batches(10_000);
        let sizes: Vec<usize> = b.iter().map(|r| r.len()).collect();
        assert_eq!(sizes, vec![256, 512, 1024, 2048, 4096, 2064]);
        assert!(b.windows(2).all(|w| w[0].end == w[1].start) && b[0].start == 0 && b[5].end == 10_000);
        assert!(batches(0).is_empty());
    }
}
