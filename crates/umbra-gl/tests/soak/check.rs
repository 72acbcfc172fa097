//! The soak's judgement: GL objects per kind exactly equal block after block, and the growth
//! of the memory windows' minima between the run's first and last thirds below a limit.

use crate::gl_objects::{GlObjects, KINDS};
use crate::plan::PHASES;
use crate::record::{Record, Sample};

/// The first phase of a block's memory window. After the recreation at a block's start the
/// methods allocate what each configuration needs the first time it comes (the directional
/// light's map on phase 1, the float32 counter on phase 6, ...), and the destroyed instance's
/// cube map usually lingers for the first two phases (see the module doc): from phase 6 on
/// every feature has been used since the recreation, so every block's window holds the same
/// allocations.
pub(crate) const SETTLED_PHASE: usize = 6;

/// Measured blocks whose windows the memory check leaves out: after the warm-up block the
/// resident memory still settles for a block (allocator arenas and Mesa's shader variants of
/// the configurations first met there). Measured on a fresh clone with 17 methods: the
/// first measured window's minimum 9.4 MB below the second's, then +3.3 MB over the next
/// three; counted, that settling alone would read as +18 KiB per frame, above the short
/// soak's limit.
/// The GL objects are still compared over every measured block.
pub(crate) const MEMORY_SETTLING_BLOCKS: usize = 1;

/// The memory check's limit on the growth of the windows' minima, in KiB per frame, for a soak
/// of `windows` measured blocks. Its noise falls with the distance between the run's thirds:
/// the windows' minima scatter by up to 12 MB (measured with 17 methods: two levels 10 MB
/// apart), up to 7.4 KiB per frame over the 1,632 frames between the thirds of the short soak. The long soak (50 windows, 6,120 frames
/// between its thirds) measured +0.53 KiB per frame: its first ten windows settle by +3 MB,
/// then it stays flat for forty. An injected leak of 64 KiB per frame measures about 100
/// (malloc's overhead and the fragmentation around the leaked blocks).
pub(crate) fn leak_limit_kib_per_frame(windows: usize) -> f64 {
    if windows >= 20 {
        2.0
    } else {
        16.0
    }
}

/// Objects umbra owns, per kind (programs only flagged for deletion left out).
pub(crate) fn owned_per_kind(o: &GlObjects) -> Vec<usize> {
    let program_kind = KINDS.iter().position(|&k| k == "glIsProgram").expect("glIsProgram probed");
    let mut v = o.per_kind.clone();
    v[program_kind] -= o.pending_programs;
    v
}

/// Least-squares slope of `y` over `x`.
pub(crate) fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx) =
        points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + (x - mx) * (y - my), b + (x - mx) * (x - mx)));
    sxy / sxx
}

/// What the memory check computed.
#[derive(Debug)]
pub(crate) struct MemoryTrend {
    /// (middle frame of the window, minimum VmRSS in KiB) per measured block.
    pub(crate) window_minima: Vec<(f64, f64)>,
    /// Least-squares slope of the windows' minima (printed; one plateau moves it).
    pub(crate) least_squares_kib_per_frame: f64,
    /// The lowest window minimum of the run's last third minus that of its first third, over
    /// the frames between the thirds' middles (asserted).
    pub(crate) kib_per_frame: f64,
}

pub(crate) fn memory_trend(record: &Record) -> MemoryTrend {
    let blocks = record.samples.iter().map(|s| s.block).max().unwrap_or(0);
    let window_minima: Vec<(f64, f64)> = (1 + MEMORY_SETTLING_BLOCKS..=blocks)
        .map(|b| {
            let min = record
                .samples
                .iter()
                .filter(|s| s.block == b && s.phase >= SETTLED_PHASE)
                .map(|s| s.rss_kib)
                .min()
                .expect("samples");
            ((b as f64 + 0.5) * record.frames_per_block as f64, min as f64)
        })
        .collect();
    let third = window_minima.len().div_ceil(3);
    let lowest = |w: &[(f64, f64)]| {
        let frame = w.iter().map(|p| p.0).sum::<f64>() / w.len() as f64;
        (frame, w.iter().map(|p| p.1).fold(f64::INFINITY, f64::min))
    };
    let (first, last) = (lowest(&window_minima[..third]), lowest(&window_minima[window_minima.len() - third..]));
    MemoryTrend {
        least_squares_kib_per_frame: slope(&window_minima),
        kib_per_frame: (last.1 - first.1) / (last.0 - first.0),
        window_minima,
    }
}

/// Everything wrong with a soak (see the module doc); empty when it shows no leak.
pub(crate) fn check(record: &Record) -> Vec<String> {
    let mut problems = Vec::new();
    if !record.drift.is_empty() {
        problems.push(format!("the fixed frame differs after the soak: {}", record.drift.join(", ")));
    }
    if let Some(left) = &record.left_behind {
        problems.push(format!("GL objects left after destroying the renderer, methods, scene and hook: {left}"));
    }
    // GL objects: every measured block equals the first, phase by phase.
    let first: Vec<&Sample> = record.samples.iter().filter(|s| s.block == 1).collect();
    assert_eq!(first.len(), PHASES, "one sample per cycle");
    for s in record.samples.iter().filter(|s| s.block > 1) {
        let want = first[s.phase];
        if owned_per_kind(&s.objects) != owned_per_kind(&want.objects) {
            problems.push(format!(
                "GL objects: block {} phase {} (frame {}) has {}; block 1 had {} at the same point",
                s.block,
                s.phase,
                s.frame,
                s.objects.describe(),
                want.objects.describe()
            ));
            break;
        }
    }
    let trend = memory_trend(record);
    println!(
        "VmRSS window minima (KiB): {:?}; last third's lowest against the first's: {:+.2} KiB/frame \
         (least-squares slope {:+.2})",
        trend.window_minima.iter().map(|w| w.1 as u64).collect::<Vec<_>>(),
        trend.kib_per_frame,
        trend.least_squares_kib_per_frame
    );
    let limit = leak_limit_kib_per_frame(trend.window_minima.len());
    if trend.kib_per_frame > limit {
        problems.push(format!(
            "VmRSS: the windows' minima grow by {:.1} KiB per frame (limit {limit} over {} windows)",
            trend.kib_per_frame,
            trend.window_minima.len()
        ));
    }
    problems
}
