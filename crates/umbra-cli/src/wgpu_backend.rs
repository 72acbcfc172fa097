//! `--backend wgpu`: `render`, `verify` and `info` on umbra-wgpu (Vulkan, Metal, DX12; Mesa's
//! lavapipe without a GPU); `bench`'s wgpu frames are `bench/wgpu_driver.rs`. The same checked configuration ([`ViewConfig`]), the same
//! frame parameters ([`crate::session::frame_params_for`]), the same verifier and output
//! formats as the GL backend; what differs is said where it applies: the methods
//! (`umbra_wgpu::method_names()`: no geometry or tessellation shaders on wgpu), the counter (the
//! 8-bit stencil only: `--counter float32`, or `auto` when a count could reach 256, is an
//! error), shadow maps (six face passes: `--sm-faces` has no effect; an integer constant bias),
//! bench stages (GPU timestamps between the passes, coarser than GL's).

use std::path::Path;
use std::sync::Arc;

use umbra_geom::weld::WeldedMesh;
use umbra_wgpu::methods::shadow_map::ShadowMapConfig;
use umbra_wgpu::{HeadlessGpu, Renderer, SceneGpu, ShadowVolumes};

use crate::config::{RenderConfig, ViewConfig};
use crate::error::CliError;
use crate::methods::{choose_counter, report_counter, CounterChoice, SmOptions};

/// A wgpu error as the CLI reports it.
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
    let decision = choose_counter(choice, &welded.positions, &welded.triangles, lights)?;
    report_counter(&decision);
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

/// `umbra render --backend wgpu`.
pub fn render(c: &RenderConfig) -> Result<(), CliError> {
    let view = &c.view;
    let mut s = WgpuSession::new(view)?;
    let params = s.frame_params(view);
    check_counter(c.counter, &s.welded, &params.lights)?;
    let mut volumes = s.volumes(&c.method, &c.sm, "--method")?;
    let (device, queue) = (&s.gpu.device, &s.gpu.queue);
    let images = s.renderer.render(device, queue, &s.scene, &mut volumes, &params).map_err(wgpu_err)?;
    images.rgba.save_png(Path::new(&c.out)).map_err(wgpu_err)?;
    eprintln!(
        "umbra: wrote {} ({}x{}, {} triangles, method {}, wgpu on {})",
        c.out,
        view.width,
        view.height,
        s.welded.triangles.len(),
        c.method,
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
