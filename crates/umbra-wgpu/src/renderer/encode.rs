//! Recording one stand-alone frame: every light's compute work, then depth + ambient, then
//! per light the volumes and the lighting, the readbacks and stage timestamps asked for, in
//! one command buffer and one submission.

use umbra_geom::image::NO_TRIANGLE;
use umbra_geom::FrameParams;

use crate::builders::LIGHT_SLOT_BYTES;
use crate::error::WgpuError;
use crate::fragments::FragmentQueries;
use crate::readback::Readback;
use crate::scene::SceneGpu;
use crate::view::{View, VolumeFrame, ZMode};
use crate::volumes::ShadowVolumes;

use super::target::{view_of, Target};
use super::Renderer;

/// The frame uniform (`Frame` of shaders/scene.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct FrameUniform {
    clip_from_world: [f32; 16],
    ambient: [f32; 4],
    eye: [f32; 4],
    albedo: [f32; 4],
    light_color: [f32; 4],
    specular: [f32; 4],
}

/// A render pass of the frame on `depth`, its depth and stencil loaded as said and stored.
fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    color_attachments: &[Option<wgpu::RenderPassColorAttachment<'_>>],
    depth: &wgpu::TextureView,
    depth_load: wgpu::LoadOp<f32>,
    stencil_load: wgpu::LoadOp<u32>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
            stencil_ops: Some(wgpu::Operations { load: stencil_load, store: wgpu::StoreOp::Store }),
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

impl Renderer {
    /// Records and submits the frame; returns the readbacks to map (the colour only with
    /// `read_color`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn encode(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        volumes: &mut ShadowVolumes,
        params: &FrameParams,
        view: &View,
        read_color: bool,
        timestamps: Option<&wgpu::QuerySet>,
    ) -> Result<Pending, WgpuError> {
        let (w, h) = (params.width, params.height);
        if self.target.as_ref().is_none_or(|t| t.width != w || t.height != h) {
            self.target = Some(Target::new(device, w, h, self.depth_format));
        }
        let eye = params.camera.eye.map(|c| c as f32);
        let frame = FrameUniform {
            clip_from_world: view.clip_from_world_f32(),
            ambient: [
                params.albedo[0] * params.ambient,
                params.albedo[1] * params.ambient,
                params.albedo[2] * params.ambient,
                0.0,
            ],
            eye: [eye[0], eye[1], eye[2], 0.0],
            albedo: [params.albedo[0], params.albedo[1], params.albedo[2], 0.0],
            light_color: [params.light_color[0], params.light_color[1], params.light_color[2], 0.0],
            specular: [params.specular, params.shininess, 0.0, 0.0],
        };
        queue.write_buffer(&self.frame_uniform, 0, bytemuck::bytes_of(&frame));
        let (lights_buffer, lights_group) = self.lights_uniform(device, params.lights.len());
        for (i, l) in params.lights.iter().enumerate() {
            queue.write_buffer(&lights_buffer, i as u64 * LIGHT_SLOT_BYTES, bytemuck::cast_slice(l));
        }
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("umbra frame"),
            layout: &self.pipelines.frame_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.frame_uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.normal_buffer().as_entire_binding() },
            ],
        });
        let target = self.target.as_ref().expect("made above");
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra frame") });
        // Stage boundaries (bench): the label of the stage that starts at each timestamp.
        let mut labels: Vec<&'static str> = Vec::new();
        let mut stamp = |encoder: &mut wgpu::CommandEncoder, label: &'static str| {
            if let Some(set) = timestamps {
                encoder.write_timestamp(set, labels.len() as u32);
                labels.push(label);
            }
        };
        // Volumes culled against the receivers need the scene's depth first (the receiver
        // maps are built from it and read back before the volumes are extracted): then the
        // depth pass is submitted on its own, and every light's work follows it.
        let cull = params.volume_cull && volumes.culls_volumes();
        // Fragment counts (bench's `volume_fragments`): the volume passes' here, the receiver
        // scatter's by the method; only for methods that count volumes.
        volumes.set_count_fragments(self.count_volume_fragments);
        let lights = params.lights.len() as u32;
        let fragments = (self.count_volume_fragments && volumes.counts_volumes())
            .then(|| FragmentQueries::new(device, "umbra volume fragments", lights))
            .flatten();
        let zmode = ZMode { zpass: params.zpass, auto_zpass: params.auto_zpass };
        let mut plans = Vec::new();
        if !cull {
            // ---- Every light's compute work, before any pass.
            stamp(&mut encoder, "prepare");
            let frame = VolumeFrame { view, lights: &params.lights, zmode, receivers: None };
            plans = volumes.prepare(device, queue, &mut encoder, scene, &frame)?.to_vec();
        }

        // ---- Pass 1: depth + ambient (+ world position, triangle id).
        stamp(&mut encoder, "depth+ambient");
        let capture_samples = params.capture.world_pos || params.capture.triangle_id;
        let (color, world, ids, lit, depth) = (
            view_of(&target.color),
            view_of(&target.world_pos),
            view_of(&target.triangle_id),
            view_of(&target.lit_mask),
            view_of(&target.depth),
        );
        use wgpu::LoadOp::{Clear, Load};
        let attachment = |view, load| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })
        };
        let draw_scene = |pass: &mut wgpu::RenderPass<'_>| {
            pass.set_vertex_buffer(0, scene.position_buffer().slice(..));
            pass.set_index_buffer(scene.index_buffer().slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..scene.index_count(), 0, 0..1);
        };
        {
            let bg = params.background.map(f64::from);
            let mut attachments =
                vec![attachment(&color, Clear(wgpu::Color { r: bg[0], g: bg[1], b: bg[2], a: bg[3] }))];
            if capture_samples {
                attachments.push(attachment(&world, Clear(wgpu::Color::TRANSPARENT)));
                attachments
                    .push(attachment(&ids, Clear(wgpu::Color { r: f64::from(NO_TRIANGLE), g: 0.0, b: 0.0, a: 0.0 })));
            }
            // Reason: reversed-Z: the far plane (and the background) is depth 0, which is also
            // where light caps are pushed (so they fail the strict test there too).
            let mut pass = begin_pass(&mut encoder, "umbra depth+ambient", &attachments, &depth, Clear(0.0), Clear(0));
            pass.set_pipeline(&self.pipelines.depth[capture_samples as usize]);
            pass.set_bind_group(0, &frame_group, &[]);
            draw_scene(&mut pass);
        }
        if cull {
            // ---- Every light's receiver map (its own submission and read-back) and cull,
            // then its uploads: after the depth, before any volume.
            stamp(&mut encoder, "receivers");
            queue.submit([std::mem::replace(
                &mut encoder,
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra frame volumes") }),
            )
            .finish()]);
            stamp(&mut encoder, "prepare");
            let frame = VolumeFrame { view, lights: &params.lights, zmode, receivers: Some(&target.depth) };
            plans = volumes.prepare(device, queue, &mut encoder, scene, &frame)?.to_vec();
        }

        let mut stencil = Vec::new();
        let mut lit_masks = Vec::new();
        for (i, plan) in plans.iter().enumerate() {
            // ---- Pass 2: this light's volumes into a freshly cleared stencil.
            stamp(&mut encoder, "volumes");
            {
                // Reason: the scene's depth, read by the volumes' depth test, never written.
                let mut pass = begin_pass(&mut encoder, "umbra volumes", &[], &depth, Load, Clear(plan.stencil_clear));
                if let Some(q) = &fragments {
                    pass.begin_pipeline_statistics_query(&q.set, i as u32);
                }
                volumes.draw(&mut pass, i);
                if fragments.is_some() {
                    pass.end_pipeline_statistics_query();
                }
            }
            if params.capture.stencil.includes(i) {
                let r =
                    Readback::copy(device, &mut encoder, &target.depth, wgpu::TextureAspect::StencilOnly, 1, "stencil");
                stencil.push((i, r));
            }
            // ---- Pass 3: lighting where the stencil is 0.
            stamp(&mut encoder, "lighting");
            let capture_lit = params.capture.lit_mask.includes(i);
            {
                let mut attachments = vec![attachment(&color, Load)];
                if capture_lit {
                    attachments.push(attachment(&lit, Clear(wgpu::Color::TRANSPARENT)));
                }
                let mut pass = begin_pass(&mut encoder, "umbra lighting", &attachments, &depth, Load, Load);
                pass.set_pipeline(&self.pipelines.lighting[capture_lit as usize]);
                pass.set_stencil_reference(0);
                pass.set_bind_group(0, &frame_group, &[]);
                pass.set_bind_group(1, &lights_group, &[(i as u64 * LIGHT_SLOT_BYTES) as u32]);
                draw_scene(&mut pass);
            }
            if capture_lit {
                let r = Readback::copy(device, &mut encoder, &target.lit_mask, wgpu::TextureAspect::All, 1, "lit mask");
                lit_masks.push((i, r));
            }
        }
        stamp(&mut encoder, "end");
        if let Some(q) = &fragments {
            q.resolve(&mut encoder);
        }
        let stamps = timestamps.map(|set| {
            let n = labels.len() as u32;
            let bytes = 8 * u64::from(n);
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("umbra timestamps"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("umbra timestamps readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            encoder.resolve_query_set(set, 0..n, &resolve, 0);
            encoder.copy_buffer_to_buffer(&resolve, 0, &readback, 0, bytes);
            (labels.clone(), readback)
        });
        let all = wgpu::TextureAspect::All;
        let pending = Pending {
            stamps,
            color: read_color.then(|| Readback::copy(device, &mut encoder, &target.color, all, 4, "colour")),
            world_pos: params
                .capture
                .world_pos
                .then(|| Readback::copy(device, &mut encoder, &target.world_pos, all, 16, "world position")),
            triangle_id: params
                .capture
                .triangle_id
                .then(|| Readback::copy(device, &mut encoder, &target.triangle_id, all, 4, "triangle id")),
            stencil,
            lit_masks,
            fragments,
        };
        queue.submit([encoder.finish()]);
        Ok(pending)
    }
}

/// Readbacks recorded in a frame's command buffer.
pub(super) struct Pending {
    /// Stage labels and the buffer their timestamps are copied to.
    pub(super) stamps: Option<(Vec<&'static str>, wgpu::Buffer)>,
    pub(super) color: Option<Readback>,
    pub(super) world_pos: Option<Readback>,
    pub(super) triangle_id: Option<Readback>,
    pub(super) stencil: Vec<(usize, Readback)>,
    pub(super) lit_masks: Vec<(usize, Readback)>,
    /// One fragment counter per light's volume pass, when counted.
    pub(super) fragments: Option<FragmentQueries>,
}
