//! The renderer's volume pass (pass 2): per light, the stencil cleared (to 0, or `W0` under
//! auto z-pass), the counter chosen, the near-plane and scene-box clip planes set, and the
//! method's [`ShadowMethod::draw_volumes`] run.

use glow::HasContext;
use umbra_geom::clearance::scene_clip_box;
use umbra_geom::Light;

use umbra_geom::FrameParams;

use super::view::{mark, PassView};
use super::Renderer;
use crate::counter::{Counter, FloatCounter};
use crate::error::GlError;
use crate::methods::{Classification, ShadowMethod, StageHook, VolumeFrame};
use crate::scene::{SceneGpu, SCENE_CLIP_BINDING};
use crate::state::GlState;

/// `v[i] = value`, growing `v` with `None`s.
fn set_at<T>(v: &mut Vec<Option<T>>, i: usize, value: Option<T>) {
    if v.len() <= i {
        v.resize_with(i + 1, || None);
    }
    v[i] = value;
}

impl Renderer {
    /// Uploads the scene box planes in `view`'s clip space to the `UmbraSceneClip` block, binds
    /// it at [`SCENE_CLIP_BINDING`] and, with `enable`, turns GL_CLIP_DISTANCE1..6 on.
    pub(super) fn bind_scene_clip(
        &mut self,
        gl: &glow::Context,
        view: &PassView,
        bounds: Option<umbra_geom::Aabb>,
        enable: bool,
    ) -> Result<(), GlError> {
        let buffer = match self.scene_clip {
            Some(b) => b,
            None => {
                // SAFETY: creating a buffer name on the current context.
                let b = unsafe { gl.create_named_buffer() }
                    .map_err(|detail| GlError::Create { what: "scene clip uniform block", detail })?;
                self.scene_clip = Some(b);
                b
            }
        };
        let mut data = [0f32; 24];
        if let (Some(bounds), true) = (bounds, enable) {
            // A world plane p (p . (X, W) >= 0 inside) in clip space: (clip_from_world)^-T p.
            let clip_from_plane = view.world_from_clip.transpose();
            for (i, p) in scene_clip_box(bounds, view.eye).iter().enumerate() {
                let q = clip_from_plane * glam::DVec4::from_array(*p);
                data[4 * i..4 * i + 4].copy_from_slice(&q.to_array().map(|c| c as f32));
            }
        }
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_ne_bytes()).collect();
        // SAFETY: 96 bytes into our own buffer; binding it to an indexed uniform block point.
        unsafe {
            gl.named_buffer_data_u8_slice(buffer, &bytes, glow::DYNAMIC_DRAW);
            gl.bind_buffer_base(glow::UNIFORM_BUFFER, SCENE_CLIP_BINDING, Some(buffer));
            // Reason: planes 1..6 clip only a z-pass pass; under z-fail the shaders still
            // write them, so a plane a host left enabled must be off (7: never written).
            for i in 1..8 {
                if enable && i < 7 {
                    gl.enable(glow::CLIP_DISTANCE0 + i);
                } else {
                    gl.disable(glow::CLIP_DISTANCE0 + i);
                }
            }
        }
        Ok(())
    }

    /// Pass 2, one light: clears the stencil of `view`'s framebuffer to 0 and lets `method`
    /// mark it (its volumes, z-fail or z-pass per `params.zpass`, against the depth already
    /// in the framebuffer), then binds `view`'s framebuffer and viewport again and re-sets the
    /// depth convention (a method may have bound its own framebuffer or changed clip control).
    /// Leaves the GL state as the method left it, apart from those.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn volume_pass(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        method: &mut dyn ShadowMethod,
        params: &FrameParams,
        view: &PassView,
        light: Light,
        light_index: usize,
        hook: &mut Option<&mut dyn StageHook>,
    ) -> Result<(), GlError> {
        // ---- Pass 2: shadow volumes into a cleared stencil.
        mark(hook, gl, "volumes", Some(light_index));
        // The wide counter (crate::counter) serves the methods that count in the stencil: they
        // draw into its framebuffer, the resolve writes the stencil they would have written.
        let fills = method.fills_volumes();
        let counter = match (params.counter, method.classification()) {
            (Counter::Float32, Classification::StencilZero) if fills => Counter::Float32,
            _ => Counter::Stencil8,
        };
        // z-pass where it is exact (umbra_geom::clearance), z-fail elsewhere. With the eye's
        // near pyramid inside W0 volumes and crossed by none of their faces, z-pass counts
        // W(p) - W0, so the stencil starts at W0 (8-bit stencil only; the wide counter starts
        // at 0, so there W0 > 0 keeps z-fail).
        let counting = method.classification() == Classification::StencilZero && fills;
        let (zpass, start) = if !fills {
            // Nothing is counted: the method writes its decision into a stencil cleared to 0.
            (false, 0)
        } else if params.zpass {
            (true, 0)
        } else if params.camera.is_orthographic() {
            // The eye is at infinity and the volumes are finite (ShadowMethod::orthographic):
            // with depth clamp, z-pass counts every crossing from infinity behind the camera
            // to the sample, where the winding is 0, so it is exact from W0 = 0 wherever the
            // camera is (docs/exactness.md, "Orthographic views"). z-fail only when asked.
            (params.auto_zpass && counting, 0)
        } else if params.auto_zpass && counting {
            let adjacency = method.silhouette_sides().then(|| scene.adjacency().as_ref());
            match scene.clearance().near_winding(scene.mesh(), adjacency, &view.near_pyramid, light) {
                Some(0) => (true, 0),
                Some(w0) if counter == Counter::Stencil8 => (true, (w0 % 256) as i32),
                _ => (false, 0),
            }
        } else {
            (false, 0)
        };
        if self.last_zpass.len() <= light_index {
            self.last_zpass.resize(light_index + 1, false);
        }
        self.last_zpass[light_index] = zpass;
        // Reason: the stencil clear obeys the stencil write mask; default = all bits.
        GlState::default().apply(gl);
        view.bind_target(gl);
        // SAFETY: clears the stencil of the bound draw framebuffer (to 0, or W0 as above).
        unsafe { gl.clear_buffer_i32_slice(glow::STENCIL, 0, &[start]) };
        let mut target = view.fb;
        if counter == Counter::Float32 {
            if self.counter.is_none() {
                self.counter = Some(FloatCounter::new(gl)?);
            }
            if let Some(c) = self.counter.as_mut() {
                target = Some(c.begin(gl, view.fb, params.width, params.height)?);
            }
        }
        {
            let mut frame = VolumeFrame {
                zpass,
                target_framebuffer: target,
                counter,
                state_override: self.volume_state_override,
                // Re-borrow with a shorter trait-object lifetime (an Option blocks the
                // automatic coercion).
                hook: match hook.as_mut() {
                    Some(h) => Some(&mut **h as &mut dyn StageHook),
                    None => None,
                },
                ..view.volume_frame(params, light, light_index, method.name())
            };
            // Reason: light caps of casters the camera's near plane cuts are clipped at that
            // plane before they are pushed to the far plane (methods/shared/depth.glsl): the
            // counting methods' volume shaders write gl_ClipDistance[0] (a positive constant
            // for everything but light caps). Not for Classification::Shader methods (shadow
            // maps draw their own depth pass without clip distances), not for methods that fill
            // no volumes (their draws write no clip distances), not on OpenGL ES (none).
            let near_clip = fills && method.classification() != Classification::Shader && !gl.version().is_embedded;
            if near_clip {
                // SAFETY: enabling a core capability on the current context.
                unsafe { gl.enable(glow::CLIP_DISTANCE0) };
            }
            // Reason: z-pass counts only crossings between the eye and the sample, inside the
            // scene box, so the volumes are clipped to it (GL_CLIP_DISTANCE1..6, planes in the
            // UmbraSceneClip block, methods/shared/depth.glsl): their parts beyond the scene cost
            // fill and binning and count nothing. The block is bound for every counting pass
            // (the shaders read it whether or not the planes are enabled). Counting methods only:
            // paper 002's all-edges-invert (parity, StencilTest) changed on 433 of 76,800 pixels
            // of tests/render.rs's z-pass case with the clip, so it keeps its unclipped volumes.
            // Not for an orthographic view: its z-pass counts from infinity behind the camera,
            // and the scene box does not hold that whole line (nor the eye, at infinity).
            let scene_clip =
                near_clip && zpass && counting && scene.bounds().is_some() && !params.camera.is_orthographic();
            if near_clip {
                self.bind_scene_clip(gl, view, scene.bounds(), scene_clip)?;
            }
            // The fragment count (renderer/fragments.rs), only when asked (reading it stalls).
            // Not for the wireframe: its lines are no volume pass, and the frame's counts stay.
            let wireframe = self.volume_state_override.is_some();
            let query =
                if self.count_volume_fragments && fills && !wireframe { self.begin_fragment_count(gl) } else { None };
            let counting = query.is_some();
            let drawn = method.draw_volumes(gl, scene, &mut frame);
            let fragments = query.map(|q| self.end_fragment_count(gl, q));
            if !wireframe {
                set_at(&mut self.last_volume_fragments, light_index, fragments);
                let d = if counting { method.read_drawn_volume(gl) } else { method.drawn_volume() };
                set_at(&mut self.last_drawn, light_index, d);
            }
            if near_clip {
                // SAFETY: as above; off again whatever the method returned.
                unsafe {
                    gl.disable(glow::CLIP_DISTANCE0);
                    for i in 1..7 {
                        gl.disable(glow::CLIP_DISTANCE0 + i);
                    }
                }
            }
            drawn?;
        }
        if let (Counter::Float32, Some(c)) = (counter, self.counter.as_ref()) {
            c.resolve(gl, view.fb, params.width, params.height)?;
        }
        // The method may have bound other framebuffers (shadow maps) or changed the clip
        // control for its own depth pass: re-bind ours, re-set the convention.
        view.bind_target(gl);
        self.set_depth_convention(gl, view.convention)?;
        Ok(())
    }
}
