//! The viewer's event loop (winit 0.30 `ApplicationHandler`): input to camera, light and
//! method changes, one frame per redraw through [`Renderer::draw_frame`] into an offscreen
//! target blitted to the window, the shadow-mask view through [`Renderer::render`]'s lit
//! masks, scripted poses and the screenshot.

use std::collections::HashSet;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::Light;
use umbra_gl::glow;
use umbra_gl::{
    create_method, method_names, read_rgba8, Attachments, Camera, DepthConvention, FrameParams, FrameTarget, Image,
    LightCapture, RenderTarget, Renderer, RgbaImage, SceneGpu, ShadowMethod,
};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::WindowId;

use crate::glue::{self, GlWindow, ImageView};
use crate::overlay::{self, OverlayInfo};
use crate::rig::{move_light, CameraRig};
use crate::script::Pose;
use crate::{ViewError, ViewSummary, ViewerConfig};

/// Radians of orbit per pixel of mouse drag.
const ORBIT_PER_PIXEL: f64 = 0.005;
/// Fly speed: scene diagonals per second.
const FLY_PER_SECOND: f64 = 0.25;
/// One arrow-key press moves a light by this fraction of the scene diagonal.
const LIGHT_STEP: f64 = 0.02;
/// The wireframe's tint: the frame's colour times this where a volume edge passes (a red
/// line on light surfaces, darker on dark ones).
const WIREFRAME_TINT: [f32; 3] = [1.0, 0.2, 0.2];
/// The title is rewritten at most this often.
const TITLE_EVERY: Duration = Duration::from_millis(250);

/// Everything that exists once the window does.
struct Running {
    // Dropped after the GL objects below are destroyed explicitly in `shutdown`.
    win: GlWindow,
    scene: SceneGpu,
    renderer: Renderer,
    method: Box<dyn ShadowMethod>,
    method_index: usize,
    target: Option<RenderTarget>,
    mask: Option<ImageView>,
    adjacency: Option<Arc<EdgeAdjacency>>,
}

#[derive(Default)]
struct Input {
    left_down: bool,
    shift: bool,
    cursor: Option<(f64, f64)>,
    held: HashSet<KeyCode>,
}

struct App {
    config: ViewerConfig,
    script: Option<Vec<Pose>>,
    script_pos: usize,
    running: Option<Running>,
    error: Option<ViewError>,
    summary: ViewSummary,
    rig: CameraRig,
    lights: Vec<Light>,
    selected_light: usize,
    show_mask: bool,
    /// Draw the selected light's shadow volumes as a wireframe over the shaded view (F).
    wireframe: bool,
    input: Input,
    diagonal: f64,
    /// Centre of the mesh's box (the orthographic far plane is fitted from it).
    centre: [f64; 3],
    frame_ms: Option<f64>,
    last_frame: Option<Instant>,
    last_title: Option<Instant>,
    silhouette_edges: Option<usize>,
    status: Option<String>,
}

pub fn run(config: ViewerConfig, script: Option<Vec<Pose>>) -> Result<ViewSummary, ViewError> {
    let event_loop =
        EventLoop::new().map_err(|e| ViewError::NoDisplay(format!("cannot connect to the display server: {e}")))?;
    // Reason: draw continuously (frame time, held keys); redraws are requested in about_to_wait.
    event_loop.set_control_flow(ControlFlow::Poll);
    let c = config.params.camera;
    let diagonal = mesh_diagonal(&config);
    let centre = mesh_centre(&config);
    let show_mask = config.mask_view;
    let mut app = App {
        rig: CameraRig { eye: c.eye, target: c.target, up: c.up },
        lights: config.params.lights.clone(),
        config,
        script,
        script_pos: 0,
        running: None,
        error: None,
        summary: ViewSummary::default(),
        selected_light: 0,
        show_mask,
        wireframe: false,
        input: Input::default(),
        diagonal,
        centre,
        frame_ms: None,
        last_frame: None,
        last_title: None,
        silhouette_edges: None,
        status: None,
    };
    event_loop.run_app(&mut app).map_err(|e| ViewError::Window(format!("event loop: {e}")))?;
    if let Some(r) = app.running.take() {
        shutdown(r);
    }
    match app.error {
        Some(e) => Err(e),
        None => Ok(app.summary),
    }
}

fn mesh_centre(config: &ViewerConfig) -> [f64; 3] {
    let mesh = &config.mesh;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in mesh.triangles.iter().flatten().map(|&i| mesh.positions[i as usize]) {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    if c.iter().all(|v| v.is_finite()) {
        c
    } else {
        [0.0; 3]
    }
}

fn mesh_diagonal(config: &ViewerConfig) -> f64 {
    let mesh = &config.mesh;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in mesh.triangles.iter().flatten().map(|&i| mesh.positions[i as usize]) {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

fn shutdown(r: Running) {
    let Running { win, scene, renderer, mut method, target, mask, .. } = r;
    let gl = &win.gl;
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    if let Some(t) = target {
        t.destroy(gl);
    }
    if let Some(m) = mask {
        m.destroy(gl);
    }
}

/// Lit masks of all lights → grey levels: white = lit by every light, black = by none.
fn mask_image(width: u32, height: u32, masks: &[umbra_gl::LitMask], lights: usize) -> RgbaImage {
    let mut img = Image::new(width, height, [0, 0, 0, 255]);
    let n = lights.max(1) as u32;
    for (i, px) in img.pixels.iter_mut().enumerate() {
        let lit = masks.iter().filter(|m| m.image.pixels.get(i).is_some_and(|&v| v != 0)).count() as u32;
        let g = (255 * lit / n) as u8;
        *px = [g, g, g, 255];
    }
    img
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        self.error = Some(e);
        event_loop.exit();
    }

    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<Running, ViewError> {
        let p = &self.config.params;
        let vsync = self.script.is_none() && self.config.screenshot.is_none();
        let win = glue::create(event_loop, "umbra view", p.width, p.height, vsync)?;
        self.summary.gl_renderer = win.renderer_string();
        let gl = &win.gl;
        let scene = SceneGpu::upload(gl, self.config.mesh.clone())?;
        // glClipControl through the window's display (GLX or EGL), for reversed-Z.
        let renderer = Renderer::new(gl)?.with_extra(win.extra);
        let method = create_method(&self.config.method)?;
        let method_index = method_names().iter().position(|&n| n == self.config.method).unwrap_or(0);
        Ok(Running { win, scene, renderer, method, method_index, target: None, mask: None, adjacency: None })
    }

    fn light_changed(&mut self) {
        self.silhouette_edges = None;
    }

    fn set_method(&mut self, index: usize) {
        let Some(r) = self.running.as_mut() else { return };
        let names = method_names();
        let Some(&name) = names.get(index % names.len()) else { return };
        match create_method(name) {
            Ok(m) => {
                r.method.destroy(&r.win.gl);
                r.method = m;
                r.method_index = index % names.len();
                self.status = None;
            }
            Err(e) => self.status = Some(e.to_string()),
        }
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, code: KeyCode, pressed: bool, repeat: bool) {
        if pressed {
            self.input.held.insert(code);
        } else {
            self.input.held.remove(&code);
            return;
        }
        let step = LIGHT_STEP * self.diagonal;
        let light_delta = match code {
            KeyCode::ArrowLeft => Some([-step, 0.0, 0.0]),
            KeyCode::ArrowRight => Some([step, 0.0, 0.0]),
            KeyCode::ArrowUp => Some([0.0, 0.0, -step]),
            KeyCode::ArrowDown => Some([0.0, 0.0, step]),
            KeyCode::PageUp => Some([0.0, step, 0.0]),
            KeyCode::PageDown => Some([0.0, -step, 0.0]),
            _ => None,
        };
        if let Some(d) = light_delta {
            if let Some(l) = self.lights.get_mut(self.selected_light) {
                *l = move_light(*l, d, self.diagonal);
                self.light_changed();
            }
            return;
        }
        if repeat {
            return;
        }
        let digit = match code {
            KeyCode::Digit1 => Some(0),
            KeyCode::Digit2 => Some(1),
            KeyCode::Digit3 => Some(2),
            KeyCode::Digit4 => Some(3),
            KeyCode::Digit5 => Some(4),
            KeyCode::Digit6 => Some(5),
            KeyCode::Digit7 => Some(6),
            KeyCode::Digit8 => Some(7),
            KeyCode::Digit9 => Some(8),
            KeyCode::Digit0 => Some(9),
            _ => None,
        };
        if let Some(i) = digit {
            self.set_method(i);
            return;
        }
        match code {
            KeyCode::KeyM => {
                let next = self.running.as_ref().map_or(0, |r| r.method_index + 1);
                self.set_method(next);
            }
            KeyCode::KeyH => {
                // hier-triangle, beyond the number keys' first ten methods.
                if let Some(i) = method_names().iter().position(|&n| n == umbra_gl::methods::hier_triangle::NAME) {
                    self.set_method(i);
                }
            }
            KeyCode::KeyR => {
                // hier-silhouette (the RSSV idea), beyond the number keys' first ten methods.
                if let Some(i) = method_names().iter().position(|&n| n == umbra_gl::methods::hier_silhouette::NAME) {
                    self.set_method(i);
                }
            }
            KeyCode::KeyB => {
                // ray-bvh (one shadow ray per sample), beyond the number keys' first ten methods.
                if let Some(i) = method_names().iter().position(|&n| n == umbra_gl::methods::ray_bvh::NAME) {
                    self.set_method(i);
                }
            }
            KeyCode::KeyV => self.show_mask = !self.show_mask,
            // The receiver cull of the volumes (docs/exactness.md): the same image, less fill.
            KeyCode::KeyC => self.config.params.volume_cull = !self.config.params.volume_cull,
            KeyCode::KeyF => {
                self.wireframe = !self.wireframe;
                self.status = None;
            }
            KeyCode::Tab if !self.lights.is_empty() => {
                self.selected_light = (self.selected_light + 1) % self.lights.len()
            }
            KeyCode::Escape => event_loop.exit(),
            _ => {}
        }
    }

    fn drag(&mut self, dx: f64, dy: f64) {
        if self.input.shift {
            // Move the selected light in the image plane, by the distance a pixel covers at
            // the target's depth.
            let fov = self.config.params.camera.fov_y_degrees.to_radians();
            let height =
                self.running.as_ref().map_or(self.config.params.height, |r| r.win.window.inner_size().height).max(1);
            let per_pixel = match self.config.params.camera.projection {
                // Orthographic: every depth has the view's height across the window.
                umbra_gl::Projection::Orthographic { height: h, .. } => h / f64::from(height),
                umbra_gl::Projection::Perspective => 2.0 * self.rig.distance() * (0.5 * fov).tan() / f64::from(height),
            };
            let d = (self.rig.right() * dx - self.rig.screen_up() * dy) * per_pixel;
            if let Some(l) = self.lights.get_mut(self.selected_light) {
                *l = move_light(*l, d.to_array(), self.diagonal);
                self.light_changed();
            }
        } else {
            self.rig.orbit(-dx * ORBIT_PER_PIXEL, dy * ORBIT_PER_PIXEL);
        }
    }

    fn fly(&mut self, dt: f64) {
        let held = |k| self.input.held.contains(&k);
        let axis = |plus, minus| f64::from(u8::from(held(plus))) - f64::from(u8::from(held(minus)));
        let forward = axis(KeyCode::KeyW, KeyCode::KeyS);
        let right = axis(KeyCode::KeyD, KeyCode::KeyA);
        let up = axis(KeyCode::KeyE, KeyCode::KeyQ);
        if forward != 0.0 || right != 0.0 || up != 0.0 {
            let s = FLY_PER_SECOND * self.diagonal * dt;
            self.rig.fly(forward * s, right * s, up * s);
        }
    }

    fn frame_params(&self, width: u32, height: u32) -> FrameParams {
        let c = self.config.params.camera;
        let mut camera = Camera { eye: self.rig.eye, target: self.rig.target, up: self.rig.up, ..c };
        if let umbra_gl::Projection::Orthographic { height, .. } = camera.projection {
            // The far plane beyond the scene wherever the rig moved the eye: every point of
            // the scene lies within half a diagonal of its box's centre.
            let to_centre: f64 = (0..3).map(|k| (self.centre[k] - camera.eye[k]).powi(2)).sum::<f64>().sqrt();
            let far = (to_centre + 0.5 * self.diagonal).max(camera.near) * 1.01 + camera.near;
            camera.projection = umbra_gl::Projection::Orthographic { height, far };
        }
        FrameParams { camera, width, height, lights: self.lights.clone(), ..self.config.params.clone() }
    }

    /// Draws one frame; Ok(true) when the viewer is done (screenshot written).
    fn redraw(&mut self) -> Result<bool, ViewError> {
        let now = Instant::now();
        let dt = self.last_frame.map_or(0.0, |t| now.duration_since(t).as_secs_f64()).min(0.25);
        if let Some(t) = self.last_frame {
            let ms = now.duration_since(t).as_secs_f64() * 1e3;
            // Exponential smoothing so the figure is readable.
            self.frame_ms = Some(self.frame_ms.map_or(ms, |old| 0.9 * old + 0.1 * ms));
        }
        self.last_frame = Some(now);
        self.fly(dt);
        let pose = self.script.as_ref().and_then(|s| s.get(self.script_pos).copied());
        if let Some(p) = pose {
            self.rig.eye = p.eye;
            self.rig.target = p.target;
            self.wireframe = p.wireframe;
        }
        let last_pose = self.script.as_ref().is_none_or(|s| self.script_pos + 1 >= s.len());

        let Some(size) = self.running.as_ref().map(|r| r.win.window.inner_size()) else { return Ok(false) };
        if size.width == 0 || size.height == 0 {
            return Ok(false);
        }
        let (w, h) = (size.width, size.height);
        let mut params = self.frame_params(w, h);
        let Some(r) = self.running.as_mut() else { return Ok(false) };
        let gl = &r.win.gl;
        let drawn = if self.show_mask {
            params.capture.lit_mask = LightCapture::AllLights;
            r.renderer.render(gl, &r.scene, r.method.as_mut(), &params, None).map(|frame| {
                if r.mask.as_ref().is_some_and(|m| m.size() != (w, h)) {
                    if let Some(m) = r.mask.take() {
                        m.destroy(gl);
                    }
                }
                if r.mask.is_none() {
                    r.mask = ImageView::new(gl, w, h).ok();
                }
                if let Some(m) = &r.mask {
                    m.show(&r.win, &mask_image(w, h, &frame.lit_masks, params.lights.len()));
                }
            })
        } else {
            if r.target.as_ref().is_some_and(|t| (t.width(), t.height()) != (w, h)) {
                if let Some(t) = r.target.take() {
                    t.destroy(gl);
                }
            }
            if r.target.is_none() {
                // The depth format umbra's own target uses for this convention, so the window
                // shows what `umbra render` writes.
                let float_depth = params.depth_convention == DepthConvention::ReversedZ;
                r.target = Some(RenderTarget::new(gl, w, h, Attachments { float_depth, ..Attachments::default() })?);
            }
            let Some(t) = r.target.as_ref() else { return Ok(false) };
            let fb = t.framebuffer();
            let target = FrameTarget { framebuffer: Some(fb) };
            r.renderer.draw_frame(gl, &r.scene, r.method.as_mut(), &params, target, None).and_then(|_| {
                let light = params.lights.get(self.selected_light).copied();
                match light.filter(|_| self.wireframe) {
                    // Over the finished frame, against its depth (the volumes' own test).
                    Some(l) => match r.renderer.draw_volume_wireframe(
                        gl,
                        &r.scene,
                        r.method.as_mut(),
                        &params,
                        l,
                        target,
                        WIREFRAME_TINT,
                    ) {
                        // A shadow map has no volumes: say so, keep drawing the frame.
                        Err(umbra_gl::GlError::Unsupported { method, .. }) => {
                            self.status = Some(format!("{method} has no shadow volumes to show"));
                            Ok(())
                        }
                        other => other,
                    },
                    None => Ok(()),
                }
                .map(|()| r.win.blit_to_window(fb, w, h, false))
            })
        };
        if let Err(e) = drawn {
            let initial = method_names().iter().position(|&n| n == self.config.method).unwrap_or(0);
            if r.method_index == initial {
                return Err(e.into());
            }
            // A method picked in the viewer failed here: say so and go back to the initial one.
            let failed = r.method.name();
            self.set_method(initial);
            self.status = Some(format!("{failed} failed: {e}"));
            return Ok(false);
        }
        self.summary.frames += 1;

        let mut done = false;
        if last_pose {
            if let Some(path) = self.config.screenshot.clone() {
                // The window's back buffer, exactly what is about to be shown.
                let shot = read_rgba8(&r.win.gl, None, glow::BACK, w, h);
                shot.save_png(Path::new(&path)).map_err(umbra_gl::GlError::from)?;
                self.summary.screenshot = Some((path, w, h));
                done = true;
            }
        }
        r.win.swap()?;
        if self.script.is_some() {
            if last_pose {
                // The path is over: the camera stays at its last pose, the controls take over.
                self.script = None;
            } else {
                self.script_pos += 1;
            }
        }
        self.update_title(now);
        Ok(done)
    }

    fn update_title(&mut self, now: Instant) {
        if self.last_title.is_some_and(|t| now.duration_since(t) < TITLE_EVERY) {
            return;
        }
        self.last_title = Some(now);
        let Some(r) = self.running.as_mut() else { return };
        if self.silhouette_edges.is_none() {
            let adjacency = r.adjacency.get_or_insert_with(|| r.scene.adjacency().clone());
            self.silhouette_edges = Some(overlay::silhouette_edges(&self.config.mesh, adjacency, &self.lights));
        }
        let title = overlay::title(&OverlayInfo {
            scene: &self.config.scene_name,
            method: r.method.name(),
            frame_ms: self.frame_ms,
            triangles: self.config.mesh.triangles.len(),
            silhouette_edges: self.silhouette_edges,
            lights: self.lights.len(),
            selected_light: self.selected_light,
            mask_view: self.show_mask,
            wireframe: self.wireframe,
            volume_cull: self.config.params.volume_cull,
            status: self.status.as_deref(),
        });
        r.win.window.set_title(&title);
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(r) => {
                r.win.window.request_redraw();
                self.running = Some(r);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(r) = &self.running {
                    r.win.resize(size);
                }
            }
            WindowEvent::ModifiersChanged(m) => self.input.shift = m.state().shift_key(),
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                self.input.left_down = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y))) = (self.input.left_down, self.input.cursor) {
                    self.drag(position.x - x, position.y - y);
                }
                self.input.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 50.0,
                };
                if let umbra_gl::Projection::Orthographic { height, far } = self.config.params.camera.projection {
                    // Orthographic: moving the eye changes nothing seen; the wheel scales the
                    // view's height instead, by 10 % per step (kept finite and > 0).
                    let height = (height * 0.9f64.powf(steps)).clamp(1e-6 * self.diagonal, 1e6 * self.diagonal);
                    self.config.params.camera.projection = umbra_gl::Projection::Orthographic { height, far };
                } else {
                    self.rig.zoom(steps, 1e-3 * self.diagonal);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    self.key(event_loop, code, event.state == ElementState::Pressed, event.repeat);
                }
            }
            WindowEvent::RedrawRequested => match self.redraw() {
                Ok(true) => event_loop.exit(),
                Ok(false) => {}
                Err(e) => self.fail(event_loop, e),
            },
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(r) = &self.running {
            r.win.window.request_redraw();
        }
    }
}
