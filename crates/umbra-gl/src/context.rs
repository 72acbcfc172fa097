//! Headless OpenGL 4.5 core (or OpenGL ES 3) context through EGL loaded at run time.
//!
//! Platform order: Mesa's surfaceless platform (`EGL_PLATFORM_SURFACELESS_MESA`, 0x31DD) via
//! `eglGetPlatformDisplay` (EGL 1.5) or `eglGetPlatformDisplayEXT`, then the EGL device
//! platform (`EGL_EXT_platform_device`, 0x313F, first device of `eglQueryDevicesEXT`).
//! Plain `eglGetDisplay(EGL_DEFAULT_DISPLAY)` is never tried: on Mesa it looks for X11.
//! The context is made current without any surface (`EGL_KHR_surfaceless_context`); all
//! rendering goes to framebuffer objects ([`crate::RenderTarget`]).
//!
//! # Thread affinity
//! A [`HeadlessContext`] is made current on the thread that creates it and is `!Send`: it
//! lives and dies on that thread. Several threads may each own a context at the same time
//! (they share the process-wide EGL display, which is therefore never terminated; each
//! context is destroyed on drop). Creating a second context on the same thread makes the
//! new one current; [`HeadlessContext::make_current`] switches back.
//!
//! # A window system's context
//! For a context made by a window system library (glutin, SDL, ...): [`from_loader`] loads
//! glow and [`GlExtra`] through its `get_proc_address` (the one `unsafe` step: the context
//! must be current), and the safe helpers [`renderer_string`], [`blit_to_default_framebuffer`]
//! and [`ImageFramebuffer`] cover what a viewer does with GL besides umbra's renderer, so
//! that its own code needs no `unsafe` GL calls (umbra-view's `glue.rs`).

use std::ffi::c_void;
use std::marker::PhantomData;
use std::sync::OnceLock;

use glow::HasContext;
use khronos_egl as egl;

use crate::error::{drain_get_error, GlErrorLog};
use crate::extra::GlExtra;

type EglInstance = egl::DynamicInstance<egl::EGL1_4>;

const EGL_PLATFORM_SURFACELESS_MESA: u32 = 0x31DD;
const EGL_PLATFORM_DEVICE_EXT: u32 = 0x313F;
const EGL_CONTEXT_MAJOR_VERSION: egl::Int = 0x3098;
const EGL_CONTEXT_MINOR_VERSION: egl::Int = 0x30FB;
const EGL_CONTEXT_OPENGL_PROFILE_MASK: egl::Int = 0x30FD;
const EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT: egl::Int = 0x1;
const EGL_CONTEXT_FLAGS_KHR: egl::Int = 0x30FC;
const EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR: egl::Int = 0x1;
const EGL_OPENGL_ES3_BIT: egl::Int = 0x40;

const INSTALL_HINT: &str =
    "install the Debian packages libegl1 libegl-mesa0 libgl1-mesa-dri (Mesa's EGL and its llvmpipe software rasterizer)";

/// Which client API the context speaks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlApi {
    /// Desktop OpenGL 4.5, core profile (what the renderer needs).
    Gl45Core,
    /// OpenGL ES 3.0 or newer (for compiling shaders against ES 3).
    Gles3,
}

/// How to create a [`HeadlessContext`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContextOptions {
    /// Which client API and version to create (default [`GlApi::Gl45Core`]).
    pub api: GlApi,
    /// Create a KHR_debug context and record GL errors through a synchronous callback
    /// ([`HeadlessContext::take_gl_errors`]). Default: on in debug builds.
    pub debug: bool,
}

impl Default for ContextOptions {
    fn default() -> Self {
        Self { api: GlApi::Gl45Core, debug: cfg!(debug_assertions) }
    }
}

/// Why no headless context could be made. Every message says what is missing and how to get it.
#[derive(Debug, thiserror::Error)]
pub enum ContextError {
    #[error("libEGL.so.1 not found ({detail}): {INSTALL_HINT}")]
    /// libEGL could not be loaded.
    LibraryNotFound {
        /// The loader's message.
        detail: String,
    },
    #[error(
        "no usable headless EGL platform: {detail}. Mesa's surfaceless platform needs libegl-mesa0 \
             (EGL_MESA_platform_surfaceless); the device platform needs EGL_EXT_platform_device; {INSTALL_HINT}"
    )]
    /// Neither the surfaceless nor the device platform gave a display.
    NoPlatform {
        /// What each platform answered.
        detail: String,
    },
    #[error("eglInitialize failed on the {platform} platform: {detail}; {INSTALL_HINT}")]
    /// eglInitialize failed.
    Initialize {
        /// The EGL platform tried ("surfaceless" or "device").
        platform: &'static str,
        /// The EGL error.
        detail: String,
    },
    #[error("the EGL display ({platform}) lacks {extension}: {why}; a current Mesa (libegl-mesa0) offers it")]
    /// The display lacks an EGL extension the context needs.
    MissingExtension {
        /// The EGL platform of the display.
        platform: &'static str,
        /// The missing extension's name.
        extension: &'static str,
        /// What it is needed for.
        why: &'static str,
    },
    #[error(
        "eglBindAPI({api}) failed: {detail}; the EGL vendor library does not offer this client API ({INSTALL_HINT})"
    )]
    /// eglBindAPI failed for the wanted client API.
    BindApi {
        /// "OpenGL" or "OpenGL ES".
        api: &'static str,
        /// The EGL error.
        detail: String,
    },
    #[error("no EGL config with {wanted} and EGL_KHR_no_config_context is not offered; {INSTALL_HINT}")]
    /// No EGL config matches and config-less contexts are not offered.
    NoConfig {
        /// The attributes asked for.
        wanted: &'static str,
    },
    #[error(
        "could not create an {what} context: {detail}. Mesa's llvmpipe offers OpenGL 4.5 core and ES 3.2 \
             (libgl1-mesa-dri); a GPU driver without them can be bypassed with LIBGL_ALWAYS_SOFTWARE=1"
    )]
    /// eglCreateContext failed.
    CreateContext {
        /// The context asked for (e.g. "OpenGL 4.5 core").
        what: &'static str,
        /// The EGL error.
        detail: String,
    },
    #[error("eglMakeCurrent (surfaceless) failed: {detail}")]
    /// eglMakeCurrent failed.
    MakeCurrent {
        /// The EGL error.
        detail: String,
    },
    #[error("the created context reports version {version:?}, but {wanted} is required")]
    /// The context was created but reports a version below the one required.
    WrongVersion {
        /// GL_VERSION as reported.
        version: String,
        /// The version required.
        wanted: &'static str,
    },
}

/// The EGL library, loaded once per process (`RTLD_NODELETE`: it is never unloaded).
fn egl_instance() -> Result<&'static EglInstance, ContextError> {
    static INSTANCE: OnceLock<Result<EglInstance, String>> = OnceLock::new();
    let loaded = INSTANCE.get_or_init(|| {
        // SAFETY: loads the system's libEGL.so.1; khronos-egl checks that every EGL 1.4 entry
        // point is present. The library is the platform's own EGL implementation.
        unsafe { EglInstance::load_required() }.map_err(|e| e.to_string())
    });
    match loaded {
        Ok(instance) => Ok(instance),
        Err(detail) => Err(ContextError::LibraryNotFound { detail: detail.clone() }),
    }
}

/// The process-wide display (one per platform); initialised once, never terminated because
/// contexts on other threads may still use it.
struct SharedDisplay {
    display: egl::Display,
    platform: &'static str,
}
// SAFETY: an EGLDisplay handle is a process-wide opaque pointer; EGL guarantees its functions
// are thread-safe on a display (EGL 1.4 §2.4 "any thread may call EGL functions").
unsafe impl Send for SharedDisplay {}
// SAFETY: see `Send`; the handle is never mutated after initialisation.
unsafe impl Sync for SharedDisplay {}

fn shared_display(egl: &'static EglInstance) -> Result<&'static SharedDisplay, ContextError> {
    static DISPLAY: OnceLock<Result<SharedDisplay, String>> = OnceLock::new();
    // Errors are remembered as text so every later attempt reports the same reason.
    let result = DISPLAY.get_or_init(|| open_display(egl).map_err(|e| e.to_string()));
    match result {
        Ok(d) => Ok(d),
        Err(detail) => Err(ContextError::NoPlatform { detail: detail.clone() }),
    }
}

type GetPlatformDisplayExt = unsafe extern "system" fn(u32, *mut c_void, *const egl::Int) -> *mut c_void;
type QueryDevicesExt = unsafe extern "system" fn(egl::Int, *mut *mut c_void, *mut egl::Int) -> egl::Boolean;

fn client_extensions(egl: &EglInstance) -> String {
    egl.query_string(None, egl::EXTENSIONS).map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn has_extension(list: &str, name: &str) -> bool {
    list.split_ascii_whitespace().any(|e| e == name)
}

/// `eglGetPlatformDisplay` (EGL 1.5) or `eglGetPlatformDisplayEXT`.
fn platform_display(egl: &EglInstance, platform: u32, native: *mut c_void) -> Result<egl::Display, String> {
    if let Some(egl15) = egl.upcast::<egl::EGL1_5>() {
        // SAFETY: `native` is null (surfaceless: EGL_DEFAULT_DISPLAY) or an EGLDeviceEXT
        // handle from eglQueryDevicesEXT, which is what these two platforms require.
        return unsafe { egl15.get_platform_display(platform, native, &[egl::ATTRIB_NONE]) }
            .map_err(|e| format!("eglGetPlatformDisplay(0x{platform:04X}): {e}"));
    }
    let f = egl
        .get_proc_address("eglGetPlatformDisplayEXT")
        .ok_or("eglGetPlatformDisplayEXT missing (EGL_EXT_platform_base)")?;
    // SAFETY: eglGetPlatformDisplayEXT has exactly this signature (EGL_EXT_platform_base).
    let f: GetPlatformDisplayExt = unsafe { std::mem::transmute::<extern "system" fn(), GetPlatformDisplayExt>(f) };
    let attribs = [egl::NONE];
    // SAFETY: same argument contract as above; the attribute list is NONE-terminated.
    let ptr = unsafe { f(platform, native, attribs.as_ptr()) };
    if ptr.is_null() {
        Err(format!("eglGetPlatformDisplayEXT(0x{platform:04X}) returned EGL_NO_DISPLAY"))
    } else {
        // SAFETY: a non-null EGLDisplay returned by EGL.
        Ok(unsafe { egl::Display::from_ptr(ptr) })
    }
}

fn open_display(egl: &EglInstance) -> Result<SharedDisplay, ContextError> {
    let ext = client_extensions(egl);
    let mut tried = Vec::new();
    if has_extension(&ext, "EGL_MESA_platform_surfaceless") {
        match platform_display(egl, EGL_PLATFORM_SURFACELESS_MESA, std::ptr::null_mut()) {
            Ok(display) => match egl.initialize(display) {
                Ok(_) => return Ok(SharedDisplay { display, platform: "surfaceless (Mesa)" }),
                Err(e) => tried.push(format!("surfaceless: eglInitialize: {e}")),
            },
            Err(e) => tried.push(format!("surfaceless: {e}")),
        }
    } else {
        tried.push("EGL_MESA_platform_surfaceless not offered".into());
    }
    if has_extension(&ext, "EGL_EXT_platform_device") {
        match first_device(egl) {
            Ok(device) => match platform_display(egl, EGL_PLATFORM_DEVICE_EXT, device) {
                Ok(display) => match egl.initialize(display) {
                    Ok(_) => return Ok(SharedDisplay { display, platform: "device (EGL_EXT_platform_device)" }),
                    Err(e) => tried.push(format!("device: eglInitialize: {e}")),
                },
                Err(e) => tried.push(format!("device: {e}")),
            },
            Err(e) => tried.push(format!("device: {e}")),
        }
    } else {
        tried.push("EGL_EXT_platform_device not offered".into());
    }
    Err(ContextError::NoPlatform { detail: format!("{} (client extensions: {ext:?})", tried.join("; ")) })
}

fn first_device(egl: &EglInstance) -> Result<*mut c_void, String> {
    let f =
        egl.get_proc_address("eglQueryDevicesEXT").ok_or("eglQueryDevicesEXT missing (EGL_EXT_device_enumeration)")?;
    // SAFETY: eglQueryDevicesEXT has exactly this signature (EGL_EXT_device_enumeration).
    let f: QueryDevicesExt = unsafe { std::mem::transmute::<extern "system" fn(), QueryDevicesExt>(f) };
    let mut devices = [std::ptr::null_mut::<c_void>(); 8];
    let mut count: egl::Int = 0;
    // SAFETY: the output array holds 8 entries and we pass 8 as its size.
    let ok = unsafe { f(devices.len() as egl::Int, devices.as_mut_ptr(), &mut count) };
    if ok != egl::TRUE || count < 1 {
        return Err(format!("eglQueryDevicesEXT found no device (returned {ok}, count {count})"));
    }
    Ok(devices[0])
}

/// A current, surfaceless GL context owned by this thread.
pub struct HeadlessContext {
    egl: &'static EglInstance,
    display: egl::Display,
    context: egl::Context,
    gl: glow::Context,
    extra: GlExtra,
    errors: Option<GlErrorLog>,
    platform: &'static str,
    api: GlApi,
    /// `!Send + !Sync`: the context is current on the creating thread only.
    _thread_bound: PhantomData<*const ()>,
}

impl HeadlessContext {
    /// OpenGL 4.5 core, debug output in debug builds.
    pub fn new() -> Result<Self, ContextError> {
        Self::with_options(ContextOptions::default())
    }

    /// OpenGL ES 3.0 or newer (Mesa gives 3.2), debug output in debug builds.
    pub fn new_gles3() -> Result<Self, ContextError> {
        Self::with_options(ContextOptions { api: GlApi::Gles3, ..ContextOptions::default() })
    }

    /// A context with these options: the client API (GL 4.5 core or GLES 3) and whether
    /// GL errors are recorded through KHR_debug.
    pub fn with_options(options: ContextOptions) -> Result<Self, ContextError> {
        let egl = egl_instance()?;
        let shared = shared_display(egl)?;
        let display = shared.display;
        let platform = shared.platform;
        let display_ext = egl
            .query_string(Some(display), egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if !has_extension(&display_ext, "EGL_KHR_surfaceless_context") {
            return Err(ContextError::MissingExtension {
                platform,
                extension: "EGL_KHR_surfaceless_context",
                why: "the context is made current without any surface",
            });
        }
        if !has_extension(&display_ext, "EGL_KHR_create_context") {
            return Err(ContextError::MissingExtension {
                platform,
                extension: "EGL_KHR_create_context",
                why: "needed to ask for a specific version / core profile / debug flag",
            });
        }

        let (api_enum, api_name, renderable, what) = match options.api {
            GlApi::Gl45Core => (egl::OPENGL_API, "EGL_OPENGL_API", egl::OPENGL_BIT, "OpenGL 4.5 core"),
            GlApi::Gles3 => (egl::OPENGL_ES_API, "EGL_OPENGL_ES_API", EGL_OPENGL_ES3_BIT, "OpenGL ES 3.0"),
        };
        egl.bind_api(api_enum).map_err(|e| ContextError::BindApi { api: api_name, detail: e.to_string() })?;

        // A PBUFFER-capable RGBA8 config; the pbuffer itself is never created (surfaceless).
        let config_attribs = [
            egl::SURFACE_TYPE,
            egl::PBUFFER_BIT,
            egl::RENDERABLE_TYPE,
            renderable,
            egl::RED_SIZE,
            8,
            egl::GREEN_SIZE,
            8,
            egl::BLUE_SIZE,
            8,
            egl::ALPHA_SIZE,
            8,
            egl::NONE,
        ];
        let config = match egl.choose_first_config(display, &config_attribs) {
            Ok(Some(c)) => c,
            _ if has_extension(&display_ext, "EGL_KHR_no_config_context") => {
                // SAFETY: EGL_NO_CONFIG_KHR is the null EGLConfig, valid with EGL_KHR_no_config_context.
                unsafe { egl::Config::from_ptr(std::ptr::null_mut()) }
            }
            _ => {
                return Err(ContextError::NoConfig { wanted: "SURFACE_TYPE=PBUFFER and the requested RENDERABLE_TYPE" })
            }
        };

        let flags = if options.debug { EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR } else { 0 };
        let mut context_attribs = vec![];
        match options.api {
            GlApi::Gl45Core => context_attribs.extend_from_slice(&[
                EGL_CONTEXT_MAJOR_VERSION,
                4,
                EGL_CONTEXT_MINOR_VERSION,
                5, // 4.6 fails on this Mesa; 4.5 has everything used.
                EGL_CONTEXT_OPENGL_PROFILE_MASK,
                EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
            ]),
            GlApi::Gles3 => {
                context_attribs.extend_from_slice(&[EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0])
            }
        }
        context_attribs.extend_from_slice(&[EGL_CONTEXT_FLAGS_KHR, flags, egl::NONE]);
        let context = egl
            .create_context(display, config, None, &context_attribs)
            .map_err(|e| ContextError::CreateContext { what, detail: e.to_string() })?;
        if let Err(e) = egl.make_current(display, None, None, Some(context)) {
            // Ignoring the destroy result: we are already reporting the more useful error.
            let _ = egl.destroy_context(display, context);
            return Err(ContextError::MakeCurrent { detail: e.to_string() });
        }

        // SAFETY: the context was just made current on this thread; eglGetProcAddress returns
        // entry points valid for it (Mesa's are context-independent).
        let mut gl = unsafe {
            glow::Context::from_loader_function(|name| {
                egl.get_proc_address(name).map_or(std::ptr::null(), |f| f as *const c_void)
            })
        };
        let extra = GlExtra::load(|name| egl.get_proc_address(name).map_or(std::ptr::null(), |f| f as *const c_void));

        let version = gl.version().clone();
        let ok = match options.api {
            GlApi::Gl45Core => !version.is_embedded && (version.major, version.minor) >= (4, 5),
            GlApi::Gles3 => version.is_embedded && version.major >= 3,
        };
        if !ok {
            // SAFETY: context current on this thread.
            let text = unsafe { gl.get_parameter_string(glow::VERSION) };
            let _ = egl.make_current(display, None, None, None);
            let _ = egl.destroy_context(display, context);
            return Err(ContextError::WrongVersion { version: text, wanted: what });
        }

        let errors = if options.debug {
            let log = GlErrorLog::new();
            log.install(&mut gl);
            Some(log)
        } else {
            None
        };

        Ok(Self { egl, display, context, gl, extra, errors, platform, api: options.api, _thread_bound: PhantomData })
    }

    /// The glow context (current on this thread).
    pub fn gl(&self) -> &glow::Context {
        &self.gl
    }

    /// Mutable glow context (e.g. to install another debug callback).
    pub fn gl_mut(&mut self) -> &mut glow::Context {
        &mut self.gl
    }

    /// GL entry points glow 0.18 lacks (glClipControl, multi-draw indirect).
    pub fn extra(&self) -> &GlExtra {
        &self.extra
    }

    /// The debug-callback error list, if this is a debug context.
    pub fn error_log(&self) -> Option<&GlErrorLog> {
        self.errors.as_ref()
    }

    /// Every GL error recorded since the last call: debug-callback messages (debug contexts)
    /// followed by pending `glGetError` codes.
    pub fn take_gl_errors(&self) -> Vec<String> {
        let mut out = self.errors.as_ref().map(GlErrorLog::take).unwrap_or_default();
        out.extend(drain_get_error(&self.gl));
        out
    }

    /// `GL_RENDERER`, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    pub fn renderer_string(&self) -> String {
        // The context is current on this thread (it is !Send and made current at creation).
        renderer_string(&self.gl)
    }

    /// `GL_VERSION`.
    pub fn version_string(&self) -> String {
        // SAFETY: as in renderer_string.
        unsafe { self.gl.get_parameter_string(glow::VERSION) }
    }

    /// Which EGL platform the display came from.
    pub fn platform(&self) -> &'static str {
        self.platform
    }

    /// The client API of the context.
    pub fn api(&self) -> GlApi {
        self.api
    }

    /// Makes this context current again (after another context was created on this thread).
    pub fn make_current(&self) -> Result<(), ContextError> {
        self.egl
            .make_current(self.display, None, None, Some(self.context))
            .map_err(|e| ContextError::MakeCurrent { detail: e.to_string() })
    }
}

impl Drop for HeadlessContext {
    fn drop(&mut self) {
        // Release only if this context is the current one, so dropping an older context does
        // not unbind a newer one on the same thread. The display stays initialised (shared).
        if self.egl.get_current_context() == Some(self.context) {
            let _ = self.egl.make_current(self.display, None, None, None);
        }
        let _ = self.egl.destroy_context(self.display, self.context);
    }
}

// ---- GL for a context made by a window system (glutin, SDL, ...) ----------------------------
//
// umbra's rule is `unsafe` only in umbra-gl: a viewer that creates its context with a window
// system library uses these instead of raw glow calls of its own.

/// Loads glow and umbra's [`GlExtra`] for a context created elsewhere (a window system's),
/// through that system's `get_proc_address`. Entry points the loader does not know must be
/// returned as null.
///
/// # Safety
/// The context the loader belongs to must be current on this thread now and whenever the
/// returned `glow::Context` (or the [`GlExtra`]) is used, and `loader` must return that
/// context's entry points (a pointer for a name must be the function of that name). These are
/// the contract of `glow::Context::from_loader_function_cstr`; every umbra function that takes
/// a `&glow::Context` relies on them.
pub unsafe fn from_loader(mut loader: impl FnMut(&std::ffi::CStr) -> *const c_void) -> (glow::Context, GlExtra) {
    // SAFETY: the caller's contract (context current, loader of that context).
    let gl = unsafe { glow::Context::from_loader_function_cstr(&mut loader) };
    let extra = GlExtra::load(|name| match std::ffi::CString::new(name) {
        Ok(c) => loader(&c),
        Err(_) => std::ptr::null(),
    });
    (gl, extra)
}

/// `GL_RENDERER` of the current context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
pub fn renderer_string(gl: &glow::Context) -> String {
    // SAFETY: a plain query on the current context (the contract of every `&glow::Context`
    // umbra is given).
    unsafe { gl.get_parameter_string(glow::RENDERER) }
}

/// Copies colour attachment 0 of `from` (`width x height`, from the origin) to the default
/// framebuffer's back buffer at the same place, upside down when `flip` (for images stored
/// top row first). GL state it leaves: both framebuffer bindings at the default framebuffer
/// (0), SCISSOR_TEST disabled (a blit obeys the scissor box), and `from`'s read buffer
/// COLOR_ATTACHMENT0 (framebuffer-object state).
pub fn blit_to_default_framebuffer(gl: &glow::Context, from: glow::Framebuffer, width: u32, height: u32, flip: bool) {
    let (w, h) = (width as i32, height as i32);
    let (y0, y1) = if flip { (h, 0) } else { (0, h) };
    // SAFETY: binds and a blit between existing framebuffers of the current context.
    unsafe {
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(from));
        // Reason: the image is in colour attachment 0 (framebuffer-object state).
        gl.read_buffer(glow::COLOR_ATTACHMENT0);
        gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
        // Reason: a blit obeys the scissor test; the whole rectangle must be copied.
        gl.disable(glow::SCISSOR_TEST);
        gl.blit_framebuffer(0, 0, w, h, 0, y0, w, y1, glow::COLOR_BUFFER_BIT, glow::NEAREST);
        // Reason: leave the window bound for reads (screenshots) and for the next frame.
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
    }
}

/// An RGBA8 texture with a framebuffer around it: a CPU image put on the GPU so that it can
/// be shown with [`blit_to_default_framebuffer`] (e.g. a viewer's shadow-mask view). Delete
/// with [`ImageFramebuffer::destroy`].
pub struct ImageFramebuffer {
    texture: glow::Texture,
    framebuffer: glow::Framebuffer,
    width: u32,
    height: u32,
}

impl ImageFramebuffer {
    /// A `width x height` image, contents undefined until [`ImageFramebuffer::upload`].
    /// Uses direct state access: no binding changes.
    pub fn new(gl: &glow::Context, width: u32, height: u32) -> Result<Self, crate::GlError> {
        let create = |what: &'static str| move |detail: String| crate::GlError::Create { what, detail };
        // SAFETY: DSA object creation on the current context; no bindings change.
        unsafe {
            let texture = gl.create_named_texture(glow::TEXTURE_2D).map_err(create("texture"))?;
            gl.texture_storage_2d(texture, 1, glow::RGBA8, width as i32, height as i32);
            let framebuffer = match gl.create_named_framebuffer() {
                Ok(f) => f,
                Err(e) => {
                    gl.delete_texture(texture);
                    return Err(create("framebuffer")(e));
                }
            };
            gl.named_framebuffer_texture(Some(framebuffer), glow::COLOR_ATTACHMENT0, Some(texture), 0);
            Ok(Self { texture, framebuffer, width, height })
        }
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The framebuffer (colour attachment 0 = the image, bottom row first as GL stores it).
    pub fn framebuffer(&self) -> glow::Framebuffer {
        self.framebuffer
    }

    /// Uploads `image` (top row first; stored as given, so row 0 lands at the texture's
    /// bottom: blit with `flip`). Err unless its size is the image framebuffer's. GL state:
    /// UNPACK_ALIGNMENT is set to 1 and restored; the PIXEL_UNPACK_BUFFER binding is left
    /// unbound (client memory upload).
    pub fn upload(&self, gl: &glow::Context, image: &crate::RgbaImage) -> Result<(), crate::GlError> {
        if (image.width, image.height) != (self.width, self.height) {
            return Err(crate::GlError::InvalidParams(format!(
                "image {}x{} uploaded into an image framebuffer of {}x{}",
                image.width, image.height, self.width, self.height
            )));
        }
        let bytes: Vec<u8> = image.pixels.iter().flatten().copied().collect();
        // SAFETY: the texture holds width x height RGBA8 texels, exactly `bytes` with unpack
        // alignment 1 from client memory.
        unsafe {
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
        Ok(())
    }

    /// Deletes the texture and framebuffer.
    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_framebuffer(self.framebuffer);
            gl.delete_texture(self.texture);
        }
    }
}
