//! umbra-wgpu's bench frames ([`umbra_wgpu::Renderer::draw_frame`], no readback) for the interleaved
//! schedule; stage times from GPU timestamps at the passes' boundaries.

use std::time::Instant;

use umbra_wgpu::ShadowVolumes;

use super::driver::Driver;
use super::flythrough::Keyframe;
use super::options::MeasureOptions;
use crate::backend::Backend;
use crate::config::ViewConfig;
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
}

impl WgpuDriver {
    pub fn new(view: &ViewConfig, methods: &[String], o: &MeasureOptions) -> Result<Self, CliError> {
        let session = WgpuSession::new(view)?;
        let params = session.frame_params(view);
        check_counter(o.counter, &session.welded, &params.lights)?;
        let instances = methods.iter().map(|m| session.volumes(m, &o.sm, "--methods")).collect::<Result<_, _>>()?;
        Ok(Self { session, params, instances })
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
        self.params.camera.eye = cam.eye;
        self.params.camera.target = cam.target;
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
        self.params.camera.eye = cam.eye;
        self.params.camera.target = cam.target;
        let s = &mut self.session;
        let (device, queue) = (&s.gpu.device, &s.gpu.queue);
        let timed = s.renderer.draw_frame_timed(device, queue, &s.scene, &mut self.instances[method], &self.params);
        // Without timestamp queries: no stages (frame times only).
        Ok(timed.map_err(|e| e.to_string())?.unwrap_or_default())
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
