//! [`BenchConfig`]: the flags of `umbra bench`, checked.

use umbra_geom::Light;

use super::checked::{Checked, Listing};
use super::parse::{
    asks_for_list, check_fov, gl_methods, parse_backend, parse_counter, parse_light, parse_ortho, parse_size, parse_sm,
    parse_volume_cull, parse_zmode, wgpu_methods,
};
use crate::args::BenchArgs;
use crate::backend::Backend;
use crate::bench::suites::{suite, Suite};
use crate::error::{bad, CliError};
use crate::methods::{CounterChoice, SmOptions};

/// `umbra bench`: frame times along a camera path, or a paper's suite of such runs.
pub struct BenchConfig {
    /// `--backend gl`, `wgpu` or `gl,wgpu` (one interleaved schedule); a suite runs on gl.
    pub backends: Vec<Backend>,
    pub mode: BenchMode,
    /// `--scene` and `--flythrough` of a run along one path.
    pub scene: String,
    pub flythrough: String,
    pub ground: bool,
    pub max_input_bytes: Option<u64>,
    /// `--light`, in order; empty: derived from each scene's bounds.
    pub lights: Vec<Light>,
    /// `--warmup`; `None`: 2 for a path, the suite's own for a suite.
    pub warmup: Option<usize>,
    /// `--stage-every`; `None`: 1 for a path, the suite's own for a suite.
    pub stage_every: Option<usize>,
    pub fov: f64,
    /// `--ortho HEIGHT`: an orthographic camera.
    pub ortho: Option<f64>,
    pub zpass: bool,
    pub auto_zpass: bool,
    /// `--volume-cull`.
    pub volume_cull: bool,
    pub counter: CounterChoice,
    pub sm: SmOptions,
    pub json: bool,
    pub csv: Option<String>,
    pub plot: Option<String>,
    pub trace_order: bool,
    pub log: bool,
}

/// A run along one camera path, or a suite.
/// The suffix of a method measured with its volumes unculled (`--volume-cull both`).
pub const CULL_OFF: &str = "@cull-off";

/// A `--methods` entry as a driver makes it: the method's name, and whether it is the unculled
/// twin (`NAME@cull-off`) that `--volume-cull both` added.
pub fn split_cull_off(entry: &str) -> (&str, bool) {
    match entry.strip_suffix(CULL_OFF) {
        Some(name) => (name, true),
        None => (entry, false),
    }
}

pub enum BenchMode {
    Path {
        /// Methods every backend asked for has.
        methods: Vec<String>,
        width: u32,
        height: u32,
        /// Measured frames, at least 1.
        frames: usize,
    },
    Suite {
        /// The suite, with only the runs `--runs` selects.
        suite: Suite,
        /// `--methods`: replaces every run's methods.
        methods: Option<Vec<String>>,
        /// `--size`: replaces every run's size (not in a stage suite).
        size: Option<(u32, u32)>,
        /// Measured frames per run, at least 1.
        frames: usize,
    },
}

impl BenchConfig {
    pub fn from_args(a: &BenchArgs) -> Result<Checked<Self>, CliError> {
        let backends = a.backend.split(',').map(parse_backend).collect::<Result<Vec<_>, _>>()?;
        if backends.is_empty() || (1..backends.len()).any(|i| backends[..i].contains(&backends[i])) {
            return Err(bad("--backend", format!("expected gl, wgpu or gl,wgpu, got {:?}", a.backend)));
        }
        if let Some(m) = a.methods.as_deref() {
            if asks_for_list(m.trim()) {
                return Ok(Checked::List(Listing::Methods(backends[0])));
            }
        }
        let mut mode = match &a.suite {
            Some(name) => {
                if backends != [Backend::Gl] && name != "list" {
                    return Err(bad("--backend", "the paper suites (--suite) run on the gl backend only"));
                }
                if name == "list" {
                    return Ok(Checked::List(Listing::Suites));
                }
                let mut suite = suite(name)?;
                if let Some(text) = &a.runs {
                    let keep = parse_runs(text, suite.runs.len())?;
                    suite.runs = keep.into_iter().map(|i| suite.runs[i].clone()).collect();
                }
                let methods = a.methods.as_deref().map(|m| gl_methods(m, "--methods")).transpose()?;
                let size = a.size.as_deref().map(parse_size).transpose()?;
                let frames = check_frames(a.frames.unwrap_or(suite.frames))?;
                BenchMode::Suite { suite, methods, size, frames }
            }
            None => {
                let (width, height) = parse_size(a.size.as_deref().unwrap_or("1280x720"))?;
                let frames = check_frames(a.frames.unwrap_or(24))?;
                // Every backend asked for must have every method (`all`: the wgpu methods when
                // wgpu is asked).
                let text = a.methods.as_deref().unwrap_or("all");
                let methods = if backends.contains(&Backend::Wgpu) {
                    wgpu_methods(text, "--methods")?
                } else {
                    gl_methods(text, "--methods")?
                };
                BenchMode::Path { methods, width, height, frames }
            }
        };
        let fov = check_fov(a.fov)?;
        let ortho = a.ortho.as_deref().map(parse_ortho).transpose()?;
        if ortho.is_some() && backends.contains(&Backend::Wgpu) {
            return Err(bad("--ortho", "applies to --backend gl (the wgpu backend's volumes run to infinity)"));
        }
        let (zpass, auto_zpass) = parse_zmode(&a.zmode, a.zpass)?;
        // `both`: every method that culls its volumes runs twice in the one interleaved
        // schedule, the second time as `NAME@cull-off` (its JSON rows: the same `method`,
        // `volume_cull` false), so the reduction is measured in one run.
        let both = a.volume_cull.trim() == "both";
        let volume_cull = both
            || parse_volume_cull(&a.volume_cull).map_err(|_| {
                bad("--volume-cull", format!("expected on, off or both, got {:?}", a.volume_cull.trim()))
            })?;
        if both {
            if let BenchMode::Path { methods, .. } = &mut mode {
                *methods = methods
                    .iter()
                    .flat_map(|m| {
                        // cpu-silhouette is the method that culls, on GL and on wgpu alike.
                        let culls = umbra_gl::create_method(m).is_ok_and(|x| x.culls_volumes());
                        std::iter::once(m.clone()).chain(culls.then(|| format!("{m}{CULL_OFF}")))
                    })
                    .collect();
            } else {
                return Err(bad("--volume-cull", "both: with a fly-through or orbit only, not with --suite"));
            }
        }
        let counter = parse_counter(&a.counter, "--counter")?;
        let sm = parse_sm(&a.sm)?;
        let lights = a.light.iter().map(|l| parse_light(l)).collect::<Result<Vec<_>, _>>()?;
        Ok(Checked::Run(Self {
            backends,
            mode,
            scene: a.scene.clone(),
            flythrough: a.flythrough.clone(),
            ground: a.ground,
            max_input_bytes: a.max_input_bytes,
            lights,
            warmup: a.warmup,
            stage_every: a.stage_every,
            fov,
            ortho,
            zpass,
            auto_zpass,
            volume_cull,
            counter,
            sm,
            json: a.json,
            csv: a.csv.clone(),
            plot: a.plot.clone(),
            trace_order: a.trace_order,
            log: a.log,
        }))
    }
}

fn check_frames(frames: usize) -> Result<usize, CliError> {
    if frames == 0 {
        return Err(bad("--frames", "must be at least 1"));
    }
    Ok(frames)
}

/// `--runs 1,3,5` (1-based) selects runs: their 0-based indices.
fn parse_runs(text: &str, count: usize) -> Result<Vec<usize>, CliError> {
    text.split(',')
        .map(|s| {
            s.trim()
                .parse::<usize>()
                .ok()
                .filter(|&i| (1..=count).contains(&i))
                .map(|i| i - 1)
                .ok_or_else(|| bad("--runs", format!("{s:?}: expected run numbers 1..={count}")))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_one_based_and_checked() {
        assert_eq!(parse_runs("1,3", 4).expect("ok"), vec![0, 2]);
        assert!(parse_runs("0", 4).is_err() && parse_runs("5", 4).is_err());
    }
}
