//! umbra-wgpu's bench frames ([`umbra_wgpu::Renderer::draw_frame`], no readback) for the interleaved
//! schedule; stage times from GPU timestamps at the passes' boundaries.

use std::time::Instant;

use umbra_wgpu::ShadowVolumes;

use super::driver::Driver;
use super::flythrough::Keyframe;
use super::options::MeasureOptions;
use super::stats::VolumeCounts;
use crate::backend::Backend;
use crate::config::{split_cull_off, ViewConfig};
use crate::error::CliError;
use crate::wgpu_backend::{check_counter, WgpuSession};

/// `bench --backend wgpu`: umbra-wgpu's frames ([`umbra_wgpu::Renderer::draw_frame`], no readback) for
/// the interleaved schedule; stage times from GPU timestamps at the passes' boundaries
/// ([`umbra_wgpu::Renderer::draw_frame_timed`]: prepare, depth+ambient, volumes, lighting) where the
/// adapter has timestamp queries inside encoders.
pub struct WgpuDriver {
    session: WgpuSession,
    params: umbra_wgpu::FrameParams,
    instances: Vec<ShadowVolumes>,
    /// Per instance: its volumes culled (`--volume-cull`; false for `NAME@cull-off`).
    cull: Vec<bool>,
}

impl WgpuDriver {
    pub fn new(view: &ViewConfig, methods: &[String], o: &MeasureOptions) -> Result<Self, CliError> {
        let session = WgpuSession::new(view)?;
        let params = session.frame_params(view);
        check_counter(o.counter, &session.welded, &params.lights)?;
        let mut instances = Vec::new();
        let mut cull = Vec::new();
        for m in methods {
            let (name, off) = split_cull_off(m);
            instances.push(session.volumes(name, &o.sm, "--methods")?);
            cull.push(o.volume_cull && !off);
        }
        Ok(Self { session, params, instances, cull })
    }
}

impl Driver for WgpuDriver {
    fn backend(&self) -> &'static str {
        Backend::Wgpu.name()
    }

    fn device_name(&self) -> String {
        self.session.gpu.adapter_line()
    }

    fn triangles(&self) -> usize {
        self.session.welded.triangles.len()
    }

    fn lights(&self) -> usize {
        self.params.lights.len()
    }

    fn counter(&self, method: usize) -> String {
        if self.instances[method].counts_volumes() { "stencil8" } else { "none" }.to_string()
    }

    fn frame(&mut self, method: usize, cam: Keyframe) -> Result<f64, String> {
        self.set_camera(method, cam);
        let s = &mut self.session;
        let (device, queue) = (&s.gpu.device, &s.gpu.queue);
        let wait =
            || device.poll(umbra_wgpu::wgpu::PollType::wait_indefinitely()).map(|_| ()).map_err(|e| e.to_string());
        // The GPU idle before; CPU clock from the first command recorded to the frame's
        // completion (the submission waited for).
        wait()?;
        let start = Instant::now();
        s.renderer
            .draw_frame(device, queue, &s.scene, &mut self.instances[method], &self.params)
            .map_err(|e| e.to_string())?;
        wait()?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }

    fn stages(&mut self, method: usize, cam: Keyframe) -> Result<Vec<(String, f64)>, String> {
        self.set_camera(method, cam);
        let s = &mut self.session;
        let (device, queue) = (&s.gpu.device, &s.gpu.queue);
        let timed = s.renderer.draw_frame_timed(device, queue, &s.scene, &mut self.instances[method], &self.params);
        // Without timestamp queries: no stages (frame times only).
        Ok(timed.map_err(|e| e.to_string())?.unwrap_or_default())
    }

    fn volume_counts(&mut self, method: usize, cam: Keyframe) -> Result<Option<VolumeCounts>, String> {
        if !self.instances[method].counts_volumes() {
            // No volume pass to count (shadow maps, ray-bvh): no frame drawn.
            return Ok(None);
        }
        self.set_camera(method, cam);
        let s = &mut self.session;
        let (device, queue) = (&s.gpu.device, &s.gpu.queue);
        let v = &mut self.instances[method];
        s.renderer.set_count_volume_fragments(true);
        let drawn = s.renderer.draw_frame(device, queue, &s.scene, v, &self.params);
        let fragments = s.renderer.last_volume_fragments().iter().copied().sum::<Option<u64>>();
        s.renderer.set_count_volume_fragments(false);
        drawn.map_err(|e| e.to_string())?;
        let lights = self.params.lights.len();
        // Triangles and edges: known on the CPU (cpu-silhouette) or read back (cs-silhouette).
        let mut drawn = Some((0, 0));
        for i in 0..lights {
            let d = v.read_drawn_volume(device, queue, i).map_err(|e| e.to_string())?;
            drawn = drawn.zip(d).map(|((t, e), d)| (t + d.triangles, e + d.edges));
        }
        // Fragment-shader invocations: wgpu's pipeline statistics, where the device has them.
        let query = fragments.map(|_| umbra_gl::VolumeFragmentQuery::FragmentShaderInvocations);
        Ok(Some(VolumeCounts { fragments, query, drawn }))
    }

    fn volume_cull(&self, method: usize) -> bool {
        self.cull[method] && self.instances[method].culls_volumes()
    }

    fn zpass_lights(&self, method: usize) -> usize {
        self.instances[method].plans().iter().filter(|p| p.zpass).count()
    }

    fn gpu_bytes(&self, method: usize) -> usize {
        self.instances[method].gpu_bytes() as usize
    }

    fn scene_figures(&self, method: usize) -> Vec<(&'static str, f64)> {
        self.instances[method].scene_figures()
    }
}

impl WgpuDriver {
    /// Method `method`'s frame at `cam`, culled as `--volume-cull` and its name say.
    fn set_camera(&mut self, method: usize, cam: Keyframe) {
        self.params.camera.eye = cam.eye;
        self.params.camera.target = cam.target;
        self.params.volume_cull = self.cull[method];
    }
}
