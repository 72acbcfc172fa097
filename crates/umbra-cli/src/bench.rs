//! `umbra bench`: frame times of shadow methods along a camera path, the way the papers
//! measure them (paper 001 Sec. 3, Tables 1-9: FPS over fly-throughs; paper 003 Sec. 3,
//! Tables 1-4: average frame time over fly-throughs and per-stage times).
//!
//! Protocol:
//! * warm-up rounds first (llvmpipe compiles a shader at its first draw), not recorded;
//! * methods interleaved frame by frame (A B C A B C ...), so drift of a shared machine hits
//!   all of them alike ([`schedule`]);
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
//! Submodules: [`flythrough`] (camera paths), [`plot`] (SVG), [`suites`] (the papers' tables).

mod flythrough;
mod plot;
mod suites;

use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::Path;

use serde::Serialize;
use umbra_geom::scene;
use umbra_geom::{Aabb, Light};
use umbra_gl::{Attachments, FrameTarget, RenderTarget, StageHook, StageMark, StageTiming, TimestampHook};

use crate::args::BenchArgs;
use crate::config::{default_light, load_scene, parse_light, parse_size, CameraConfig, CliError, Framing, ViewConfig};
pub use crate::methods::{make_method, method_exists, SmOptions};
use crate::session::Session;
use crate::wgpu_backend::Backend;

/// `bench --methods`: see [`crate::methods::parse_methods`].
pub fn parse_methods(text: &str) -> Result<Vec<String>, CliError> {
    crate::methods::parse_methods(text, "--methods")
}

pub use flythrough::Keyframe;

fn bad(flag: &'static str, message: impl Into<String>) -> CliError {
    CliError::BadFlag { flag, message: message.into() }
}

fn gl_err(e: impl std::fmt::Display) -> CliError {
    CliError::Gl(e.to_string())
}

/// One step of the interleaved schedule: round `round` (warm-up or measured) of method
/// `method` (index into the method list).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slot {
    pub round: usize,
    pub method: usize,
    pub warmup: bool,
}

/// Warm-up rounds, then measured rounds; in every round each method once, in list order.
pub fn schedule(methods: usize, warmup: usize, frames: usize) -> Vec<Slot> {
    let rounds = (0..warmup).map(|r| (r, true)).chain((0..frames).map(|r| (r, false)));
    rounds.flat_map(|(round, warmup)| (0..methods).map(move |method| Slot { round, method, warmup })).collect()
}

/// A loaded scene ready to bench: mesh (with ground if asked), the bounds of the scene itself,
/// framing, lights.
pub struct BenchScene {
    pub spec: String,
    pub mesh: umbra_geom::Mesh,
    pub bounds: Aabb,
    pub framing: Framing,
    pub lights: Vec<Light>,
}

impl BenchScene {
    pub fn load(spec: &str, ground: bool, max_input_bytes: Option<u64>, lights: &[String]) -> Result<Self, CliError> {
        let framing = Framing::of(&scene::parse(spec)?);
        let mut mesh = load_scene(spec, false, max_input_bytes)?;
        let bounds = mesh.bounds().unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
        if ground {
            scene::add_ground(&mut mesh);
        }
        let explicit = lights.iter().map(|l| parse_light(l)).collect::<Result<Vec<_>, _>>()?;
        let lights = if explicit.is_empty() { vec![default_light(&bounds, framing)] } else { explicit };
        Ok(Self { spec: spec.to_string(), mesh, bounds, framing, lights })
    }
}

/// `orbit`, or a fly-through file, as `frames` cameras.
pub fn camera_path(which: &str, scene: &BenchScene, frames: usize) -> Result<Vec<Keyframe>, CliError> {
    let n = frames.max(1);
    if which == "orbit" {
        return Ok(flythrough::orbit(&scene.bounds, scene.framing, n));
    }
    let keys = flythrough::load(Path::new(which))?;
    Ok(flythrough::interpolate(&keys, n))
}

/// Everything one measurement needs besides the scene.
#[derive(Clone, Debug)]
pub struct MeasureOptions {
    pub width: u32,
    pub height: u32,
    pub warmup: usize,
    /// Draw a stage-timed copy of every `stage_every`-th measured round; 0 = never.
    pub stage_every: usize,
    pub fov: f64,
    pub zpass: bool,
    /// `--zmode auto`: z-pass where provably exact.
    pub auto_zpass: bool,
    /// `--counter` (resolved per scene and lights in [`measure`]).
    pub counter: crate::methods::CounterChoice,
    pub sm: SmOptions,
    pub trace_order: bool,
    /// `--log`: one stderr line per drawn frame.
    pub log: bool,
    pub progress_label: String,
}

/// Per-method results of one measurement.
#[derive(Clone, Debug, Default)]
pub struct MethodStats {
    pub method: String,
    /// Whole-frame times of the measured rounds, in round order (ms).
    pub frame_ms: Vec<f64>,
    /// Per stage (first-seen order): the stage's time in each stage-timed round (ms).
    pub stage_ms: Vec<(String, Vec<f64>)>,
    pub gpu_bytes: usize,
    pub error: Option<String>,
    /// The counter the method's volume pass used ("stencil8", "float32", or "none" for a
    /// method that does not count in the stencil).
    pub counter: String,
    /// Measured frames' lights counted z-pass, and all measured frames' lights.
    pub zpass_lights: usize,
    pub lights: usize,
}

impl MethodStats {
    pub fn mean(&self) -> Option<f64> {
        (!self.frame_ms.is_empty()).then(|| self.frame_ms.iter().sum::<f64>() / self.frame_ms.len() as f64)
    }
    pub fn median(&self) -> Option<f64> {
        percentile_sorted(&sorted(&self.frame_ms), 0.5)
    }
    pub fn p95(&self) -> Option<f64> {
        percentile_sorted(&sorted(&self.frame_ms), 0.95)
    }
    /// Mean of each stage over the stage-timed rounds.
    pub fn stage_means(&self) -> Vec<(String, f64)> {
        self.stage_ms
            .iter()
            .filter(|(_, v)| !v.is_empty())
            .map(|(n, v)| (n.clone(), v.iter().sum::<f64>() / v.len() as f64))
            .collect()
    }
}

fn sorted(v: &[f64]) -> Vec<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// Median (q = 0.5: mean of the middle two for even counts) or nearest-rank percentile.
fn percentile_sorted(s: &[f64], q: f64) -> Option<f64> {
    if s.is_empty() {
        return None;
    }
    if q == 0.5 {
        let n = s.len();
        return Some(if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) });
    }
    let rank = ((q * s.len() as f64).ceil() as usize).clamp(1, s.len());
    Some(s[rank - 1])
}

/// Stage name of a timing: the renderer's passes by their role, the method's by its label.
fn stage_name(t: &StageTiming) -> String {
    match (t.mark.source, t.mark.label) {
        ("renderer", "depth") => "depth+ambient".into(),
        ("renderer", "volumes") => "stencil-clear".into(),
        ("renderer", "lighting") => "lighting".into(),
        (_, label) => label.to_string(),
    }
}

/// Forwards only the frame's first mark and its "end" mark to a synchronous timestamp hook:
/// glFinish right before the frame's first pass and right after its last, CPU clock between.
struct FrameClock {
    inner: TimestampHook,
    seen_first: bool,
}

impl StageHook for FrameClock {
    fn mark(&mut self, gl: &umbra_gl::glow::Context, mark: StageMark) {
        if !self.seen_first || mark.label == "end" {
            self.seen_first = true;
            self.inner.mark(gl, mark);
        }
    }
}

/// Stage timing with timestamp pairs that are right on llvmpipe. A timestamp query there is
/// recorded when the rasterizer runs the command batch holding it, i.e. at the NEXT flush: a
/// query issued after the glFinish of a synchronous mark would carry the time the following
/// stage ends. So every mark is followed by a second synchronous mark ("flush") whose glFinish
/// executes the first query at once; a stage's time is the sum of its two intervals (mark to
/// flush, flush to the next mark) = the difference of the two marks' timestamps.
struct StageClock {
    inner: TimestampHook,
}

impl StageHook for StageClock {
    fn mark(&mut self, gl: &umbra_gl::glow::Context, mark: StageMark) {
        self.inner.mark(gl, mark);
        self.inner.mark(gl, StageMark { source: "bench", label: "flush", light: mark.light });
    }
}

/// Per stage (name, GPU ms from timestamps, CPU ms between the glFinish-ed marks), from the
/// timings of a [`StageClock`] frame, summed over lights, in first-seen order.
fn stage_times(timings: &[StageTiming]) -> Vec<(String, f64, f64)> {
    let mut per: Vec<(String, f64, f64)> = Vec::new();
    for pair in timings.chunks(2) {
        // "end" only closes the last stage; its own interval is the hook's epilogue.
        if pair[0].mark.label == "end" {
            continue;
        }
        let name = stage_name(&pair[0]);
        let gpu = pair.iter().map(|t| t.gpu_ns).sum::<u64>() as f64 / 1e6;
        let cpu = pair.iter().map(|t| t.cpu_ns).sum::<u64>() as f64 / 1e6;
        match per.iter_mut().find(|(n, _, _)| *n == name) {
            Some((_, g, c)) => {
                *g += gpu;
                *c += cpu;
            }
            None => per.push((name, gpu, cpu)),
        }
    }
    per
}

/// Progress on stderr when it is a terminal.
struct Progress {
    on: bool,
    total: usize,
    label: String,
}

impl Progress {
    fn new(total: usize, label: &str) -> Self {
        Self { on: std::io::stderr().is_terminal(), total, label: label.to_string() }
    }
    fn show(&self, done: usize, what: &str) {
        if !self.on {
            return;
        }
        let width = 30;
        let filled = (done * width).checked_div(self.total).unwrap_or(width).min(width);
        let bar: String = "#".repeat(filled) + &" ".repeat(width - filled);
        eprint!("\r{} [{bar}] {done}/{} {what:<28}", self.label, self.total);
        let _ = std::io::stderr().flush();
    }
    fn done(&self) {
        if self.on {
            eprint!("\r{}\r", " ".repeat(self.label.len() + 80));
            let _ = std::io::stderr().flush();
        }
    }
}

/// What the measurement saw besides the per-method stats.
pub struct Measurement {
    /// Per row of `stats`: its backend.
    pub backends: Vec<&'static str>,
    pub stats: Vec<MethodStats>,
    pub renderer: String,
    pub triangles: usize,
}

/// The view a measurement draws (the camera moves along `cameras`), shared by both backends.
pub fn bench_view(scene: &BenchScene, cameras: &[Keyframe], o: &MeasureOptions) -> Result<ViewConfig, CliError> {
    if cameras.is_empty() {
        return Err(CliError::Other("no frames to measure".into()));
    }
    Ok(ViewConfig {
        scene_spec: scene.spec.clone(),
        mesh: scene.mesh.clone(),
        camera: CameraConfig {
            eye: cameras[0].eye,
            target: cameras[0].target,
            up: [0.0, 1.0, 0.0],
            fov_y_degrees: o.fov,
        },
        lights: scene.lights.clone(),
        width: o.width,
        height: o.height,
        zpass: o.zpass,
        auto_zpass: o.auto_zpass,
    })
}

/// One backend's frames, as the interleaved schedule drives them ([`run_schedule`]).
pub trait Driver {
    /// "gl" or "wgpu".
    fn backend(&self) -> &'static str;
    /// The device, for the report.
    fn device_name(&self) -> String;
    /// Triangles drawn.
    fn triangles(&self) -> usize;
    /// Lights per frame.
    fn lights(&self) -> usize;
    /// Method `method`'s counter label ("stencil8", "float32", "none").
    fn counter(&self, method: usize) -> String;
    /// Draws method `method`'s frame at `cam` (no readback) and returns its time: the GPU
    /// idle before, CPU clock from the first command to the frame's completion (ms).
    fn frame(&mut self, method: usize, cam: Keyframe) -> Result<f64, String>;
    /// The same frame once more with per-stage timing: (stage, GPU ms) summed over lights;
    /// empty when the backend has no stage timing.
    fn stages(&mut self, method: usize, cam: Keyframe) -> Result<Vec<(String, f64)>, String>;
    /// Lights of the last frame counted z-pass.
    fn zpass_lights(&self, method: usize) -> usize;
    /// Bytes of GPU memory method `method` holds.
    fn gpu_bytes(&self, method: usize) -> usize;
}

/// umbra-gl's frames: [`umbra_gl::Renderer::draw_frame`] into an offscreen target.
struct GlDriver {
    s: Session,
    params: umbra_gl::FrameParams,
    target: Option<RenderTarget>,
    instances: Vec<Box<dyn umbra_gl::ShadowMethod>>,
    clock: FrameClock,
    stage_hook: StageClock,
}

impl GlDriver {
    fn new(view: &ViewConfig, methods: &[String], o: &MeasureOptions) -> Result<Self, CliError> {
        let s = Session::new(view)?;
        let mut params = s.frame_params(view);
        let decision =
            crate::methods::choose_counter(o.counter, &s.welded.positions, &s.welded.triangles, &params.lights)?;
        crate::methods::report_counter(&decision);
        params.counter = decision.counter;
        let target = RenderTarget::new(s.context.gl(), o.width, o.height, Attachments::default()).map_err(gl_err)?;
        let mut instances = Vec::new();
        for m in methods {
            instances.push(make_method(m, &o.sm, "--methods")?);
        }
        Ok(Self {
            s,
            params,
            target: Some(target),
            instances,
            clock: FrameClock { inner: TimestampHook::synchronous(), seen_first: false },
            stage_hook: StageClock { inner: TimestampHook::synchronous() },
        })
    }
}

impl Drop for GlDriver {
    fn drop(&mut self) {
        let gl = self.s.context.gl();
        for m in &mut self.instances {
            m.destroy(gl);
        }
        std::mem::take(&mut self.clock.inner).destroy(gl);
        std::mem::take(&mut self.stage_hook.inner).destroy(gl);
        if let Some(t) = self.target.take() {
            t.destroy(gl);
        }
    }
}

impl GlDriver {
    fn target(&self) -> FrameTarget {
        FrameTarget { framebuffer: self.target.as_ref().map(RenderTarget::framebuffer) }
    }

    fn set_camera(&mut self, cam: Keyframe) {
        self.params.camera.eye = cam.eye;
        self.params.camera.target = cam.target;
    }
}

impl Driver for GlDriver {
    fn backend(&self) -> &'static str {
        "gl"
    }

    fn device_name(&self) -> String {
        self.s.context.renderer_string()
    }

    fn triangles(&self) -> usize {
        self.s.welded.triangles.len()
    }

    fn lights(&self) -> usize {
        self.params.lights.len()
    }

    fn counter(&self, method: usize) -> String {
        crate::methods::counter_label(self.instances[method].as_ref(), self.params.counter).to_string()
    }

    fn frame(&mut self, method: usize, cam: Keyframe) -> Result<f64, String> {
        self.set_camera(cam);
        let fb = self.target();
        let gl = self.s.context.gl();
        self.clock.seen_first = false;
        let m = self.instances[method].as_mut();
        let drawn = self.s.renderer.draw_frame(gl, &self.s.scene, m, &self.params, fb, Some(&mut self.clock));
        let timings = self.clock.inner.finish(gl);
        drawn.map_err(|e| e.to_string())?;
        Ok(timings.iter().map(|t| t.cpu_ns).sum::<u64>() as f64 / 1e6)
    }

    fn stages(&mut self, method: usize, cam: Keyframe) -> Result<Vec<(String, f64)>, String> {
        self.set_camera(cam);
        let fb = self.target();
        let gl = self.s.context.gl();
        let m = self.instances[method].as_mut();
        let drawn = self.s.renderer.draw_frame(gl, &self.s.scene, m, &self.params, fb, Some(&mut self.stage_hook));
        let timings = self.stage_hook.inner.finish(gl);
        drawn.map_err(|e| e.to_string())?;
        Ok(stage_times(&timings).into_iter().map(|(name, gpu_ms, _)| (name, gpu_ms)).collect())
    }

    fn zpass_lights(&self, _method: usize) -> usize {
        self.s.renderer.last_zpass().iter().filter(|z| **z).count()
    }

    fn gpu_bytes(&self, method: usize) -> usize {
        self.instances[method].gpu_bytes()
    }
}

/// One row of a measurement: method `method` of driver `driver`.
struct Entry {
    driver: usize,
    method: usize,
}

/// Runs the interleaved schedule of `entries` (driver, method) over `cameras` (one camera per
/// measured round; warm-up round r uses camera r): warm-up rounds first, then every entry once
/// per round in list order, so drift of a shared machine hits every method and backend alike.
fn run_schedule(
    drivers: &mut [Box<dyn Driver>],
    entries: &[Entry],
    names: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
) -> Vec<MethodStats> {
    let mut stats: Vec<MethodStats> = entries
        .iter()
        .zip(names)
        .map(|(e, name)| MethodStats {
            method: name.clone(),
            counter: drivers[e.driver].counter(e.method),
            ..Default::default()
        })
        .collect();
    let slots = schedule(entries.len(), o.warmup, cameras.len());
    let progress = Progress::new(slots.len(), &o.progress_label);
    for (i, slot) in slots.iter().enumerate() {
        let st = &mut stats[slot.method];
        if st.error.is_some() {
            continue;
        }
        let entry = &entries[slot.method];
        let driver = drivers[entry.driver].as_mut();
        progress.show(i, &st.method);
        if o.trace_order {
            eprintln!("bench-order {} {} {}", if slot.warmup { "warmup" } else { "frame" }, slot.round, st.method);
        }
        let cam = cameras[slot.round % cameras.len()];
        let frame_ms = match driver.frame(entry.method, cam) {
            Ok(ms) => ms,
            Err(e) => {
                eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                st.error = Some(e);
                continue;
            }
        };
        if o.log {
            let kind = if slot.warmup { "warmup" } else { "frame" };
            eprintln!("umbra bench: {} {kind} {} {} {frame_ms:.1} ms", o.progress_label, slot.round, st.method);
        }
        let zpass = driver.zpass_lights(entry.method);
        let stage_round = o.stage_every > 0 && (slot.warmup || slot.round % o.stage_every == 0);
        if stage_round {
            match driver.stages(entry.method, cam) {
                Ok(stages) if !slot.warmup => {
                    for (name, ms) in stages {
                        match st.stage_ms.iter_mut().find(|(n, _)| *n == name) {
                            Some((_, v)) => v.push(ms),
                            None => st.stage_ms.push((name, vec![ms])),
                        }
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                    st.error = Some(e);
                    continue;
                }
            }
        }
        if !slot.warmup {
            st.frame_ms.push(frame_ms);
            st.zpass_lights += zpass;
            st.lights += driver.lights();
        }
    }
    progress.done();
    for (st, e) in stats.iter_mut().zip(entries) {
        st.gpu_bytes = drivers[e.driver].gpu_bytes(e.method);
    }
    stats
}

/// Runs the interleaved schedule of `methods` over `cameras` on a fresh GL context.
pub fn measure(
    scene: &BenchScene,
    methods: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
) -> Result<Measurement, CliError> {
    measure_backends(scene, methods, cameras, o, &[Backend::Gl])
}

/// The same for every backend of `backends`, in ONE interleaved schedule (`--backend gl,wgpu`:
/// wgpu against GL in the same run). With several backends each row's method is labelled
/// `NAME@BACKEND` in the table (the JSON rows keep `method` and gain `backend`).
pub fn measure_backends(
    scene: &BenchScene,
    methods: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
    backends: &[Backend],
) -> Result<Measurement, CliError> {
    let view = bench_view(scene, cameras, o)?;
    let mut drivers: Vec<Box<dyn Driver>> = Vec::new();
    let mut entries = Vec::new();
    let mut names = Vec::new();
    for (d, &backend) in backends.iter().enumerate() {
        drivers.push(match backend {
            Backend::Gl => Box::new(GlDriver::new(&view, methods, o)?),
            Backend::Wgpu => Box::new(crate::wgpu_backend::WgpuDriver::new(&view, methods, o)?),
        });
        for (m, name) in methods.iter().enumerate() {
            entries.push(Entry { driver: d, method: m });
            names.push(if backends.len() > 1 { format!("{name}@{}", backend.name()) } else { name.clone() });
        }
    }
    let stats = run_schedule(&mut drivers, &entries, &names, cameras, o);
    let backend_of: Vec<&'static str> = entries.iter().map(|e| drivers[e.driver].backend()).collect();
    Ok(Measurement {
        backends: backend_of,
        stats,
        renderer: drivers
            .iter()
            .map(|d| format!("{}: {}", d.backend(), d.device_name()))
            .collect::<Vec<_>>()
            .join("; "),
        triangles: drivers.first().map_or(0, |d| d.triangles()),
    })
}
/// One object of `bench --json`; the first seven keys are the contract.
#[derive(Serialize, Debug, Clone)]
pub struct JsonRow {
    pub method: String,
    pub frames: usize,
    pub mean_ms: Option<f64>,
    pub median_ms: Option<f64>,
    pub p95_ms: Option<f64>,
    /// Stage name -> mean ms over the stage-timed frames.
    pub stages: BTreeMap<String, f64>,
    pub gpu_bytes: usize,
    pub scene: String,
    pub triangles: usize,
    /// "stencil8", "float32", or "none" (the method does not count in the stencil).
    pub counter: String,
    /// Share of the measured frames' lights counted z-pass (`--zmode`), 0 to 1.
    pub zpass_share: f64,
    pub width: u32,
    pub height: u32,
    /// "gl" or "wgpu" (`--backend`).
    pub backend: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

pub fn json_rows(
    m: &Measurement,
    scene: &str,
    width: u32,
    height: u32,
    run: Option<&str>,
    x: Option<f64>,
) -> Vec<JsonRow> {
    m.stats
        .iter()
        .zip(&m.backends)
        .map(|(s, &backend)| JsonRow {
            method: s.method.split('@').next().unwrap_or(&s.method).to_string(),
            frames: s.frame_ms.len(),
            mean_ms: s.mean(),
            median_ms: s.median(),
            p95_ms: s.p95(),
            stages: s.stage_means().into_iter().collect(),
            gpu_bytes: s.gpu_bytes,
            scene: scene.to_string(),
            triangles: m.triangles,
            counter: s.counter.clone(),
            zpass_share: if s.lights == 0 { 0.0 } else { s.zpass_lights as f64 / s.lights as f64 },
            width,
            height,
            backend: backend.to_string(),
            run: run.map(str::to_string),
            x,
            error: s.error.clone(),
        })
        .collect()
}

/// Per-frame samples in long form: `scene,width,height,method,frame,kind,name,ms` with kind
/// `frame` (whole frame) or `stage`.
pub fn csv_lines(m: &Measurement, scene: &str, width: u32, height: u32, stage_every: usize) -> Vec<String> {
    let mut out = Vec::new();
    let q = |s: &str| if s.contains([',', '"']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() };
    for s in &m.stats {
        for (f, ms) in s.frame_ms.iter().enumerate() {
            out.push(format!("{},{width},{height},{},{f},frame,total,{ms:.4}", q(scene), q(&s.method)));
        }
        for (name, v) in &s.stage_ms {
            for (k, ms) in v.iter().enumerate() {
                let f = k * stage_every.max(1);
                out.push(format!("{},{width},{height},{},{f},stage,{},{ms:.4}", q(scene), q(&s.method), q(name)));
            }
        }
    }
    out
}

pub const CSV_HEADER: &str = "scene,width,height,method,frame,kind,name,ms";

/// The 1-, 5- and 15-minute load averages (Linux), for the record.
pub fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

fn fmt_ms(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.2}"))
}

/// Markdown table of one measurement.
pub fn print_table(m: &Measurement) {
    let mut stage_names: Vec<String> = Vec::new();
    for s in &m.stats {
        for (n, _) in &s.stage_ms {
            if !stage_names.contains(n) {
                stage_names.push(n.clone());
            }
        }
    }
    let mut header = "| method | frames | mean ms | median ms | p95 ms | GPU MiB |".to_string();
    for n in &stage_names {
        header.push_str(&format!(" {n} |"));
    }
    println!("{header}");
    println!("|{}", " --- |".repeat(6 + stage_names.len()));
    for s in &m.stats {
        let means = s.stage_means();
        let mut row = format!(
            "| {} | {} | {} | {} | {} | {:.1} |",
            s.method,
            s.frame_ms.len(),
            fmt_ms(s.mean()),
            fmt_ms(s.median()),
            fmt_ms(s.p95()),
            s.gpu_bytes as f64 / (1024.0 * 1024.0)
        );
        for n in &stage_names {
            row.push_str(&format!(" {} |", fmt_ms(means.iter().find(|(k, _)| k == n).map(|(_, v)| *v))));
        }
        if let Some(e) = &s.error {
            row.push_str(&format!(" error: {e}"));
        }
        println!("{row}");
    }
}

/// Frame-time plot (`path`) and stage plot (`path`-stages.svg).
pub fn write_plots(path: &Path, title: &str, m: &Measurement) -> Result<(), CliError> {
    let series: Vec<(String, Vec<(f64, f64)>)> = m
        .stats
        .iter()
        .filter(|s| !s.frame_ms.is_empty())
        .map(|s| (s.method.clone(), s.frame_ms.iter().enumerate().map(|(f, &ms)| (f as f64, ms)).collect()))
        .collect();
    plot::lines(path, &format!("{title}: frame time along the path"), "frame", "ms", &series, false)?;
    let mut stage_names: Vec<String> = Vec::new();
    for s in &m.stats {
        for (n, _) in &s.stage_ms {
            if !stage_names.contains(n) {
                stage_names.push(n.clone());
            }
        }
    }
    let rows: Vec<(String, Vec<f64>)> = m
        .stats
        .iter()
        .filter(|s| !s.stage_ms.is_empty())
        .map(|s| {
            let means = s.stage_means();
            (
                s.method.clone(),
                stage_names.iter().map(|n| means.iter().find(|(k, _)| k == n).map_or(0.0, |(_, v)| *v)).collect(),
            )
        })
        .collect();
    plot::stacked_bars(&plot::stages_path(path), &format!("{title}: stages"), &stage_names, &rows)
}

/// Frames, warm-up and stage settings from the flags (shared by plain runs and suites).
pub fn measure_options(
    a: &BenchArgs,
    width: u32,
    height: u32,
    stage_every_default: usize,
    label: &str,
) -> Result<MeasureOptions, CliError> {
    if !(a.fov > 0.0 && a.fov < 180.0) {
        return Err(bad("--fov", format!("must be in (0, 180) degrees, got {}", a.fov)));
    }
    let (zpass, auto_zpass) = crate::config::parse_zmode(&a.zmode, a.zpass)?;
    Ok(MeasureOptions {
        width,
        height,
        warmup: a.warmup.unwrap_or(2),
        stage_every: a.stage_every.unwrap_or(stage_every_default),
        fov: a.fov,
        zpass,
        auto_zpass,
        counter: crate::methods::CounterChoice::parse(&a.counter, "--counter")?,
        sm: SmOptions::from_args(&a.sm)?,
        trace_order: a.trace_order,
        log: a.log,
        progress_label: label.to_string(),
    })
}

pub fn run(a: &BenchArgs) -> Result<(), CliError> {
    let backends = a.backend.split(',').map(Backend::parse).collect::<Result<Vec<_>, _>>()?;
    if backends.is_empty() || (1..backends.len()).any(|i| backends[..i].contains(&backends[i])) {
        return Err(bad("--backend", format!("expected gl, wgpu or gl,wgpu, got {:?}", a.backend)));
    }
    // `--methods help` (or `list`): the methods of the first backend named, one per line.
    if let Some(m) = a.methods.as_deref() {
        if crate::methods::list_if_help_for(backends[0], m.trim()) {
            return Ok(());
        }
    }
    if let Some(name) = &a.suite {
        if backends != [Backend::Gl] && name != "list" {
            return Err(bad("--backend", "the paper suites (--suite) run on the gl backend only"));
        }
        return suites::run(name, a);
    }
    let (width, height) = parse_size(a.size.as_deref().unwrap_or("1280x720"))?;
    let frames = a.frames.unwrap_or(24);
    if frames == 0 {
        return Err(bad("--frames", "must be at least 1"));
    }
    // Every backend asked for must have every method (`all`: the wgpu methods when wgpu is asked).
    let text = a.methods.as_deref().unwrap_or("all");
    let methods = if backends.contains(&Backend::Wgpu) {
        crate::wgpu_backend::parse_methods(text, "--methods")?
    } else {
        parse_methods(text)?
    };
    let o = measure_options(a, width, height, 1, "bench")?;
    let scene = BenchScene::load(&a.scene, a.ground, a.max_input_bytes, &a.light)?;
    let cameras = camera_path(&a.flythrough, &scene, frames)?;
    let load_before = load_average();
    // wgpu rows have frame times only (no stage timing: their stages stay empty).
    let m = measure_backends(&scene, &methods, &cameras, &o, &backends)?;
    let load_after = load_average();
    if let Some(path) = &a.csv {
        let mut text = String::from(CSV_HEADER);
        text.push('\n');
        for l in csv_lines(&m, &scene.spec, width, height, o.stage_every) {
            text.push_str(&l);
            text.push('\n');
        }
        std::fs::write(path, text).map_err(|source| CliError::Io { path: path.clone(), source })?;
    }
    if let Some(path) = &a.plot {
        write_plots(Path::new(path), &format!("{} {width}x{height}", scene.spec), &m)?;
    }
    if a.json {
        let rows = json_rows(&m, &scene.spec, width, height, None, None);
        println!("{}", serde_json::to_string_pretty(&rows).map_err(|e| CliError::Other(e.to_string()))?);
    } else {
        println!(
            "{} ({} triangles) at {width}x{height}, {} frame(s) + {} warm-up along {}, {} light(s), {}; load average {} -> {}",
            scene.spec,
            m.triangles,
            frames,
            o.warmup,
            a.flythrough,
            scene.lights.len(),
            m.renderer,
            load_before.as_deref().unwrap_or("?"),
            load_after.as_deref().unwrap_or("?"),
        );
        print_table(&m);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_interleaves_methods_after_warmup() {
        let s = schedule(3, 1, 2);
        let order: Vec<(usize, usize, bool)> = s.iter().map(|x| (x.round, x.method, x.warmup)).collect();
        assert_eq!(
            order,
            vec![
                (0, 0, true),
                (0, 1, true),
                (0, 2, true),
                (0, 0, false),
                (0, 1, false),
                (0, 2, false),
                (1, 0, false),
                (1, 1, false),
                (1, 2, false)
            ]
        );
        assert!(schedule(0, 2, 5).is_empty());
    }

    #[test]
    fn stage_times_pair_each_mark_with_its_flush_and_sum_lights() {
        let t = |source: &'static str, label: &'static str, light, gpu_ns| StageTiming {
            mark: StageMark { source, label, light },
            gpu_ns,
            cpu_ns: gpu_ns + 1,
        };
        let timings = [
            t("renderer", "depth", None, 1_000_000),
            t("bench", "flush", None, 500_000),
            t("renderer", "lighting", Some(0), 2_000_000),
            t("bench", "flush", Some(0), 0),
            t("renderer", "lighting", Some(1), 3_000_000),
            t("bench", "flush", Some(1), 1_000_000),
            t("renderer", "end", None, 7),
        ];
        let s = stage_times(&timings);
        let names: Vec<&str> = s.iter().map(|(n, _, _)| n.as_str()).collect();
        assert_eq!(names, ["depth+ambient", "lighting"], "end dropped, lights summed");
        assert!((s[0].1 - 1.5).abs() < 1e-12 && (s[1].1 - 6.0).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn percentiles() {
        let st = MethodStats { frame_ms: vec![5.0, 1.0, 3.0, 2.0, 4.0], ..Default::default() };
        assert_eq!(st.mean(), Some(3.0));
        assert_eq!(st.median(), Some(3.0));
        assert_eq!(st.p95(), Some(5.0));
        let even = MethodStats { frame_ms: vec![4.0, 1.0, 3.0, 2.0], ..Default::default() };
        assert_eq!(even.median(), Some(2.5));
        let twenty = MethodStats { frame_ms: (1..=20).map(f64::from).collect(), ..Default::default() };
        assert_eq!(twenty.p95(), Some(19.0), "nearest rank: ceil(0.95 * 20) = 19th");
        assert_eq!(MethodStats::default().mean(), None);
    }
}
