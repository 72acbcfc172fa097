//! [`MeasureOptions`]: everything one measurement needs besides the scene.

use crate::config::BenchConfig;
use crate::methods::{CounterChoice, SmOptions};

/// Everything one measurement needs besides the scene.
#[derive(Clone, Debug)]
pub struct MeasureOptions {
    pub width: u32,
    pub height: u32,
    pub warmup: usize,
    /// Draw a stage-timed copy of every `stage_every`-th measured round; 0 = never.
    pub stage_every: usize,
    pub fov: f64,
    /// `--ortho HEIGHT`: an orthographic camera.
    pub ortho: Option<f64>,
    pub zpass: bool,
    /// `--zmode auto`: z-pass where provably exact.
    pub auto_zpass: bool,
    /// `--volume-cull`: volumes culled and clamped against the receivers.
    pub volume_cull: bool,
    /// `--counter` (resolved per scene and lights by each backend's driver).
    pub counter: CounterChoice,
    pub sm: SmOptions,
    pub trace_order: bool,
    /// `--log`: one stderr line per drawn frame.
    pub log: bool,
    pub progress_label: String,
}

impl MeasureOptions {
    /// The options of one run at `width`x`height`: `--warmup` or `warmup_default`,
    /// `--stage-every` or `stage_every_default`, the other settings as checked in `c`.
    pub fn for_run(
        c: &BenchConfig,
        width: u32,
        height: u32,
        warmup_default: usize,
        stage_every_default: usize,
        label: &str,
    ) -> Self {
        MeasureOptions {
            width,
            height,
            warmup: c.warmup.unwrap_or(warmup_default),
            stage_every: c.stage_every.unwrap_or(stage_every_default),
            fov: c.fov,
            ortho: c.ortho,
            zpass: c.zpass,
            auto_zpass: c.auto_zpass,
            volume_cull: c.volume_cull,
            counter: c.counter,
            sm: c.sm,
            trace_order: c.trace_order,
            log: c.log,
            progress_label: label.to_string(),
        }
    }
}
