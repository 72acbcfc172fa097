//! umbra-gl: exact per-sample stencil shadow volumes for triangle soups on OpenGL 4.5 core.
//!
//! * [`context`]: headless GL 4.5 core / GLES 3 context through EGL loaded at run time
//!   (Mesa surfaceless platform, EGL device platform fallback), KHR_debug error capture; GL
//!   for a window system's context ([`context::from_loader`]) and safe helpers for a viewer.
//! * [`extra`]: entry points glow 0.18 lacks (glClipControl, multi-draw indirect).
//! * [`state`]: [`GlState`], the full fixed-function state of one draw, applied explicitly.
//! * [`camera`]: look-at + infinite-far perspective (Everitt & Kilgard 2002), standard or
//!   reversed-Z ([`DepthConvention`], reversed-Z with float depth by default); shared with
//!   umbra-wgpu through [`umbra_geom::camera`], with the GL enums in [`DepthConventionGl`].
//! * [`scene`]: [`SceneGpu`], a welded mesh uploaded once.
//! * [`target`]: [`RenderTarget`] and readback helpers (top row first).
//! * [`renderer`]: the frame: depth + ambient, per light stencil volumes + additive lighting,
//!   optional per-light lit masks (the final lit/shadow decision the image shows); and inside
//!   a renderer of the caller's, light by light: [`Renderer::count_shadows`] (the stencil
//!   only, on the caller's depth) and [`Renderer::add_light`]. A frame is described by
//!   [`FrameParams`], umbra-geom's, the one umbra-wgpu takes too.
//! * [`methods`]: [`ShadowMethod`] trait, registry ([`method_names`], [`create_method`]),
//!   `none` and `cpu-silhouette`.
//! * [`timing`]: glQueryCounter(GL_TIMESTAMP) stage timing.
//! * [`image`]: top-row-first images and PNG output.
//!
//! `unsafe` is confined to this crate; every block carries a SAFETY comment.

#![warn(missing_docs)]

pub mod camera;
pub mod context;
pub mod counter;
pub mod error;
pub mod extra;
mod gl_names;
pub(crate) mod gpu_buffer;
pub mod image;
pub mod methods;
pub mod program;
pub mod renderer;
mod saved;
pub mod scene;
pub mod state;
pub mod target;
pub mod timing;

pub use camera::{Camera, DepthConvention, DepthConventionGl, Projection};
pub use context::{ContextError, ContextOptions, GlApi, HeadlessContext};
pub use error::{GlError, GlErrorLog};
pub use extra::GlExtra;
pub use image::{Image, LitMaskImage, RgbaImage, StencilImage, TriangleIdImage, WorldPosImage};
pub use methods::work_counts::WorkCounts;
pub use methods::{
    create_method, method_names, Classification, DrawnVolume, ShadowMethod, StageHook, StageMark, UnknownMethod,
    VolumeFrame,
};
pub use renderer::{
    CaptureFlags, FrameImages, FrameParams, FrameTarget, LightCapture, LitMask, LitMaskCapture, Receivers, Renderer,
    StencilCapture, StencilMask, VolumeFragmentQuery,
};
pub use scene::{SceneGpu, SceneId};
pub use state::{BlendState, GlState, StencilFace};
pub use target::{read_rgba8, read_stencil, Attachments, RenderTarget, TargetPass, NO_TRIANGLE};
pub use timing::{StageTiming, TimestampHook};

/// glam, the math of the method-author API ([`VolumeFrame::clip_from_world`], [`Camera`]'s
/// matrix functions); feature `glam` (default).
#[cfg(feature = "glam")]
pub use glam;
pub use glow;
