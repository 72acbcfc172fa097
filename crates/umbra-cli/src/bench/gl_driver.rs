//! umbra-gl's bench frames and their clocks: the whole frame between two glFinish calls, and
//! per-stage GPU times from timestamp queries at every stage boundary.

use umbra_gl::{Attachments, FrameTarget, RenderTarget, StageHook, StageMark, StageTiming, TimestampHook};

use super::driver::Driver;
use super::flythrough::Keyframe;
use super::options::MeasureOptions;
use super::stats::VolumeCounts;
use crate::config::{split_cull_off, ViewConfig};
use crate::error::CliError;
use crate::methods::{choose_counter, counter_label, make_method, report_counter};
use crate::session::Session;

fn gl_err(e: impl std::fmt::Display) -> CliError {
    CliError::Gl(e.to_string())
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

/// umbra-gl's frames: [`umbra_gl::Renderer::draw_frame`] into an offscreen target.
pub struct GlDriver {
    s: Session,
    params: umbra_gl::FrameParams,
    target: Option<RenderTarget>,
    instances: Vec<Box<dyn umbra_gl::ShadowMethod>>,
    /// Per instance: its volumes culled (`--volume-cull`; false for `NAME@cull-off`).
    cull: Vec<bool>,
    clock: FrameClock,
    stage_hook: StageClock,
}

impl GlDriver {
    pub fn new(view: &ViewConfig, methods: &[String], o: &MeasureOptions) -> Result<Self, CliError> {
        let s = Session::new(view)?;
        let mut params = s.frame_params(view);
        let decision = choose_counter(o.counter, &s.welded.positions, &s.welded.triangles, &params.lights)?;
        report_counter(&decision);
        params.counter = decision.counter;
        let target = RenderTarget::new(s.context.gl(), o.width, o.height, Attachments::default()).map_err(gl_err)?;
        let mut instances = Vec::new();
        let mut cull = Vec::new();
        for m in methods {
            let (name, off) = split_cull_off(m);
            instances.push(make_method(name, &o.sm, "--methods")?);
            cull.push(o.volume_cull && !off);
        }
        Ok(Self {
            s,
            params,
            target: Some(target),
            instances,
            cull,
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
        crate::session::fit_ortho_far(&mut self.params.camera, self.s.scene.bounds());
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
        counter_label(self.instances[method].as_ref(), self.params.counter).to_string()
    }

    fn frame(&mut self, method: usize, cam: Keyframe) -> Result<f64, String> {
        self.set_camera(cam);
        self.params.volume_cull = self.cull[method];
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
        self.params.volume_cull = self.cull[method];
        let fb = self.target();
        let gl = self.s.context.gl();
        let m = self.instances[method].as_mut();
        let drawn = self.s.renderer.draw_frame(gl, &self.s.scene, m, &self.params, fb, Some(&mut self.stage_hook));
        let timings = self.stage_hook.inner.finish(gl);
        drawn.map_err(|e| e.to_string())?;
        Ok(stage_times(&timings).into_iter().map(|(name, gpu_ms, _)| (name, gpu_ms)).collect())
    }

    fn work(&mut self, method: usize, cam: Keyframe) -> Result<Option<umbra_gl::WorkCounts>, String> {
        self.set_camera(cam);
        self.params.volume_cull = self.cull[method];
        let fb = self.target();
        let gl = self.s.context.gl();
        let m = self.instances[method].as_mut();
        m.set_count_work(true);
        // A method without work counts says None at once: no frame drawn for it.
        if m.work_counts(gl).is_none() {
            return Ok(None);
        }
        m.set_count_work(true);
        let drawn = self.s.renderer.draw_frame(gl, &self.s.scene, m, &self.params, fb, None);
        let counts = m.work_counts(gl);
        m.set_count_work(false);
        drawn.map_err(|e| e.to_string())?;
        Ok(counts)
    }

    fn volume_counts(&mut self, method: usize, cam: Keyframe) -> Result<Option<VolumeCounts>, String> {
        if !self.instances[method].fills_volumes() {
            // No volume pass to count (hier-triangle, ray-bvh): no frame drawn.
            return Ok(None);
        }
        self.set_camera(cam);
        self.params.volume_cull = self.cull[method];
        let fb = self.target();
        let gl = self.s.context.gl();
        let m = self.instances[method].as_mut();
        self.s.renderer.set_count_volume_fragments(true);
        let drawn = self.s.renderer.draw_frame(gl, &self.s.scene, m, &self.params, fb, None);
        self.s.renderer.set_count_volume_fragments(false);
        drawn.map_err(|e| e.to_string())?;
        let lights = self.params.lights.len();
        let fragments = self.s.renderer.last_volume_fragments().iter().take(lights).copied().sum::<Option<u64>>();
        let drawn = self
            .s
            .renderer
            .last_drawn()
            .iter()
            .take(lights)
            .try_fold((0, 0), |(t, e), d| d.map(|d| (t + d.triangles, e + d.edges)));
        let query = fragments.and(self.s.renderer.volume_fragment_query());
        Ok(Some(VolumeCounts { fragments, query, drawn }))
    }

    fn volume_cull(&self, method: usize) -> bool {
        self.cull[method] && self.instances[method].culls_volumes()
    }

    fn zpass_lights(&self, _method: usize) -> usize {
        self.s.renderer.last_zpass().iter().filter(|z| **z).count()
    }

    fn gpu_bytes(&self, method: usize) -> usize {
        self.instances[method].gpu_bytes()
    }

    fn scene_figures(&self, method: usize) -> Vec<(&'static str, f64)> {
        self.instances[method].scene_figures()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
