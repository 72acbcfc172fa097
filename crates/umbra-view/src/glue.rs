//! Window-system glue: a winit window with an OpenGL 4.5 core context and window surface
//! from glutin (its display tries EGL, then GLX, on X11; EGL on Wayland), `glow` and umbra's
//! [`GlExtra`] loaded through that display, and the two raw GL operations the viewer does
//! itself: copying a finished frame to the window (glBlitFramebuffer) and showing an image
//! (the shadow-mask view) through a texture.
//!
//! `unsafe` here is only what glutin's API makes unsafe by contract, each call site marked
//! `#[allow(unsafe_code)]` under the crate's `#![deny(unsafe_code)]`:
//! * `create_context` and `create_window_surface` take a raw window handle, which glutin
//!   cannot check: the window must outlive the context and surface (it does: [`GlWindow`]'s
//!   field order drops them first);
//! * loading GL for that context ([`umbra_gl::context::from_loader`]): the loader must be the
//!   current context's, which glutin's display gives only while the context is current.
//!
//! Every GL call the viewer makes itself goes through umbra-gl's safe helpers
//! ([`umbra_gl::context::renderer_string`], [`umbra_gl::context::blit_to_default_framebuffer`],
//! [`umbra_gl::context::ImageFramebuffer`]), so the GL layer keeps all raw GL `unsafe` (the
//! project's rule).

use std::num::NonZeroU32;

use glutin::config::{Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext, Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, SwapInterval, WindowSurface};
use glutin_winit::{DisplayBuilder, GlWindow as _};
use umbra_gl::context::{blit_to_default_framebuffer, from_loader, renderer_string, ImageFramebuffer};
use umbra_gl::glow;
use umbra_gl::{GlExtra, RgbaImage};
use winit::dpi::PhysicalSize;
use winit::event_loop::ActiveEventLoop;
use winit::raw_window_handle::HasWindowHandle;
use winit::window::Window;

use crate::ViewError;

/// A window, its current GL context and surface, and GL loaded for it.
pub struct GlWindow {
    // Field order = drop order: GL objects are deleted by their owners before this drops;
    // the surface and context go before the window they were made for.
    pub gl: glow::Context,
    pub extra: GlExtra,
    pub surface: Surface<WindowSurface>,
    pub context: PossiblyCurrentContext,
    pub window: Window,
}

fn window_err(what: &str, e: impl std::fmt::Display) -> ViewError {
    ViewError::Window(format!("{what}: {e}"))
}

/// The first single-sampled configuration (a multisampled window cannot receive the blit
/// of the single-sampled frame), else the first one.
fn pick_config(configs: Box<dyn Iterator<Item = Config> + '_>) -> Config {
    let all: Vec<Config> = configs.collect();
    let single = all.iter().position(|c| c.num_samples() == 0).unwrap_or(0);
    all.into_iter().nth(single).expect("glutin returns at least one config")
}

/// Creates the window (inner size `width x height`) with a GL 4.5 core context, current.
/// `vsync` off for scripted runs (frames as fast as they draw).
pub fn create(
    event_loop: &ActiveEventLoop,
    title: &str,
    width: u32,
    height: u32,
    vsync: bool,
) -> Result<GlWindow, ViewError> {
    let attributes = Window::default_attributes().with_title(title).with_inner_size(PhysicalSize::new(width, height));
    let template = ConfigTemplateBuilder::new();
    let (window, config) = DisplayBuilder::new()
        .with_window_attributes(Some(attributes))
        .build(event_loop, template, pick_config)
        .map_err(|e| window_err("no GL configuration for a window on this display", e))?;
    let window = window.ok_or_else(|| ViewError::Window("the window was not created".into()))?;
    let handle = window.window_handle().map_err(|e| window_err("window handle", e))?.as_raw();
    let display = config.display();
    let context_attributes = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
        .with_profile(GlProfile::Core)
        .build(Some(handle));
    // SAFETY: the handle belongs to `window`, which outlives the context (GlWindow's field
    // order drops the context first).
    #[allow(unsafe_code)]
    let not_current = unsafe { display.create_context(&config, &context_attributes) }
        .map_err(|e| window_err("no OpenGL 4.5 core context (umbra needs GL 4.5; Mesa's llvmpipe provides it)", e))?;
    let surface_attributes =
        window.build_surface_attributes(Default::default()).map_err(|e| window_err("window surface attributes", e))?;
    // SAFETY: as above, the surface is dropped before the window.
    #[allow(unsafe_code)]
    let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
        .map_err(|e| window_err("window surface", e))?;
    let context = not_current.make_current(&surface).map_err(|e| window_err("make the context current", e))?;
    let interval = if vsync { SwapInterval::Wait(NonZeroU32::MIN) } else { SwapInterval::DontWait };
    // Not every platform lets the interval be chosen; the default is fine then.
    let _ = surface.set_swap_interval(&context, interval);
    // SAFETY: the context was just made current on this thread and stays current for the
    // GlWindow's life (the viewer makes no other context current); the display's
    // get_proc_address returns that context's entry points.
    #[allow(unsafe_code)]
    let (gl, extra) = unsafe { from_loader(|name| display.get_proc_address(name)) };
    Ok(GlWindow { gl, extra, surface, context, window })
}

impl GlWindow {
    /// Resizes the surface to the window's inner size (no-op while it is zero).
    pub fn resize(&self, size: PhysicalSize<u32>) {
        if let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) {
            self.surface.resize(&self.context, w, h);
        }
    }

    pub fn swap(&self) -> Result<(), ViewError> {
        self.surface.swap_buffers(&self.context).map_err(|e| window_err("swap buffers", e))
    }

    /// The GL_RENDERER string.
    pub fn renderer_string(&self) -> String {
        renderer_string(&self.gl)
    }

    /// Copies colour attachment 0 of `from` (`width x height`) to the window's back buffer,
    /// `flip` = upside down (for images stored top row first). Leaves both framebuffer
    /// bindings at the window (0).
    pub fn blit_to_window(&self, from: glow::Framebuffer, width: u32, height: u32, flip: bool) {
        // Reason (inside): the frame is in colour attachment 0; the scissor test is disabled
        // for the blit (umbra's renderer restores GL's default, off, after each frame anyway).
        blit_to_default_framebuffer(&self.gl, from, width, height, flip);
    }
}

/// A texture + framebuffer pair that shows a CPU image in the window (the mask view).
pub struct ImageView {
    image: ImageFramebuffer,
}

impl ImageView {
    /// A `width x height` view.
    pub fn new(gl: &glow::Context, width: u32, height: u32) -> Result<Self, ViewError> {
        let image = ImageFramebuffer::new(gl, width, height).map_err(|e| window_err("mask image", e))?;
        Ok(Self { image })
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        self.image.size()
    }

    /// Uploads `image` (its size must be the view's, else nothing is shown) and copies it to
    /// the window.
    pub fn show(&self, win: &GlWindow, image: &RgbaImage) {
        if self.image.upload(&win.gl, image).is_err() {
            return;
        }
        let (w, h) = self.image.size();
        // Top row first in memory = bottom row of the texture: flip while copying.
        win.blit_to_window(self.image.framebuffer(), w, h, true);
    }

    /// Deletes the GL objects.
    pub fn destroy(self, gl: &glow::Context) {
        self.image.destroy(gl);
    }
}
