//! `umbra bench`: frame times of shadow methods along a camera path, the way the papers
//! measure them (paper 001 Sec. 3, Tables 1-9: FPS over fly-throughs; paper 003 Sec. 3,
//! Tables 1-4: average frame time over fly-throughs and per-stage times).
//!
//! Protocol:
//! * warm-up rounds first (llvmpipe compiles a shader at its first draw), not recorded;
//! * methods interleaved frame by frame (A B C A B C ...), so drift of a shared machine hits
//!   all of them alike (`bench/schedule.rs`);
//! * whole frame: glFinish before and after (through a synchronous
//!   [`umbra_gl::TimestampHook`] that sees only the frame's first and last stage marks), CPU
//!   clock in between; drawn with [`umbra_gl::Renderer::draw_frame`] into an offscreen target,
//!   no readback;
//! * stages: on every `stage_every`-th round, the same frame drawn once more with a
//!   synchronous timestamp hook (glFinish + glQueryCounter(GL_TIMESTAMP) at every stage
//!   boundary: GL_TIME_ELAPSED is wrong on llvmpipe), so each stage's work completes inside its
//!   own interval. Those frames are not part of the frame-time statistics (the per-stage
//!   glFinish costs the pipelining between stages).
//!

//! Files, one concept each:
//!
//! | file | what |
//! | --- | --- |
//! | `bench/options.rs` | [`MeasureOptions`]: one measurement's settings |
//! | `bench/scene.rs` | the scene measured and its camera path |
//! | `bench/flythrough.rs` | camera paths: orbits and fly-through files |
//! | `bench/schedule.rs` | the interleaved schedule |
//! | `bench/driver.rs` | the backend-neutral [`driver::Driver`] |
//! | `bench/gl_driver.rs`, `bench/wgpu_driver.rs` | each backend's frames and clocks |
//! | `bench/progress.rs` | the progress bar |
//! | `bench/measure.rs` | one measurement: drivers, schedule, statistics |
//! | `bench/stats.rs` | per-method statistics |
//! | `bench/output.rs` | JSON rows, CSV lines, the table, the plots |
//! | `bench/plot.rs` | SVG plots |
//! | `bench/suites.rs`, `bench/suite_run.rs` | the papers' suites: definitions, and running them |

mod driver;
mod flythrough;
mod gl_driver;
mod measure;
mod options;
mod output;
mod plot;
mod progress;
mod scene;
mod schedule;
mod stats;
mod suite_run;
pub mod suites;
mod wgpu_driver;

use std::path::Path;

use crate::config::{BenchConfig, BenchMode};
use crate::error::CliError;
use measure::measure_backends;
use options::MeasureOptions;
use output::{csv_lines, json_rows, load_average, print_table, write_plots, CSV_HEADER};
use scene::{camera_path, BenchScene};

pub use suites::list as list_suites;

/// `umbra bench`: a run along one camera path, or a suite.
pub fn run(c: &BenchConfig) -> Result<(), CliError> {
    let (methods, width, height, frames) = match &c.mode {
        BenchMode::Suite { suite, methods, size, frames } => {
            return suite_run::run(c, suite, methods.as_deref(), *size, *frames);
        }
        BenchMode::Path { methods, width, height, frames } => (methods, *width, *height, *frames),
    };
    let o = MeasureOptions::for_run(c, width, height, 2, 1, "bench");
    let scene = BenchScene::load(&c.scene, c.ground, c.max_input_bytes, &c.lights)?;
    let cameras = camera_path(&c.flythrough, &scene, frames)?;
    let load_before = load_average();
    // wgpu rows have frame times only (no stage timing: their stages stay empty).
    let m = measure_backends(&scene, methods, &cameras, &o, &c.backends)?;
    let load_after = load_average();
    if let Some(path) = &c.csv {
        let mut text = String::from(CSV_HEADER);
        text.push('\n');
        for l in csv_lines(&m, &scene.spec, width, height, o.stage_every) {
            text.push_str(&l);
            text.push('\n');
        }
        std::fs::write(path, text).map_err(|source| CliError::Io { path: path.clone(), source })?;
    }
    if let Some(path) = &c.plot {
        write_plots(Path::new(path), &format!("{} {width}x{height}", scene.spec), &m)?;
    }
    if c.json {
        let rows = json_rows(&m, &scene.spec, width, height, None, None);
        println!("{}", serde_json::to_string_pretty(&rows).map_err(|e| CliError::Other(e.to_string()))?);
    } else {
        println!(
            "{} ({} triangles) at {width}x{height}, {} frame(s) + {} warm-up along {}, {} light(s), {}; load average {} -> {}",
            scene.spec,
            m.triangles,
            frames,
            o.warmup,
            c.flythrough,
            scene.lights.len(),
            m.renderer,
            load_before.as_deref().unwrap_or("?"),
            load_after.as_deref().unwrap_or("?"),
        );
        print_table(&m);
    }
    Ok(())
}
