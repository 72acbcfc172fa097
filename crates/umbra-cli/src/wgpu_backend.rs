//! `--backend wgpu`: `render`, `verify`, `bench` and `info` on umbra-wgpu (Vulkan, Metal, DX12;
//! Mesa's lavapipe without a GPU). The same checked configuration ([`ViewConfig`]), the same
//! frame parameters ([`crate::session::frame_params_for`]), the same verifier and output
//! formats as the GL backend; what differs is said where it applies: the methods
//! (`umbra_wgpu::method_names()`: no geometry or tessellation shaders on wgpu), the counter (the
//! 8-bit stencil only: `--counter float32`, or `auto` when a count could reach 256, is an
//! error), shadow maps (six face passes: `--sm-faces` has no effect; an integer constant bias),
//! bench stages (GPU timestamps between the passes, coarser than GL's).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use umbra_geom::weld::WeldedMesh;
use umbra_wgpu::methods::shadow_map::ShadowMapConfig;
use umbra_wgpu::{HeadlessGpu, Renderer, SceneGpu, ShadowVolumes};

use crate::config::{CliError, ViewConfig};
use crate::methods::{CounterChoice, SmOptions};

/// Which backend draws (`--backend`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// OpenGL 4.5 through EGL (umbra-gl), the default.
    Gl,
    /// wgpu: Vulkan, Metal or DX12 (umbra-wgpu).
    Wgpu,
}

impl Backend {
    /// `gl` or `wgpu`.
    pub fn parse(text: &str) -> Result<Self, CliError> {
        match text.trim() {
            "gl" => Ok(Backend::Gl),
            "wgpu" => Ok(Backend::Wgpu),
            other => {
                Err(CliError::BadFlag { flag: "--backend", message: format!("expected gl or wgpu, got {other:?}") })
            }
        }
    }

    /// `gl` or `wgpu`, as the JSON outputs name it.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Gl => "gl",
            Backend::Wgpu => "wgpu",
        }
    }
}

pub fn wgpu_err(e: impl std::fmt::Display) -> CliError {
    CliError::Gl(format!("wgpu: {e}"))
}

/// The wgpu backend's twin of [`crate::session::Session`]: device, uploaded scene, renderer.
pub struct WgpuSession {
    pub gpu: HeadlessGpu,
    pub scene: SceneGpu,
    pub renderer: Renderer,
    pub welded: Arc<WeldedMesh>,
}

impl WgpuSession {
    /// Welds the mesh ([`crate::session::welded_scene`]), creates the device (a missing adapter
    /// is an error naming what to install) and uploads the scene.
    pub fn new(view: &ViewConfig) -> Result<Self, CliError> {
        let welded = crate::session::welded_scene(view)?;
        let gpu = HeadlessGpu::new().map_err(wgpu_err)?;
        let scene = SceneGpu::upload(&gpu.device, welded.clone()).map_err(wgpu_err)?;
        let renderer = Renderer::new(&gpu.device).map_err(wgpu_err)?;
        Ok(Self { gpu, scene, renderer, welded })
    }

    /// The frame `render` and `verify` draw for `view`: the GL backend's parameters
    /// ([`crate::session::frame_params_for`]), the same struct (reversed-Z and the 8-bit
    /// stencil counter, both defaults; the counter is checked by [`check_counter`]).
    pub fn frame_params(&self, view: &ViewConfig) -> umbra_wgpu::FrameParams {
        crate::session::frame_params_for(view, self.scene.bounds())
    }

    /// The volumes of `name` for this session's renderer; shadow maps with the `--sm-*` options.
    pub fn volumes(&self, name: &str, sm: &SmOptions, flag: &'static str) -> Result<ShadowVolumes, CliError> {
        let device = &self.gpu.device;
        if let Some(mut c) = ShadowMapConfig::from_name(name) {
            if let Some(b) = sm.bias_constant {
                c.bias_constant = b.round() as i32;
            }
            if let Some(s) = sm.bias_slope {
                c.bias_slope = s;
            }
            c.pcf |= sm.pcf;
            return self.renderer.shadow_map(device, c).map_err(wgpu_err);
        }
        self.renderer.volumes(device, name).map_err(|e| match e {
            umbra_wgpu::WgpuError::UnknownMethod { .. } => CliError::BadFlag { flag, message: e.to_string() },
            other => wgpu_err(other),
        })
    }
}

/// The wgpu backend counts in the 8-bit stencil only: `float32`, or `auto` when the winding
/// bound of some light reaches 256, is an error (never a silently wrapped image).
pub fn check_counter(choice: CounterChoice, welded: &WeldedMesh, lights: &[umbra_geom::Light]) -> Result<(), CliError> {
    let decision = crate::methods::choose_counter(choice, &welded.positions, &welded.triangles, lights)?;
    crate::methods::report_counter(&decision);
    if decision.counter == umbra_gl::counter::Counter::Float32 {
        let why = match decision.bound {
            Some(b) => format!("a winding bound of {b} layers reaches 256"),
            None => "float32 was asked for".to_string(),
        };
        return Err(CliError::BadFlag {
            flag: "--counter",
            message: format!(
                "the wgpu backend counts in the 8-bit stencil only and {why}; use --backend gl for the float32 counter"
            ),
        });
    }
    Ok(())
}

/// `all` (every wgpu method), or a comma-separated list of names, each checked against the
/// wgpu registry (any `shadow-map-cube:RES[+pcf]`).
pub fn parse_methods(text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    if text.trim() == "all" {
        return Ok(umbra_wgpu::method_names().iter().map(|s| s.to_string()).collect());
    }
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
    if names.is_empty() {
        return Err(CliError::BadFlag { flag, message: "no method named".into() });
    }
    for n in &names {
        if !umbra_wgpu::method_names().contains(&n.as_str()) && ShadowMapConfig::from_name(n).is_none() {
            let gl_only = umbra_gl::create_method(n).is_ok();
            return Err(CliError::BadFlag {
                flag,
                message: format!(
                    "unknown shadow method {n:?} on the wgpu backend{}; known: {}",
                    if gl_only { " (it needs geometry or tessellation shaders: --backend gl)" } else { "" },
                    umbra_wgpu::method_names().join(", ")
                ),
            });
        }
    }
    Ok(names)
}

/// `umbra render --backend wgpu`.
pub fn render(a: &crate::args::RenderArgs, method_name: &str) -> Result<(), CliError> {
    let sm = SmOptions::from_args(&a.sm)?;
    parse_methods(method_name, "--method")?;
    let view = ViewConfig::from_args(&a.view)?;
    let choice = CounterChoice::parse(&a.counter, "--counter")?;
    let mut s = WgpuSession::new(&view)?;
    let params = s.frame_params(&view);
    check_counter(choice, &s.welded, &params.lights)?;
    let mut volumes = s.volumes(method_name, &sm, "--method")?;
    let (device, queue) = (&s.gpu.device, &s.gpu.queue);
    let images = s.renderer.render(device, queue, &s.scene, &mut volumes, &params).map_err(wgpu_err)?;
    images.rgba.save_png(Path::new(&a.out)).map_err(wgpu_err)?;
    eprintln!(
        "umbra: wrote {} ({}x{}, {} triangles, method {}, wgpu on {})",
        a.out,
        view.width,
        view.height,
        s.welded.triangles.len(),
        method_name,
        s.gpu.adapter_line()
    );
    Ok(())
}

/// One method's outcome in [`verify`]: its report, or why it could not be drawn here.
pub type MethodOutcome = Result<WgpuVerified, CliError>;

/// One method's verification on wgpu: the report, the counter label and the per-light z-pass.
pub struct WgpuVerified {
    pub report: umbra_verify::MethodReport,
    pub counter: &'static str,
    pub zpass: Vec<bool>,
}

/// `umbra verify --backend wgpu`: the view's reference from the wgpu frame's own samples,
/// then every method through [`umbra_verify::wgpu::verify_method`].
pub fn verify(
    view: &ViewConfig,
    methods: &[String],
    sm: &SmOptions,
    choice: CounterChoice,
) -> Result<(WgpuSession, umbra_verify::ViewReference, Vec<MethodOutcome>), CliError> {
    let mut s = WgpuSession::new(view)?;
    let params = s.frame_params(view);
    check_counter(choice, &s.welded, &params.lights)?;
    let (device, queue) = (&s.gpu.device, &s.gpu.queue);
    let reference = umbra_verify::wgpu::view_reference(device, queue, &mut s.renderer, &s.scene, &params)
        .map_err(|e| CliError::Other(e.to_string()))?;
    let mut out = Vec::new();
    for name in methods {
        // Per method: one that cannot be drawn here is its own error (verify.rs goes on with
        // the others when there are several).
        let verified = (|| {
            let mut volumes = s.volumes(name, sm, "--method")?;
            let (device, queue) = (&s.gpu.device, &s.gpu.queue);
            let report = umbra_verify::wgpu::verify_method(
                device,
                queue,
                &mut s.renderer,
                &s.scene,
                &mut volumes,
                &params,
                &reference,
            )
            .map_err(|e| CliError::Other(e.to_string()))?;
            let counter = if volumes.counts_volumes() { "stencil8" } else { "none" };
            let zpass = volumes.plans().iter().map(|p| p.zpass).collect();
            Ok(WgpuVerified { report, counter, zpass })
        })();
        out.push(verified);
    }
    Ok((s, reference, out))
}

/// `umbra info --backend wgpu`: the adapter umbra-wgpu would draw on, one line per fact.
pub fn adapter_report() -> Result<Vec<(String, String)>, CliError> {
    let gpu = HeadlessGpu::new().map_err(wgpu_err)?;
    let info = gpu.adapter.get_info();
    let features = gpu.device.features();
    let yes = |f| if features.contains(f) { "yes" } else { "no" };
    Ok(vec![
        ("adapter".into(), info.name.clone()),
        ("backend".into(), format!("{:?}", info.backend)),
        ("device type".into(), format!("{:?}", info.device_type)),
        ("driver".into(), format!("{} {}", info.driver, info.driver_info).trim().to_string()),
        ("depth clamp".into(), yes(umbra_wgpu::wgpu::Features::DEPTH_CLIP_CONTROL).into()),
        ("clip distances".into(), yes(umbra_wgpu::wgpu::Features::CLIP_DISTANCES).into()),
        ("primitive index".into(), yes(umbra_wgpu::wgpu::Features::PRIMITIVE_INDEX).into()),
        ("depth32float-stencil8".into(), yes(umbra_wgpu::wgpu::Features::DEPTH32FLOAT_STENCIL8).into()),
        ("methods".into(), umbra_wgpu::method_names().join(", ")),
    ])
}

/// `bench --backend wgpu`: umbra-wgpu's frames ([`Renderer::draw_frame`], no readback) for
/// the interleaved schedule; stage times from GPU timestamps at the passes' boundaries
/// ([`Renderer::draw_frame_timed`]: prepare, depth+ambient, volumes, lighting) where the
/// adapter has timestamp queries inside encoders.
pub struct WgpuDriver {
    session: WgpuSession,
    params: umbra_wgpu::FrameParams,
    instances: Vec<ShadowVolumes>,
}

impl WgpuDriver {
    pub fn new(view: &ViewConfig, methods: &[String], o: &crate::bench::MeasureOptions) -> Result<Self, CliError> {
        let session = WgpuSession::new(view)?;
        let params = session.frame_params(view);
        check_counter(o.counter, &session.welded, &params.lights)?;
        let instances = methods.iter().map(|m| session.volumes(m, &o.sm, "--methods")).collect::<Result<_, _>>()?;
        Ok(Self { session, params, instances })
    }
}

impl crate::bench::Driver for WgpuDriver {
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

    fn frame(&mut self, method: usize, cam: crate::bench::Keyframe) -> Result<f64, String> {
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

    fn stages(&mut self, method: usize, cam: crate::bench::Keyframe) -> Result<Vec<(String, f64)>, String> {
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
}
