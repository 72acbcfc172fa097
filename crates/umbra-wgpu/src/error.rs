//! Typed errors of the wgpu backend. Nothing in this crate panics on bad input or a missing
//! adapter: every failure is one of these, with what to do about it.

/// Anything that went wrong in umbra-wgpu.
#[derive(Debug, thiserror::Error)]
pub enum WgpuError {
    /// No adapter of the backends asked for. On a machine without a GPU, Vulkan runs on Mesa's
    /// lavapipe: install it (`install` says how).
    #[error("no {backends} adapter found ({detail}); {install}")]
    NoAdapter {
        /// The backends that were asked, e.g. "Vulkan/Metal/DX12".
        backends: String,
        /// wgpu's answer.
        detail: String,
        /// What to install on this platform.
        install: &'static str,
    },
    /// The adapter lacks features umbra-wgpu needs.
    #[error("adapter {adapter:?} lacks {missing}: {why}")]
    MissingFeatures {
        /// The adapter's name.
        adapter: String,
        /// The missing features (wgpu's names).
        missing: String,
        /// What needs them.
        why: &'static str,
    },
    /// The device could not be created.
    #[error("could not create a wgpu device on {adapter:?}: {detail}")]
    RequestDevice {
        /// The adapter's name.
        adapter: String,
        /// wgpu's message.
        detail: String,
    },
    /// Parameters umbra cannot use (zero size, bad light, a scene too large for a buffer, ...).
    #[error("invalid parameters: {0}")]
    InvalidParams(String),
    /// A frame parameter this backend cannot honour: the f32 counter, the standard depth
    /// convention (umbra-wgpu draws reversed-Z with the 8-bit stencil counter). Refused before
    /// any GPU work, never drawn differently.
    #[error("the wgpu backend does not support {what} {value} (it supports {supported} only); use umbra-gl for it")]
    Unsupported {
        /// The parameter ("counter", "depth convention").
        what: &'static str,
        /// The value asked for.
        value: String,
        /// The one value this backend draws.
        supported: &'static str,
    },
    /// A method name the wgpu backend does not know.
    #[error("unknown shadow method {name:?} on the wgpu backend; known: {known}")]
    UnknownMethod {
        /// The name asked for.
        name: String,
        /// The wgpu backend's methods.
        known: String,
    },
    /// wgpu reported a validation or out-of-memory error during `during`.
    #[error("wgpu reported an error during {during}: {message}")]
    Wgpu {
        /// The operation ("frame", "upload", ...).
        during: &'static str,
        /// wgpu's message.
        message: String,
    },
    /// Reading a buffer back failed (the device was lost, or mapping failed).
    #[error("readback of {what} failed: {detail}")]
    Readback {
        /// What was read back.
        what: &'static str,
        /// wgpu's message.
        detail: String,
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

impl From<umbra_geom::camera::CameraError> for WgpuError {
    fn from(e: umbra_geom::camera::CameraError) -> Self {
        WgpuError::InvalidParams(e.0)
    }
}

impl From<umbra_geom::image::PngError> for WgpuError {
    fn from(e: umbra_geom::image::PngError) -> Self {
        WgpuError::Png { path: e.path, detail: e.detail }
    }
}

impl From<umbra_geom::InvalidFrame> for WgpuError {
    fn from(e: umbra_geom::InvalidFrame) -> Self {
        WgpuError::InvalidParams(e.0)
    }
}

impl From<umbra_geom::InvalidLight> for WgpuError {
    fn from(e: umbra_geom::InvalidLight) -> Self {
        WgpuError::InvalidParams(e.0)
    }
}

/// Runs `f` inside a validation and an out-of-memory error scope on `device` and turns what
/// they caught into [`WgpuError::Wgpu`]. wgpu reports such errors asynchronously; the scopes
/// catch those of every call `f` makes on this thread.
pub(crate) fn scoped<T>(
    device: &wgpu::Device,
    during: &'static str,
    f: impl FnOnce() -> Result<T, WgpuError>,
) -> Result<T, WgpuError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = f();
    let validation = pollster::block_on(validation.pop());
    let oom = pollster::block_on(oom.pop());
    let error = validation.or(oom);
    match (result, error) {
        (Err(e), _) => Err(e),
        (Ok(_), Some(e)) => Err(WgpuError::Wgpu { during, message: e.to_string() }),
        (Ok(v), None) => Ok(v),
    }
}
