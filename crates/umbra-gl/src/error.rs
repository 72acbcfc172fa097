//! Typed errors of the GL layer, and the shared list the KHR_debug callback records into.

use std::sync::{Arc, Mutex};

/// Anything that went wrong while talking to GL (context creation has its own
/// [`crate::ContextError`]).
#[derive(Debug, thiserror::Error)]
pub enum GlError {
    /// A shader did not compile; `name` is the `.glsl` file it came from.
    #[error("GLSL compile error in {name} ({stage}):\n{log}")]
    Compile {
        /// The shader's file name.
        name: String,
        /// "vertex", "fragment", ...
        stage: &'static str,
        /// The compiler's info log.
        log: String,
    },
    /// A program did not link.
    #[error("GLSL link error in program {name}:\n{log}")]
    Link {
        /// The program's name.
        name: String,
        /// The linker's info log.
        log: String,
    },
    /// The GL reported errors (KHR_debug messages of type ERROR / severity HIGH, or
    /// `glGetError` codes) during or before the operation.
    #[error("GL reported {} error(s) during {during}: {}", messages.len(), messages.join("; "))]
    Gl {
        /// The operation during which they were recorded ("frame", "readback", ...).
        during: &'static str,
        /// One line per recorded error.
        messages: Vec<String>,
    },
    /// `glCheckFramebufferStatus` was not COMPLETE.
    #[error("framebuffer incomplete: status 0x{status:04X} ({what})")]
    Framebuffer {
        /// The status glCheckFramebufferStatus returned.
        status: u32,
        /// Which framebuffer.
        what: &'static str,
    },
    /// The driver refused to allocate storage (`GL_OUT_OF_MEMORY`): `what` names the buffer
    /// or texture, `bytes` its size. Nothing of the failed allocation is left behind and the
    /// context stays usable (`tests/gl_failures.rs`).
    #[error("out of GPU memory allocating {what} ({bytes} bytes): {}", messages.join("; "))]
    OutOfMemory {
        /// The buffer or texture being allocated.
        what: String,
        /// Its size in bytes.
        bytes: usize,
        /// The GL error messages recorded.
        messages: Vec<String>,
    },
    /// Creating a GL object failed (glow returns a String).
    #[error("could not create GL {what}: {detail}")]
    Create {
        /// The kind of object ("buffer", "program", ...).
        what: &'static str,
        /// glow's message.
        detail: String,
    },
    /// Parameters the renderer cannot use (zero size, light index out of range, ...).
    #[error("invalid parameters: {0}")]
    InvalidParams(String),
    /// A shadow method needs something the context does not offer.
    #[error("shadow method {method} is unsupported here: {reason}")]
    Unsupported {
        /// The method's registry name.
        method: &'static str,
        /// What is missing.
        reason: String,
    },
    /// Writing a PNG failed.
    #[error("could not write PNG {path}: {detail}")]
    Png {
        /// The file written.
        path: String,
        /// The I/O or encoder error.
        detail: String,
    },
}

impl From<umbra_geom::image::PngError> for GlError {
    fn from(e: umbra_geom::image::PngError) -> Self {
        GlError::Png { path: e.path, detail: e.detail }
    }
}

impl From<umbra_geom::InvalidFrame> for GlError {
    /// A frame no backend can draw is an invalid parameter.
    fn from(e: umbra_geom::InvalidFrame) -> Self {
        GlError::InvalidParams(e.0)
    }
}

impl From<crate::camera::CameraError> for GlError {
    /// A camera that defines no view is an invalid parameter of the frame.
    fn from(e: crate::camera::CameraError) -> Self {
        GlError::InvalidParams(e.0)
    }
}

/// Shared, thread-safe list of GL error messages, filled by the synchronous KHR_debug
/// callback that [`GlErrorLog::install`] sets up, drained with [`GlErrorLog::take`].
///
/// A clone shares the same list.
#[derive(Clone, Debug, Default)]
pub struct GlErrorLog(Arc<Mutex<Vec<String>>>);

impl GlErrorLog {
    /// An empty list.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends one message.
    pub fn push(&self, message: String) {
        // A poisoned lock only means another thread panicked while pushing; the Vec is intact.
        let mut list = self.0.lock().unwrap_or_else(|e| e.into_inner());
        list.push(message);
    }

    /// Removes and returns everything recorded so far.
    pub fn take(&self) -> Vec<String> {
        let mut list = self.0.lock().unwrap_or_else(|e| e.into_inner());
        std::mem::take(&mut *list)
    }

    /// Installs a synchronous KHR_debug callback on the *current* context that records
    /// every message of type `DEBUG_TYPE_ERROR` or severity `DEBUG_SEVERITY_HIGH` into this
    /// list. Works on any GL 4.3+ / KHR_debug context; messages only arrive in full if the
    /// context was created with the debug flag (Mesa reports API errors either way).
    ///
    /// GL state touched: enables `DEBUG_OUTPUT` and `DEBUG_OUTPUT_SYNCHRONOUS` (left enabled:
    /// synchronous delivery is what ties a message to the call that caused it).
    pub fn install(&self, gl: &mut glow::Context) {
        use glow::HasContext;
        let log = self.clone();
        // SAFETY: the caller's context is current on this thread (glow requires it for every
        // call); the callback closure is 'static + Send + Sync and only locks a Mutex.
        unsafe {
            gl.enable(glow::DEBUG_OUTPUT);
            // Reason: synchronous delivery runs the callback inside the offending GL call, so
            // the message belongs to this thread's context and is recorded before the frame
            // function checks the list.
            gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
            gl.debug_message_callback(move |source, ty, id, severity, message| {
                if ty == glow::DEBUG_TYPE_ERROR || severity == glow::DEBUG_SEVERITY_HIGH {
                    log.push(format!(
                        "{} (source 0x{source:04X}, type 0x{ty:04X}, id {id}, severity 0x{severity:04X})",
                        message.trim_end()
                    ));
                }
            });
        }
    }
}

/// Drains `glGetError` (at most 16 codes, the GL may keep one per error class) into names.
pub fn drain_get_error(gl: &glow::Context) -> Vec<String> {
    use glow::HasContext;
    let mut out = Vec::new();
    for _ in 0..16 {
        // SAFETY: glGetError has no preconditions beyond a current context.
        let code = unsafe { gl.get_error() };
        if code == glow::NO_ERROR {
            break;
        }
        let name = match code {
            glow::INVALID_ENUM => "GL_INVALID_ENUM",
            glow::INVALID_VALUE => "GL_INVALID_VALUE",
            glow::INVALID_OPERATION => "GL_INVALID_OPERATION",
            glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION",
            glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY",
            glow::STACK_OVERFLOW => "GL_STACK_OVERFLOW",
            glow::STACK_UNDERFLOW => "GL_STACK_UNDERFLOW",
            _ => "unknown GL error",
        };
        out.push(format!("glGetError: {name} (0x{code:04X})"));
    }
    out
}
