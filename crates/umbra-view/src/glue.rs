//! Window-system glue: a winit window with an OpenGL 4.5 core context and window surface
//! from glutin (its display tries EGL, then GLX, on X11; EGL on Wayland), `glow` and umbra's
//! [`GlExtra`] loaded through that display, and the two raw GL operations the viewer does
//! itself: copying a finished frame to the window (glBlitFramebuffer) and showing an image
//! (the shadow-mask view) through a texture.
//!
//! This is the one file of umbra-view with `unsafe`: creating a GL context and surface for a
//! native window, loading GL entry points, and raw GL calls are unsafe in glutin and glow.

use std::ffi::CString;
use std::num::NonZeroU32;

use glutin::config::{Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext, Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, SwapInterval, WindowSurface};
use glutin_winit::{DisplayBuilder, GlWindow as _};
use umbra_gl::glow::{self, HasContext};
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
    let not_current = unsafe { display.create_context(&config, &context_attributes) }
        .map_err(|e| window_err("no OpenGL 4.5 core context (umbra needs GL 4.5; Mesa's llvmpipe provides it)", e))?;
    let surface_attributes =
        window.build_surface_attributes(Default::default()).map_err(|e| window_err("window surface attributes", e))?;
    // SAFETY: as above, the surface is dropped before the window.
    let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
        .map_err(|e| window_err("window surface", e))?;
    let context = not_current.make_current(&surface).map_err(|e| window_err("make the context current", e))?;
    let interval = if vsync { SwapInterval::Wait(NonZeroU32::MIN) } else { SwapInterval::DontWait };
    // Not every platform lets the interval be chosen; the default is fine then.
    let _ = surface.set_swap_interval(&context, interval);
    // SAFETY: the context is current on this thread; the loader returns its entry points.
    let gl = unsafe { glow::Context::from_loader_function_cstr(|name| display.get_proc_address(name)) };
    let extra = GlExtra::load(|name| match CString::new(name) {
        Ok(c) => display.get_proc_address(&c),
        Err(_) => std::ptr::null(),
    });
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
        // SAFETY: a plain query on the current context.
        unsafe { self.gl.get_parameter_string(glow::RENDERER) }
    }

    /// Copies colour attachment 0 of `from` (`width x height`) to the window's back buffer,
    /// `flip` = upside down (for images stored top row first). Leaves both framebuffer
    /// bindings at the window (0).
    pub fn blit_to_window(&self, from: glow::Framebuffer, width: u32, height: u32, flip: bool) {
        let (w, h) = (width as i32, height as i32);
        let (y0, y1) = if flip { (h, 0) } else { (0, h) };
        // SAFETY: binds and a blit between existing framebuffers of the current context.
        unsafe {
            let gl = &self.gl;
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(from));
            // Reason: the frame is in colour attachment 0 (framebuffer-object state).
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
            // Reason: a blit obeys the scissor test (off in GL's default state, which
            // umbra's renderer restores after each frame; made sure here).
            gl.disable(glow::SCISSOR_TEST);
            gl.blit_framebuffer(0, 0, w, h, 0, y0, w, y1, glow::COLOR_BUFFER_BIT, glow::NEAREST);
            // Reason: leave the window bound for reads (screenshot) and for the next frame.
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
    }
}

/// A texture + framebuffer pair that shows a CPU image in the window (the mask view).
pub struct ImageView {
    texture: glow::Texture,
    framebuffer: glow::Framebuffer,
    width: u32,
    height: u32,
}

impl ImageView {
    pub fn new(gl: &glow::Context, width: u32, height: u32) -> Result<Self, ViewError> {
        // SAFETY: DSA creation on the current context; no bindings change.
        unsafe {
            let texture = gl.create_named_texture(glow::TEXTURE_2D).map_err(|e| window_err("mask texture", e))?;
            gl.texture_storage_2d(texture, 1, glow::RGBA8, width as i32, height as i32);
            let framebuffer = gl.create_named_framebuffer().map_err(|e| window_err("mask framebuffer", e))?;
            gl.named_framebuffer_texture(Some(framebuffer), glow::COLOR_ATTACHMENT0, Some(texture), 0);
            Ok(Self { texture, framebuffer, width, height })
        }
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Uploads `image` (its size must be the view's) and copies it to the window.
    pub fn show(&self, win: &GlWindow, image: &RgbaImage) {
        if (image.width, image.height) != (self.width, self.height) {
            return;
        }
        let bytes: Vec<u8> = image.pixels.iter().flatten().copied().collect();
        // SAFETY: the texture holds width x height RGBA8 texels, exactly `bytes`; unpack state
        // set for tightly packed client memory (and restored).
        unsafe {
            let gl = &win.gl;
            let align = gl.get_parameter_i32(glow::UNPACK_ALIGNMENT);
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
            gl.texture_sub_image_2d(
                self.texture,
                0,
                0,
                0,
                self.width as i32,
                self.height as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelUnpackData::Slice(Some(&bytes)),
            );
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, align);
        }
        // Top row first in memory = bottom row of the texture: flip while copying.
        win.blit_to_window(self.framebuffer, self.width, self.height, true);
    }

    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_framebuffer(self.framebuffer);
            gl.delete_texture(self.texture);
        }
    }
}
