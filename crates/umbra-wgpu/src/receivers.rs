//! The receiver map pass: the host's visible samples scattered into one light's
//! [`ReceiverMap`] on the GPU (`shaders/receivers.wgsl`), read back for the CPU's exact culling
//! and clamping of the shadow volumes ([`ReceiverMap::cull_and_clamp`], docs/exactness.md,
//! "Volumes clamped to their receivers"). The twin of umbra-gl's `methods/receivers`.
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004) with the receivers taken
//! from the frame itself. One scene draw per light over the host's depth (a read-only
//! attachment, and a texture the shader compares against), an `atomicMax` per sample into a
//! buffer of [`ReceiverGrid::cells`] words, and a read-back of that buffer: a submission and
//! a wait, since the CPU needs the map before it can extract the volume.

use umbra_geom::receivers::{ReceiverGrid, ReceiverMap, RECEIVER_SIDE};
use umbra_geom::{Aabb, Light};

use crate::builders::storage_entry;
use crate::common::Common;
use crate::error::WgpuError;
use crate::fragments::FragmentQueries;
use crate::scene::SceneGpu;
use crate::view::View;

const SHADER: &str = include_str!("shaders/receivers.wgsl");
const RECEIVER_CELL: &str = include_str!("shaders/receiver_cell.wgsl");

/// The scatter's uniform (`Scatter` of shaders/receivers.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ScatterUniform {
    clip_from_world: [f32; 16],
    light: [f32; 4],
    origin: [f32; 4],
    u: [f32; 4],
    v: [f32; 4],
    travel: [f32; 4],
    lo_scale: [f32; 4],
    side: u32,
    depth_slack: f32,
    pad: [u32; 2],
}

/// What the scatter needs of the host's depth: the texture it was drawn into.
fn check_depth(device: &wgpu::Device, depth: &wgpu::Texture) -> Result<(), WgpuError> {
    let needed = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    if !depth.usage().contains(needed) {
        return Err(WgpuError::InvalidParams(format!(
            "volume culling reads the scene's depth as a texture: its usage {:?} lacks {:?}",
            depth.usage(),
            needed - depth.usage()
        )));
    }
    if !depth.format().has_depth_aspect() || depth.sample_count() != 1 {
        return Err(WgpuError::InvalidParams(format!(
            "volume culling needs a single-sample depth texture, got {:?} with {} samples",
            depth.format(),
            depth.sample_count()
        )));
    }
    if !device.features().contains(wgpu::Features::PRIMITIVE_INDEX) {
        return Err(WgpuError::InvalidParams(
            "volume culling needs the device feature PRIMITIVE_INDEX (the seen side's normal per sample)".into(),
        ));
    }
    Ok(())
}

/// The receiver pass's pipeline (for one depth format) and buffers (sized for a point light's
/// cube).
pub(crate) struct ReceiverPass {
    format: wgpu::TextureFormat,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    map: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl ReceiverPass {
    /// Bytes of the map (a point light's six faces).
    fn map_bytes() -> u64 {
        4 * ReceiverGrid::Cube { light: [0.0; 3], side: RECEIVER_SIDE }.cells() as u64
    }

    /// The pipeline for depth textures of `format`, and the buffers.
    pub(crate) fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        // With early depth tests the hidden fragments are rejected before the shader (depth
        // EQUAL, as umbra-gl's `early_fragment_tests`); without, every fragment of the scene
        // runs the shader's own test, the same samples at a higher cost.
        let early = device.features().contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
        let source = if early {
            SHADER.replace("@fragment\nfn fs_scatter(", "@fragment @early_depth_test(force)\nfn fs_scatter(")
        } else {
            SHADER.to_string()
        };
        let module = Common::module(device, "receivers.wgsl", &["enable primitive_index;", RECEIVER_CELL, &source]);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra receiver map"),
            entries: &[
                crate::builders::uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, false),
                storage_entry(1, fragment, true),
                storage_entry(2, fragment, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: fragment,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra receiver map"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let positions =
            [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: 0 }];
        let keep = wgpu::StencilFaceState::IGNORE;
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("umbra receiver map scatter"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_scatter"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &positions,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                strip_index_format: None,
                // Reason: front_facing picks the seen side's normal, counter-clockwise = front
                // as in the scene's normals.
                front_face: wgpu::FrontFace::Ccw,
                // Reason: both faces are surfaces, as in the host's depth pass.
                cull_mode: None,
                // Reason: the same clipping as the host's depth pass (depths must be equal).
                unclipped_depth: false,
                polygon_mode: wgpu::PolygonMode::Fill,
                conservative: false,
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format,
                // Reason: the host's depth is final; it is only read (attachment and texture).
                depth_write_enabled: Some(false),
                // Reason: forced before the shader, EQUAL lets exactly the visible surface
                // through (bit-identical depths); otherwise the shader tests the depth itself
                // (see shaders/receivers.wgsl), since a test after it would not undo its write.
                depth_compare: Some(if early { wgpu::CompareFunction::Equal } else { wgpu::CompareFunction::Always }),
                // Reason: the stencil is neither tested nor written.
                stencil: wgpu::StencilState { front: keep, back: keep, read_mask: 0, write_mask: 0 },
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_scatter"),
                compilation_options: Default::default(),
                // Reason: the map is the only output.
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        use wgpu::BufferUsages as U;
        let bytes = Self::map_bytes();
        Self {
            format,
            pipeline,
            layout,
            uniform: buffer("umbra receiver map uniform", Self::uniform_bytes(), U::UNIFORM | U::COPY_DST),
            map: buffer("umbra receiver map", bytes, U::STORAGE | U::COPY_SRC | U::COPY_DST),
            readback: buffer("umbra receiver map readback", bytes, U::MAP_READ | U::COPY_DST),
        }
    }

    /// The depth format the pipeline was made for.
    pub(crate) fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Bytes of GPU memory held.
    pub(crate) fn gpu_bytes(&self) -> u64 {
        2 * Self::map_bytes() + self.uniform.size()
    }

    /// The map of `light` over the visible samples of `depth` (drawn by the host with `view`
    /// and submitted), read back, and with `count` the fragments the scatter shaded (`None`
    /// where the device cannot count). `bounds`: the scene's box (a directional light's grid
    /// spans it).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        view: &View,
        light: Light,
        bounds: Aabb,
        depth: &wgpu::Texture,
        count: bool,
    ) -> Result<(ReceiverMap, Option<u64>), WgpuError> {
        let queries = if count { FragmentQueries::new(device, "umbra receiver map fragments", 1) } else { None };
        let grid = ReceiverGrid::new(light, bounds, RECEIVER_SIDE);
        let cells = grid.cells() as u64;
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("umbra receiver map") });
        self.record(
            device,
            queue,
            &mut encoder,
            scene,
            view,
            light,
            &grid,
            depth,
            &self.uniform,
            &self.map,
            queries.as_ref(),
        )?;
        encoder.copy_buffer_to_buffer(&self.map, 0, &self.readback, 0, 4 * cells);
        if let Some(q) = &queries {
            q.resolve(&mut encoder);
        }
        queue.submit([encoder.finish()]);
        let words: Vec<u32> = crate::readback::read_buffer(device, &self.readback, "receiver map")?;
        let fragments = queries.map(|q| q.read(device)).transpose()?.map(|v| v[0]);
        let map = ReceiverMap::from_encoded(grid, &words[..cells as usize])
            .ok_or_else(|| WgpuError::InvalidParams("receiver map: read back a map of the wrong size".into()))?;
        Ok((map, fragments))
    }

    /// Records into `encoder` the scatter of `depth`'s visible samples (drawn by the host with
    /// `view` and submitted before `encoder` is) into the first [`ReceiverGrid::cells`] words
    /// of `map`, cleared first: `light`'s map of `grid`. `uniform` (a buffer of
    /// [`ReceiverPass::uniform_bytes`], `UNIFORM | COPY_DST`) is written through `queue` and
    /// must not be shared by two scatters of one submission. With `queries`, counter 0
    /// counts the fragments shaded.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        view: &View,
        light: Light,
        grid: &ReceiverGrid,
        depth: &wgpu::Texture,
        uniform_buffer: &wgpu::Buffer,
        map: &wgpu::Buffer,
        queries: Option<&FragmentQueries>,
    ) -> Result<(), WgpuError> {
        check_depth(device, depth)?;
        let cells = grid.cells() as u64;
        let mut uniform = ScatterUniform {
            clip_from_world: view.clip_from_world_f32(),
            light,
            origin: [0.0; 4],
            u: [0.0; 4],
            v: [0.0; 4],
            travel: [0.0; 4],
            lo_scale: [0.0; 4],
            side: grid.side(),
            // A float depth holds the fragment's very depth; a 24-bit one its rounding to
            // 2^-24, which a slack of 2^-22 covers.
            depth_slack: if matches!(
                depth.format(),
                wgpu::TextureFormat::Depth32Float | wgpu::TextureFormat::Depth32FloatStencil8
            ) {
                0.0
            } else {
                1.0 / 4_194_304.0
            },
            pad: [0; 2],
        };
        if let ReceiverGrid::Flat { origin, u, v, travel, lo, scale, .. } = *grid {
            let w = |a: [f32; 3]| [a[0], a[1], a[2], 0.0];
            uniform.origin = w(origin);
            uniform.u = w(u);
            uniform.v = w(v);
            uniform.travel = w(travel);
            uniform.lo_scale = [lo[0], lo[1], scale[0], scale[1]];
        }
        queue.write_buffer(uniform_buffer, 0, bytemuck::bytes_of(&uniform));
        let attachment = depth.create_view(&wgpu::TextureViewDescriptor::default());
        let sampled = depth.create_view(&wgpu::TextureViewDescriptor {
            label: Some("umbra receiver map depth"),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("umbra receiver map"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.normal_buffer().as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: map.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&sampled) },
            ],
        });
        // Reason: every cell starts empty (the word 0 is below every encoded value).
        encoder.clear_buffer(map, 0, Some(4 * cells));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("umbra receiver map scatter"),
            color_attachments: &[],
            // Reason: read-only depth (and stencil): the pass needs an attachment of the
            // frame's size, and the same texture is read as a texture in it.
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &attachment,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(q) = queries {
            pass.begin_pipeline_statistics_query(&q.set, 0);
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_vertex_buffer(0, scene.position_buffer().slice(..));
        pass.set_index_buffer(scene.index_buffer().slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..scene.index_count(), 0, 0..1);
        if queries.is_some() {
            pass.end_pipeline_statistics_query();
        }
        Ok(())
    }

    /// Bytes of the scatter's uniform buffer.
    pub(crate) fn uniform_bytes() -> u64 {
        std::mem::size_of::<ScatterUniform>() as u64
    }
}
