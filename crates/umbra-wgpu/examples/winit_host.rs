//! A window with a host renderer of its own that uses umbra's shadows (examples/host/mod.rs):
//! the host owns the device, the surface, the depth-stencil texture, the passes and its
//! shaders; umbra's `ShadowVolumes` counts a point light's and a directional light's shadow
//! volumes into the host's stencil inside the host's render passes. The point light circles
//! the sphere.
//!
//! `cargo run --release -p umbra-wgpu --example winit_host [-- --frames N] [-- --msaa]`
//! (`--frames N`: close after N frames and print the frame rate, e.g. under Xvfb;
//! `--msaa`: 4 samples per pixel, volumes counted per sample).

#[path = "host/mod.rs"]
mod host;

use std::sync::Arc;
use std::time::Instant;

use umbra_geom::scene::{ground_plane, torus, uv_sphere};
use umbra_wgpu::wgpu;
use umbra_wgpu::{Camera, SceneGpu, View};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    host: host::HostRenderer,
    scene: SceneGpu,
}

#[derive(Default)]
struct App {
    state: Option<State>,
    error: Option<String>,
    frames: u32,
    max_frames: Option<u32>,
    msaa: bool,
    start: Option<Instant>,
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<State, Box<dyn std::error::Error>> {
        let window = Arc::new(event_loop.create_window(
            Window::default_attributes().with_title("umbra-wgpu: a host renderer with umbra's shadows"),
        )?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: umbra_wgpu::device::backends(),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| format!("no adapter for this window ({e}); {}", umbra_wgpu::device::INSTALL_HINT))?;
        // The host's device: what umbra's volumes need, nothing more.
        let (device, queue) = umbra_wgpu::device::request_device(&adapter, umbra_wgpu::device::volume_features())?;
        let size = window.inner_size();
        let caps = surface.get_capabilities(&adapter);
        let format = caps.formats.first().copied().ok_or("the surface offers no format")?;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&device, &config);
        let mut mesh = uv_sphere([0.0, 1.6, 0.0], 0.8, 48, 24);
        mesh.append(&torus([1.8, 0.6, 0.5], 0.6, 0.2, 48, 16));
        mesh.append(&ground_plane([0.0, 0.0, 0.0], 8.0));
        let scene = SceneGpu::upload(&device, Arc::new(umbra_geom::weld::weld(&mesh)))?;
        let samples = if self.msaa { 4 } else { 1 };
        let host = host::HostRenderer::new(
            &device,
            format,
            wgpu::TextureFormat::Depth24PlusStencil8,
            samples,
            "cs-silhouette",
        )?;
        println!("{} on {}", host.volumes.method_name(), umbra_wgpu::device::adapter_line(&adapter));
        Ok(State { window, surface, device, queue, config, host, scene })
    }

    fn draw(&mut self) -> Result<(), Box<dyn std::error::Error>> {
        let Some(s) = self.state.as_mut() else { return Ok(()) };
        let t = self.start.get_or_insert_with(Instant::now).elapsed().as_secs_f32();
        let frame = match s.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            other => {
                // Lost or outdated: configure again and skip this frame.
                eprintln!("surface: {other:?}");
                s.surface.configure(&s.device, &s.config);
                return Ok(());
            }
        };
        let target = frame.texture.create_view(&Default::default());
        let (w, h) = (s.config.width, s.config.height);
        let camera = Camera { near: 0.02, ..Camera::look_at([4.5, 3.5, 5.5], [0.0, 0.7, 0.0]) };
        let view = View::from_camera(&camera, w, h)?;
        let lights = [[3.0 * t.cos(), 4.0, 3.0 * t.sin(), 1.0], [-0.4, 1.0, 0.3, 0.0]];
        let mut encoder = s.device.create_command_encoder(&Default::default());
        s.host.frame(&s.device, &s.queue, &mut encoder, &s.scene, &view, &lights, &target, (w, h))?;
        s.queue.submit([encoder.finish()]);
        s.window.pre_present_notify();
        s.queue.present(frame);
        self.frames += 1;
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_none() {
            match self.init(event_loop) {
                Ok(s) => self.state = Some(s),
                Err(e) => {
                    self.error = Some(e.to_string());
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(s) = self.state.as_mut() {
                    s.config.width = size.width.max(1);
                    s.config.height = size.height.max(1);
                    s.surface.configure(&s.device, &s.config);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.draw() {
                    self.error = Some(e.to_string());
                    event_loop.exit();
                }
                if self.max_frames.is_some_and(|n| self.frames >= n) {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(s) = &self.state {
            s.window.request_redraw();
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let max_frames =
        args.iter().position(|a| a == "--frames").and_then(|i| args.get(i + 1)).map(|n| n.parse()).transpose()?;
    let mut app = App { max_frames, msaa: args.iter().any(|a| a == "--msaa"), ..App::default() };
    let event_loop = EventLoop::new().map_err(|e| format!("no window system ({e}); try the headless example"))?;
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e.into());
    }
    let seconds = app.start.map_or(0.0, |s| s.elapsed().as_secs_f64());
    println!("{} frames in {seconds:.2} s", app.frames);
    Ok(())
}
