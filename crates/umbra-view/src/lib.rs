//! umbra-view: an interactive window on umbra's shadow-volume renderer.
//!
//! A winit 0.30 window with a GL 4.5 core context from glutin 0.32 (GLX or EGL on X11, EGL
//! on Wayland), drawn by the same [`umbra_gl::Renderer`] as `umbra render`: the frame is drawn
//! with [`umbra_gl::Renderer::draw_frame`] into an offscreen [`umbra_gl::RenderTarget`] of the
//! window's size (the depth format `umbra render` uses, so both give the same shadows) and
//! blitted to the window.
//!
//! Controls: left drag orbits the camera around its target, the wheel zooms, W/A/S/D fly
//! (Q/E down/up); shift + left drag moves the selected light in the image plane, the arrow
//! keys move it horizontally and PageUp/PageDown vertically, Tab selects the next light;
//! number keys 1-9 and 0 pick methods 1-10 of [`umbra_gl::method_names`], H picks
//! hier-triangle, R hier-silhouette, B ray-bvh, M cycles through all of them; V toggles the shadow-mask view (white = lit by every light, black = by none);
//! F toggles the selected light's shadow-volume wireframe over the shaded view
//! ([`umbra_gl::Renderer::draw_volume_wireframe`]; shadow maps, hier-triangle,
//! hier-silhouette and ray-bvh have no volumes); Escape quits.
//!
//! The overlay (frame time, method, triangles, silhouette edges, selected light) is the
//! window title: egui_glow, the maintained GL back end of egui, is built on glow 0.17 in its
//! newest release (0.37) and umbra is on glow 0.18, and the two `glow::Context` types do not
//! mix; see [`overlay`].
//!
//! Testing hooks: [`ViewerConfig::script`] (one camera pose per frame and wireframe
//! toggles, [`script`]) and
//! [`ViewerConfig::screenshot`] (after the last pose, the window's back buffer is written to a
//! PNG and the viewer exits).
//!
//! Without a display (neither `DISPLAY` nor `WAYLAND_DISPLAY` set, or the event loop cannot
//! connect) [`run`] returns [`ViewError::NoDisplay`], which suggests `umbra render`.

#![warn(missing_docs)]
// `unsafe` belongs to umbra-gl (the GL layer); the only exceptions are glutin's
// constructors in glue.rs, each marked `#[allow(unsafe_code)]` (why: glue.rs's module doc).
#![deny(unsafe_code)]

use std::path::PathBuf;
use std::sync::Arc;

use umbra_geom::WeldedMesh;
use umbra_gl::FrameParams;

mod app;
mod glue;
pub mod overlay;
pub mod rig;
pub mod script;

/// What to show and how.
#[derive(Clone, Debug)]
pub struct ViewerConfig {
    /// Name shown in the title (e.g. the scene spec).
    pub scene_name: String,
    /// The welded scene (see `umbra_geom::weld::weld`).
    pub mesh: Arc<WeldedMesh>,
    /// Initial camera, lights, shading, z-pass, depth convention and shadow-volume counter
    /// ([`FrameParams::counter`], used by every frame). `width` and `height`
    /// are the window's initial inner size; frames follow the window's size.
    pub params: FrameParams,
    /// Initial shadow method (a name from [`umbra_gl::method_names`]).
    pub method: String,
    /// Camera path, one pose per frame (see [`script`]).
    pub script: Option<PathBuf>,
    /// Write the window's frame after the script's last pose (or the first frame without a
    /// script) to this PNG, then exit.
    pub screenshot: Option<PathBuf>,
    /// Start in the shadow-mask view (V toggles it): grey level = fraction of the lights
    /// that light the pixel (umbra's per-light lit masks), black = none, white = all.
    pub mask_view: bool,
}

/// Why the viewer could not run.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// No X11 or Wayland display to open a window on.
    #[error("no display to open a window on ({0}); `umbra render` draws the same frame to a PNG without one")]
    NoDisplay(String),
    /// The window, its GL 4.5 core context or its surface could not be made.
    #[error("window or GL context: {0}")]
    Window(String),
    /// umbra's renderer failed (GL error, bad parameters).
    #[error("{0}")]
    Gl(#[from] umbra_gl::GlError),
    /// The initial method is not in the registry.
    #[error("{0}")]
    UnknownMethod(#[from] umbra_gl::UnknownMethod),
    /// A camera script that cannot be used (file, 1-based line; 0 = the whole file).
    #[error("{file}:{line}: {message}")]
    Script {
        /// The script file.
        file: String,
        /// 1-based line (0: the file as a whole).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Reading the script or writing the screenshot failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Nothing to draw.
    #[error("the scene has no triangles to draw")]
    EmptyScene,
}

/// What a run did (for scripts and tests).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewSummary {
    /// Frames drawn.
    pub frames: usize,
    /// The screenshot written, if any, and its size.
    pub screenshot: Option<(PathBuf, u32, u32)>,
    /// The GL renderer string of the window's context.
    pub gl_renderer: String,
}

/// Whether the environment names a display server at all (X11 or Wayland).
pub fn display_available() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// Opens the window and runs until it is closed (or the screenshot is written).
pub fn run(config: ViewerConfig) -> Result<ViewSummary, ViewError> {
    if config.mesh.triangles.is_empty() {
        return Err(ViewError::EmptyScene);
    }
    umbra_gl::create_method(&config.method)?;
    let script = config.script.as_deref().map(script::load).transpose()?;
    if !display_available() {
        return Err(ViewError::NoDisplay("neither DISPLAY nor WAYLAND_DISPLAY is set".into()));
    }
    app::run(config, script)
}
