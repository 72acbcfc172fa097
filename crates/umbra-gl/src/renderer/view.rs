//! [`PassView`]: what the passes of one frame share, derived once from its [`FrameParams`]
//! and target, and the stage marks the passes hand to a [`StageHook`].

use glam::DMat4;
use glow::HasContext;
use umbra_geom::camera::near_pyramid_points;
use umbra_geom::{FrameParams, Light};

use crate::camera::{to_f32_cols, DepthConvention};
use crate::counter::Counter;
use crate::methods::{StageHook, StageMark, VolumeFrame};

/// What the passes of one frame share, derived once from its [`FrameParams`] and target.
pub(super) struct PassView {
    /// Camera clip space from world space in the frame's depth convention.
    pub(super) clip_from_world: DMat4,
    /// The same, as f32 columns for the shaders.
    pub(super) clip_f32: [f32; 16],
    /// Its inverse (the near-plane corners, the scene clip planes in clip space).
    pub(super) world_from_clip: DMat4,
    /// The eye and the near-plane corners the auto z-pass test uses (per frame, any light).
    pub(super) near_pyramid: Vec<[f64; 3]>,
    pub(super) eye: [f64; 3],
    /// The lighting pass's `u_eye`: the eye (w = 1), or the unit direction towards it (w = 0)
    /// when the camera is orthographic.
    pub(super) shading_eye: [f32; 4],
    pub(super) convention: DepthConvention,
    /// The framebuffer drawn into (None = default framebuffer).
    pub(super) fb: Option<glow::Framebuffer>,
    pub(super) width: i32,
    pub(super) height: i32,
    /// [`VolumeFrame::view_serial`]: new whenever the depth may have changed.
    pub(super) serial: u64,
}

impl PassView {
    /// The [`VolumeFrame`] a method gets for `light` in this view: drawn into the view's
    /// framebuffer, 8-bit stencil counting, no state override, no hook (the volume pass sets
    /// those it needs).
    pub(super) fn volume_frame(
        &self,
        params: &FrameParams,
        light: Light,
        light_index: usize,
        source: &'static str,
    ) -> VolumeFrame<'static> {
        VolumeFrame {
            clip_from_world: self.clip_from_world,
            eye: self.eye,
            light,
            light_index,
            zpass: params.zpass,
            volume_cull: params.volume_cull,
            receivers: params.receivers,
            width: params.width,
            height: params.height,
            target_framebuffer: self.fb,
            depth_convention: self.convention,
            counter: Counter::Stencil8,
            state_override: None,
            view_serial: self.serial,
            source,
            hook: None,
        }
    }

    pub(super) fn new(params: &FrameParams, fb: Option<glow::Framebuffer>, serial: u64) -> Self {
        let convention = params.depth_convention;
        let aspect = params.width as f64 / params.height as f64;
        let clip_from_world = params.camera.clip_from_world_in(aspect, convention);
        let world_from_clip = clip_from_world.inverse();
        Self {
            clip_f32: to_f32_cols(&clip_from_world),
            near_pyramid: near_pyramid_points(&world_from_clip, params.camera.eye, convention),
            world_from_clip,
            clip_from_world,
            eye: params.camera.eye,
            shading_eye: if params.camera.is_orthographic() {
                let f = params.camera.forward();
                [-f[0] as f32, -f[1] as f32, -f[2] as f32, 0.0]
            } else {
                let e = params.camera.eye;
                [e[0] as f32, e[1] as f32, e[2] as f32, 1.0]
            },
            convention,
            fb,
            width: params.width as i32,
            height: params.height as i32,
            serial,
        }
    }

    /// Binds the frame's framebuffer for drawing and sets the viewport to the whole frame.
    pub(super) fn bind_target(&self, gl: &glow::Context) {
        // SAFETY: binding the frame's framebuffer and setting the viewport.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, self.fb);
            gl.viewport(0, 0, self.width, self.height);
        }
    }
}

/// Hands the stage boundary `label` (of `light`, if any) to the hook, if any.
pub(super) fn mark(
    hook: &mut Option<&mut dyn StageHook>,
    gl: &glow::Context,
    label: &'static str,
    light: Option<usize>,
) {
    if let Some(h) = hook.as_deref_mut() {
        h.mark(gl, StageMark { source: "renderer", label, light });
    }
}
