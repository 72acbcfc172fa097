//! The GPU cull of the GPU silhouette methods: per light and frame, which pieces of the caster
//! (triangles joined across shared edges, [`caster_pieces`]) may shadow a visible sample,
//! found without a read-back. The host's visible samples are scattered into the light's
//! receiver map (`receivers.rs`, as `cpu-silhouette`'s cull does), then `shaders/cull.wgsl`
//! raises the eye's near pyramid under z-pass, builds the map's max pyramid and marks the
//! pieces a triangle of which has a cell beyond it in its frustum; `cs-silhouette`'s
//! orientation pass then gives the other pieces' triangles orientation 0.
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004, Section 4.1), culling
//! only: the volumes kept are drawn whole, to infinity. The proof: docs/exactness.md,
//! "Volumes culled on the GPU".
//!
//! Buffers: the map and its pyramid (a point light's six faces, 2.0 MiB), per light the
//! scatter's and the cull's uniforms; per mesh (the method's) the pieces and their flags.

use umbra_geom::camera::{zpass_start_points, DepthConvention};
use umbra_geom::receivers::{gpu_cull_level_offsets, gpu_cull_words, ReceiverGrid, GPU_CULL_WORDS, RECEIVER_SIDE};
use umbra_geom::silhouette::caster_pieces;
use umbra_geom::Aabb;

use crate::builders::{compute_pipeline, dispatch_size, storage_entry, uniform_entry, LIGHT_SLOT_BYTES};
use crate::common::Common;
use crate::error::WgpuError;
use crate::methods::LightFrame;
use crate::receivers::ReceiverPass;
use crate::scene::{buffer_zeroed, SceneGpu};

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const SHADER: &str = include_str!("../shaders/cull.wgsl");
const RECEIVER_CELL: &str = include_str!("../shaders/receiver_cell.wgsl");

/// Levels of the pyramid: the map's side, halved down to one cell.
const LEVELS: u32 = RECEIVER_SIDE.trailing_zeros() + 1;

/// `CullLevel` of shaders/cull.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CullLevel {
    src: u32,
    dst: u32,
    side: u32,
    pad: u32,
}

/// Word offset of every level of the pyramid, then its words ([`gpu_cull_level_offsets`]).
fn level_offsets() -> Vec<u32> {
    gpu_cull_level_offsets(RECEIVER_SIDE)
}

/// The pieces of one mesh and their flags, which the method's orientation pass reads.
pub(crate) struct CullMesh {
    /// Per triangle, its piece.
    pub(crate) piece: wgpu::Buffer,
    /// Word 0 the triangles kept, word 1 + p whether piece p is needed.
    pub(crate) needed: wgpu::Buffer,
}

impl CullMesh {
    /// The pieces of `scene`'s mesh, uploaded.
    pub(crate) fn new(device: &wgpu::Device, scene: &SceneGpu) -> Result<Self, WgpuError> {
        let (piece, pieces) = caster_pieces(scene.triangle_count(), scene.adjacency(), scene.slots()?.as_ref());
        let storage = wgpu::BufferUsages::STORAGE;
        // An empty mesh still binds a buffer of one word.
        let words = if piece.is_empty() { vec![0] } else { piece };
        Ok(Self {
            piece: crate::scene::buffer_init(device, "umbra cull pieces", bytemuck::cast_slice(&words), storage)?,
            needed: buffer_zeroed(
                device,
                "umbra cull needed",
                4 * (1 + u64::from(pieces)),
                storage | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            )?,
        })
    }

    /// Bytes held.
    pub(crate) fn bytes(&self) -> u64 {
        self.piece.size() + self.needed.size()
    }
}

/// One light's uniforms.
struct CullLight {
    scatter: wgpu::Buffer,
    grid: wgpu::Buffer,
}

/// See the module documentation.
pub(crate) struct GpuCull {
    /// The scatter (made on the first culled frame, for the caller's depth format).
    receivers: Option<ReceiverPass>,
    layout: wgpu::BindGroupLayout,
    raise: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    need: wgpu::ComputePipeline,
    /// One [`CullLevel`] per level built, a slot apart.
    levels_group: wgpu::BindGroup,
    levels: wgpu::Buffer,
    cells: wgpu::Buffer,
    lights: Vec<CullLight>,
}

impl GpuCull {
    /// The pipelines, the pyramid and the level uniforms.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Result<Self, WgpuError> {
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra cull"),
            entries: &[
                uniform_entry(0, compute, false),
                storage_entry(1, compute, false),
                storage_entry(2, compute, true),
                storage_entry(3, compute, true),
                storage_entry(4, compute, true),
                storage_entry(5, compute, false),
            ],
        });
        let level_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("umbra cull level"),
            entries: &[uniform_entry(0, compute, true)],
        });
        let module = Common::module(device, "cull.wgsl", &["enable clip_distances;", VOLUME, RECEIVER_CELL, SHADER]);
        let pipeline_layout = common.pipeline_layout(device, "umbra cull", &[&layout, &level_layout]);
        let pipeline = |entry| compute_pipeline(device, "umbra cull", &pipeline_layout, &module, entry);
        let offsets = level_offsets();
        let mut slots = vec![0u8; (LEVELS as usize - 1) * LIGHT_SLOT_BYTES as usize];
        for k in 1..LEVELS as usize {
            let level = CullLevel { src: offsets[k - 1], dst: offsets[k], side: RECEIVER_SIDE >> k, pad: 0 };
            let at = (k - 1) * LIGHT_SLOT_BYTES as usize;
            slots[at..at + std::mem::size_of::<CullLevel>()].copy_from_slice(bytemuck::bytes_of(&level));
        }
        let levels = crate::scene::buffer_init(device, "umbra cull levels", &slots, wgpu::BufferUsages::UNIFORM)?;
        let levels_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("umbra cull levels"),
            layout: &level_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &levels,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<CullLevel>() as u64),
                }),
            }],
        });
        Ok(Self {
            receivers: None,
            raise: pipeline("raise"),
            reduce: pipeline("reduce"),
            need: pipeline("need"),
            layout,
            levels_group,
            levels,
            cells: buffer_zeroed(
                device,
                "umbra cull pyramid",
                4 * u64::from(offsets[LEVELS as usize]),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            )?,
            lights: Vec::new(),
        })
    }

    /// Bytes held.
    pub(crate) fn bytes(&self) -> u64 {
        self.cells.size()
            + self.levels.size()
            + self.lights.iter().map(|l| l.scatter.size() + l.grid.size()).sum::<u64>()
            + self.receivers.as_ref().map_or(0, ReceiverPass::gpu_bytes)
    }

    /// Records light `frame.slot`'s cull into `encoder` (after the caller's depth, `depth`,
    /// was submitted; the light's uniform slot written): `mesh.needed` then marks the pieces
    /// needed, with word 0 cleared for the orientation pass to count the triangles kept.
    /// `false` (nothing recorded) where the cull cannot be exact for this light: under z-pass,
    /// a point light's near pyramid that no one face of the map bounds.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame<'_>,
        depth: &wgpu::Texture,
        bounds: Aabb,
        mesh: &CullMesh,
    ) -> Result<bool, WgpuError> {
        let light = frame.data.light;
        let grid = ReceiverGrid::new(light, bounds, RECEIVER_SIDE);
        let view = frame.view;
        // z-pass starts every count at the eye's near rectangle: its cells are raised to its
        // farthest point, so a triangle whose frustum holds a point of it is kept (the same
        // as cpu-silhouette's ReceiverMap::raise_hull).
        let raise = if frame.plan.zpass {
            match grid.hull_raise(&zpass_start_points(&view.world_from_clip, view.eye, DepthConvention::ReversedZ)) {
                Some(r) => Some(r),
                None => return Ok(false),
            }
        } else {
            None
        };
        if self.receivers.as_ref().is_none_or(|r| r.format() != depth.format()) {
            self.receivers = Some(ReceiverPass::new(device, depth.format()));
        }
        while self.lights.len() <= frame.slot {
            let uniform = |label, bytes| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            };
            self.lights.push(CullLight {
                scatter: uniform("umbra cull scatter", ReceiverPass::uniform_bytes()),
                grid: uniform("umbra cull grid", 4 * GPU_CULL_WORDS as u64),
            });
        }
        let l = &self.lights[frame.slot];
        let scatter = self.receivers.as_ref().expect("made above");
        scatter.record(device, queue, encoder, scene, view, light, &grid, depth, &l.scatter, &self.cells, None)?;

        let words = gpu_cull_words(&grid, raise);
        queue.write_buffer(&l.grid, 0, bytemuck::cast_slice(&words));
        let buffers = [&l.grid, &self.cells, scene.position_buffer(), scene.index_buffer(), &mesh.piece, &mesh.needed];
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("umbra cull"),
            layout: &self.layout,
            entries: &entries,
        });
        // Reason: no piece is needed and no triangle kept until this light's passes say so.
        encoder.clear_buffer(&mesh.needed, 0, None);
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("umbra cull"), timestamp_writes: None });
        common.bind_slot_compute(&mut pass, frame.slot);
        pass.set_bind_group(1, &group, &[]);
        // Each dispatch is its own synchronisation scope: each level reads the one before.
        if let Some((_, [i0, i1, j0, j1], _)) = raise {
            pass.set_pipeline(&self.raise);
            pass.set_bind_group(2, &self.levels_group, &[0]);
            let (x, y) = dispatch_size((i1 - i0 + 1) * (j1 - j0 + 1));
            pass.dispatch_workgroups(x, y, 1);
        }
        pass.set_pipeline(&self.reduce);
        for k in 1..LEVELS {
            pass.set_bind_group(2, &self.levels_group, &[((k - 1) as u64 * LIGHT_SLOT_BYTES) as u32]);
            let side = RECEIVER_SIDE >> k;
            let (x, y) = dispatch_size(grid.faces() * side * side);
            pass.dispatch_workgroups(x, y, 1);
        }
        if frame.data.triangles > 0 {
            pass.set_pipeline(&self.need);
            pass.set_bind_group(2, &self.levels_group, &[0]);
            let (x, y) = dispatch_size(frame.data.triangles);
            pass.dispatch_workgroups(x, y, 1);
        }
        Ok(true)
    }
}
