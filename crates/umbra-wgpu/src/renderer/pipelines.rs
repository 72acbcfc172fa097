//! The scene pipelines of the stand-alone frame: depth + ambient (with and without the
//! world-position and triangle-id attachments) and the per-light lighting (with and without the
//! lit mask), with their bind group layouts.

use crate::builders::{storage_entry, uniform_entry};
use crate::common::Common;

use super::COLOR_FORMAT;

const SCENE: &str = include_str!("../shaders/scene.wgsl");

/// The scene pipelines for one depth-stencil format.
pub(super) struct ScenePipelines {
    /// Group 0 of both passes: the frame uniform and the triangle normals.
    pub(super) frame_layout: wgpu::BindGroupLayout,
    /// Group 1 of the lighting pass: one light's slot (dynamic offset).
    pub(super) light_layout: wgpu::BindGroupLayout,
    /// [without, with] the world-position and triangle-id attachments.
    pub(super) depth: [wgpu::RenderPipeline; 2],
    /// [without, with] the lit mask.
    pub(super) lighting: [wgpu::RenderPipeline; 2],
}

impl ScenePipelines {
    pub(super) fn new(device: &wgpu::Device, depth_format: wgpu::TextureFormat) -> Self {
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra frame"),
            entries: &[uniform_entry(0, vf, false), storage_entry(1, wgpu::ShaderStages::FRAGMENT, true)],
        });
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra lighting light"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::FRAGMENT, true)],
        });
        let module = Common::module(device, "scene.wgsl", &["enable primitive_index;", SCENE]);
        let depth_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra depth"),
            bind_group_layouts: &[Some(&frame_layout)],
            immediate_size: 0,
        });
        let lighting_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("umbra lighting"),
            bind_group_layouts: &[Some(&frame_layout), Some(&light_layout)],
            immediate_size: 0,
        });
        let vertex = wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_scene"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &[wgpu::VertexAttribute {
                    format: wgpu::VertexFormat::Float32x3,
                    offset: 0,
                    shader_location: 0,
                }],
            })],
        };
        let primitive = wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            strip_index_format: None,
            // Reason: the stored normal is that of the counter-clockwise winding.
            front_face: wgpu::FrontFace::Ccw,
            // Reason: triangle soups are two-sided; every triangle is visible from both sides.
            cull_mode: None,
            // Reason: the scene uses normal near clipping; only volumes need clamping.
            unclipped_depth: false,
            polygon_mode: wgpu::PolygonMode::Fill,
            conservative: false,
        };
        // The depth and lighting pipelines differ in their depth-stencil state, fragment entry
        // and colour targets only.
        let pipeline = |label, layout, depth_stencil, entry, targets: &[Option<wgpu::ColorTargetState>]| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: vertex.clone(),
                primitive,
                depth_stencil: Some(depth_stencil),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let depth_pipelines = [false, true].map(|capture| {
            let mut targets = vec![Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                // Reason: opaque ambient base colour.
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })];
            if capture {
                for format in [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::R32Uint] {
                    targets.push(Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    }));
                }
            }
            pipeline(
                if capture { "umbra depth+ambient+captures" } else { "umbra depth+ambient" },
                &depth_layout,
                wgpu::DepthStencilState {
                    format: depth_format,
                    depth_write_enabled: Some(true),
                    // Reason: nearest surface wins (reversed-Z: GREATER); ties keep the first
                    // triangle drawn (strict), the one the lighting pass's EQUAL selects.
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    // Reason: the stencil belongs to the per-light volume passes.
                    stencil: wgpu::StencilState::default(),
                    // Reason: depths must match the lighting pass and the volumes exactly.
                    bias: wgpu::DepthBiasState::default(),
                },
                if capture { "fs_depth" } else { "fs_depth_color" },
                &targets,
            )
        });
        let one_per_pixel = wgpu::StencilFaceState {
            // Reason: lit where the count is 0.
            compare: wgpu::CompareFunction::Equal,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            // Reason: the first fragment shaded at a pixel bumps the stencil to 1, so a
            // coplanar duplicate triangle (common in soups) cannot add this light twice.
            pass_op: wgpu::StencilOperation::IncrementWrap,
        };
        let additive = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let lighting_pipelines = [false, true].map(|lit_mask| {
            let mut targets = vec![Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                // Reason: each light adds its diffuse + specular onto ambient + earlier lights.
                blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                // Reason: alpha keeps pass 1's coverage value 1.
                write_mask: wgpu::ColorWrites::COLOR,
            })];
            if lit_mask {
                targets.push(Some(wgpu::ColorTargetState {
                    format: wgpu::TextureFormat::R8Unorm,
                    // Reason: min(1, dst + src) with src in {0, 1}: an OR, so a second fragment
                    // of a pixel cannot clear the bit.
                    blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
                    write_mask: wgpu::ColorWrites::RED,
                }));
            }
            pipeline(
                if lit_mask { "umbra lighting+lit mask" } else { "umbra lighting" },
                &lighting_layout,
                wgpu::DepthStencilState {
                    format: depth_format,
                    // Reason: depth is final after pass 1.
                    depth_write_enabled: Some(false),
                    // Reason: shade exactly the surface pass 1 left visible (the same invariant
                    // vertex shader gives bit-identical depths).
                    depth_compare: Some(wgpu::CompareFunction::Equal),
                    stencil: wgpu::StencilState {
                        front: one_per_pixel,
                        back: one_per_pixel,
                        read_mask: 0xFF,
                        write_mask: 0xFF,
                    },
                    bias: wgpu::DepthBiasState::default(),
                },
                if lit_mask { "fs_lighting" } else { "fs_lighting_color" },
                &targets,
            )
        });
        Self { frame_layout, light_layout, depth: depth_pipelines, lighting: lighting_pipelines }
    }
}
