//! A headless wgpu device for umbra's own frames (the CLI, the tests, the headless example).
//!
//! Backends: Vulkan, Metal and DX12 (whichever the platform has; `WGPU_BACKEND` overrides, as
//! everywhere in wgpu). On a machine without a GPU, Vulkan runs on Mesa's lavapipe (Debian:
//! `apt-get install mesa-vulkan-drivers libvulkan1`). No adapter is a
//! [`WgpuError::NoAdapter`] that says what to install, never a panic.
//!
//! Features requested (all of them on lavapipe, and on every desktop GPU wgpu 30 supports):
//! * [`wgpu::Features::DEPTH_CLIP_CONTROL`] (required): `unclipped_depth`, depth clamping
//!   instead of near/far clipping, for the shadow volumes (vertices at infinity land exactly on
//!   the far plane, rounding must not clip them);
//! * [`wgpu::Features::CLIP_DISTANCES`] (required): the near-plane clip of light caps and the
//!   scene-box clip of z-pass volumes;
//! * [`wgpu::Features::PRIMITIVE_INDEX`] (required for umbra's own frames): the triangle id per
//!   sample and the flat normal the lighting pass reads;
//! * [`wgpu::Features::DEPTH32FLOAT_STENCIL8`] (optional): reversed-Z with a float depth
//!   buffer; without it the frame uses `Depth24PlusStencil8` (less depth precision far away);
//! * [`wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS`] (optional): per-stage frame times
//!   ([`crate::Renderer::draw_frame_timed`]);
//! * [`wgpu::Features::SHADER_EARLY_DEPTH_TEST`] (optional, Vulkan and GLES): the receiver
//!   map's scatter tests the depth before its fragment shader, so hidden fragments cost no
//!   shading (without it every fragment of the scene runs the shader's own depth test);
//! * [`wgpu::Features::PIPELINE_STATISTICS_QUERY`] (optional): the fragments the volume passes
//!   rasterize ([`crate::Renderer::set_count_volume_fragments`], `bench`'s `volume_fragments`).
//!
//! Limits: the adapter's own (the largest scenes need large storage buffers).

use crate::error::WgpuError;

/// What to install when no adapter is found, per platform.
pub const INSTALL_HINT: &str = if cfg!(target_os = "macos") {
    "Metal needs macOS 10.13 or later on a Metal-capable Mac"
} else if cfg!(target_os = "windows") {
    "install a GPU driver with Vulkan or DX12, or run on a machine that has one"
} else {
    "install a Vulkan driver; without a GPU, Mesa's lavapipe: `apt-get install mesa-vulkan-drivers libvulkan1` (Debian/Ubuntu) or `dnf install mesa-vulkan-drivers vulkan-loader` (Fedora)"
};

/// The backends umbra-wgpu asks for: Vulkan, Metal, DX12 (wgpu's GL backend has no stencil
/// copies; umbra-gl is umbra's OpenGL path).
pub fn backends() -> wgpu::Backends {
    wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12
}

/// Features without which no shadow volume can be drawn.
pub fn volume_features() -> wgpu::Features {
    wgpu::Features::DEPTH_CLIP_CONTROL | wgpu::Features::CLIP_DISTANCES
}

/// Features umbra's own frames ([`crate::Renderer`]) need on top of [`volume_features`].
pub fn frame_features() -> wgpu::Features {
    volume_features() | wgpu::Features::PRIMITIVE_INDEX
}

/// `required` is a subset of `available`, else [`WgpuError::MissingFeatures`].
pub fn check_features(
    adapter: &str,
    available: wgpu::Features,
    required: wgpu::Features,
    why: &'static str,
) -> Result<(), WgpuError> {
    let missing = required - available;
    if missing.is_empty() {
        Ok(())
    } else {
        Err(WgpuError::MissingFeatures { adapter: adapter.to_string(), missing: format!("{missing:?}"), why })
    }
}

/// An instance, adapter, device and queue, without a window.
pub struct HeadlessGpu {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter the device was made on.
    pub adapter: wgpu::Adapter,
    /// The device (features of [`frame_features`], plus `DEPTH32FLOAT_STENCIL8` when offered).
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

impl HeadlessGpu {
    /// The first adapter of [`backends`] (high-performance preference), and a device on it
    /// with [`frame_features`].
    pub fn new() -> Result<Self, WgpuError> {
        let descriptor =
            wgpu::InstanceDescriptor { backends: backends(), ..wgpu::InstanceDescriptor::new_without_display_handle() };
        Self::with_instance(descriptor.with_env())
    }

    /// As [`HeadlessGpu::new`] with exactly `backends` (no environment override).
    pub fn with_backends(backends: wgpu::Backends) -> Result<Self, WgpuError> {
        Self::with_instance(wgpu::InstanceDescriptor {
            backends,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        })
    }

    fn with_instance(descriptor: wgpu::InstanceDescriptor) -> Result<Self, WgpuError> {
        let named: Vec<&str> = descriptor.backends.iter_names().map(|(name, _)| name).collect();
        let named = if named.is_empty() { "no".to_string() } else { named.join("/") };
        let instance = wgpu::Instance::new(descriptor);
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        };
        let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| WgpuError::NoAdapter {
            backends: named,
            detail: e.to_string(),
            install: INSTALL_HINT,
        })?;
        let (device, queue) = request_device(&adapter, frame_features())?;
        Ok(Self { instance, adapter, device, queue })
    }

    /// One line about the adapter: name, backend, type, driver.
    pub fn adapter_line(&self) -> String {
        adapter_line(&self.adapter)
    }
}

/// A device on `adapter` with `required` plus `DEPTH32FLOAT_STENCIL8`, the timestamp
/// queries, `SHADER_EARLY_DEPTH_TEST` and `PIPELINE_STATISTICS_QUERY` when offered, and the
/// adapter's limits. Uncaptured errors are printed, never a panic (umbra's own calls run
/// inside error scopes and report theirs as [`WgpuError::Wgpu`]).
pub fn request_device(
    adapter: &wgpu::Adapter,
    required: wgpu::Features,
) -> Result<(wgpu::Device, wgpu::Queue), WgpuError> {
    let info = adapter.get_info();
    let available = adapter.features();
    check_features(&info.name, available, required, "umbra-wgpu's shadow volumes and frames")?;
    // Optional: float depth with stencil; timestamps inside encoders (bench's stage times);
    // early depth tests for the receiver map's scatter; pipeline statistics (bench's
    // `volume_fragments`).
    let optional = available
        & (wgpu::Features::DEPTH32FLOAT_STENCIL8
            | wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
            | wgpu::Features::SHADER_EARLY_DEPTH_TEST
            | wgpu::Features::PIPELINE_STATISTICS_QUERY);
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("umbra-wgpu"),
        required_features: required | optional,
        required_limits: adapter.limits(),
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
        .map_err(|e| WgpuError::RequestDevice { adapter: info.name.clone(), detail: e.to_string() })?;
    device.on_uncaptured_error(std::sync::Arc::new(|e: wgpu::Error| {
        eprintln!("umbra-wgpu: uncaptured wgpu error: {e}");
    }));
    Ok((device, queue))
}

/// `name (backend, device type, driver driver_info)`.
pub fn adapter_line(adapter: &wgpu::Adapter) -> String {
    let i = adapter.get_info();
    format!("{} ({:?}, {:?}, {} {})", i.name, i.backend, i.device_type, i.driver, i.driver_info)
}
