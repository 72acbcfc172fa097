//! A hier method's work counting ([`crate::ShadowMethod::set_count_work`]): the switch, the
//! dispatches counted on the CPU ([`super::Passes::counted`]), and the GPU counters
//! (hierarchy.glsl `count_work`) zeroed when counting starts and read back when asked.

use super::{FrameObjects, Passes};
use crate::methods::work_counts::WorkCounts;

/// See the module documentation.
#[derive(Clone, Copy, Debug, Default)]
pub struct WorkCounter {
    on: bool,
    /// The GPU counters still need zeroing (counting was just switched on, or the frame
    /// objects were reallocated).
    reset: bool,
    dispatches: u64,
}

impl WorkCounter {
    /// Switches counting on (from 0) or off.
    pub fn set(&mut self, on: bool) {
        *self = Self { on, reset: on, dispatches: 0 };
    }

    /// Whether the shaders count (`u_count_work`).
    pub fn on(&self) -> bool {
        self.on
    }

    /// Before a light's passes: zeroes the GPU counters of `f` if counting just began, or if
    /// `fresh` (the frame objects were just allocated: their counters hold garbage).
    pub fn begin(&mut self, gl: &glow::Context, f: &FrameObjects, fresh: bool) {
        if self.on && (self.reset || fresh) {
            f.reset_work(gl);
            self.reset = false;
        }
    }

    /// After a light's passes: adds the dispatches they issued.
    pub fn end(&mut self, passes: &Passes<'_>) {
        if self.on {
            self.dispatches += passes.dispatches.get();
        }
    }

    /// The counts so far (a read-back stall), `None` while counting is off. Without frame
    /// objects (nothing drawn yet) the GPU counts are 0.
    pub fn read(&self, gl: &glow::Context, f: Option<&FrameObjects>) -> Option<WorkCounts> {
        if !self.on {
            return None;
        }
        let [nodes_tested, leaves_tested, nodes_pruned] = f.map_or([0; 3], |f| f.read_work(gl));
        Some(WorkCounts { dispatches: self.dispatches, nodes_tested, leaves_tested, nodes_pruned })
    }
}
