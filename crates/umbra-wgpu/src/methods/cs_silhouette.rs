//! `cs-silhouette` on wgpu: silhouette shadow volumes found by compute shaders and drawn with
//! indirect draws, no CPU round trip.
//!
//! Paper 001 (Milet, Kobrtek, Zemčík), Section 2.2-2.3 and its future work (a compute-shader
//! silhouette): edge multiplicity with the reference edge (Alg. 3-4), sides extruded with
//! Eq. 2, caps oriented by the same test; light caps pushed to the far plane (paper 003,
//! Eq. 6) with the infinite far plane; z-fail with caps at infinity, z-pass where
//! [`crate::ShadowVolumes`] proves it exact. The twin of umbra-gl's `cs-silhouette` with one
//! change WGSL forces (it has no `precise`): every triangle's orientation is computed ONCE per
//! light in its own pass, and the sides sum those values instead of evaluating Alg. 4 per
//! (edge, opposite) pair (see shaders/multiplicity.wgsl).
//!
//! Once per mesh (`prepare_scene`): per edge record `(A, B, first slot, count)` and
//! the slots (the triangle behind each of the edge's opposite vertices and its direction,
//! [`umbra_geom::silhouette::TriangleSlots`]) in storage buffers. An edge with more than
//! [`MAX_TRIANGLES_PER_RECORD`] triangles is split into several records (Mesa's gallivm, which
//! runs lavapipe as it runs llvmpipe, silently ends a shader loop after 65,535 iterations);
//! each record emits the quads of its partial multiplicity with its own sign, and the stencil
//! counts of an edge's records add up to its multiplicity.
//!
//! Per light (its own buffers, so every light of a frame is prepared before any is drawn):
//! 1. both indirect commands reset to `{0 vertices, 1 instance}` (a copy in the encoder);
//! 2. "orientation" (shaders/orientation.wgsl): one invocation per triangle writes its
//!    orientation and, under z-fail, its cap (three vertex indices wound to face the light,
//!    compacted with an atomic counter in the caps command);
//! 3. "silhouette" (shaders/cs_sides.wgsl): one invocation per edge record sums the
//!    orientations of its triangles and writes `|m|` quad records `(X, Y)`, compacted the same
//!    way in the sides command;
//! 4. "transform" (shaders/transform.wgsl): every vertex to clip space, as a point and
//!    extruded to infinity, once: sides and caps read these, so their shared vertices are the
//!    same bits (the same reason as the orientation pass, for positions);
//! 5. in the caller's pass: two indirect draws (shaders/cs_draw.wgsl) with the counting state.
//!
//! Given the caller's depth ([`crate::VolumeFrame::receivers`]), the volume is culled on the
//! GPU before step 2 (`gpu_cull.rs`, shaders/cull.wgsl): the visible samples scattered into
//! the light's receiver map, and every piece of the caster (triangles joined across shared
//! edges) that no visible sample lies behind marked unneeded; the orientation pass
//! (`orient_kept` entries) gives its triangles orientation 0, so they cast no side and no cap.
//! Nothing is read back: the frame stays one submission after the depth.
//!
//! Buffers per light, sized for the worst case: orientation 4 bytes per triangle, quads 8
//! bytes per opposite vertex (`Σ|m| <= Σk`), caps 12 bytes per triangle, two 16-byte commands,
//! clip positions 32 bytes per vertex.

use umbra_geom::sides_data::record_ranges;
use umbra_geom::EdgeAdjacency;

use crate::builders::{buffers_group, compute_pipeline, dispatch_size, storage_entry};
use crate::common::{Common, LightPlan};
use crate::error::WgpuError;
use crate::methods::gpu_cull::{CullMesh, GpuCull};
use crate::methods::method::{DrawnVolume, LightFrame, Method, MethodKind};
use crate::methods::transform::{ClipPositions, Transform};
use crate::scene::{buffer_init, buffer_zeroed, SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "cs-silhouette";

/// Most triangles one invocation of the sides pass loops over (one edge record): far below
/// gallivm's 65,535 iterations per shader loop, and the quad-writing loop besides it.
pub const MAX_TRIANGLES_PER_RECORD: u32 = 16_384;

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const MULTIPLICITY: &str = include_str!("../shaders/multiplicity.wgsl");
const ORIENTATION: &str = include_str!("../shaders/orientation.wgsl");
const SIDES: &str = include_str!("../shaders/cs_sides.wgsl");
const DRAW: &str = include_str!("../shaders/cs_draw.wgsl");

/// Bytes of one draw-indirect command (vertex count, instance count, first vertex, first instance).
const COMMAND_BYTES: u64 = 16;

/// The edge records of `adj`, split at `max` triangles ([`record_ranges`]): `(A, B, first
/// slot, count)` with at least one record per edge (an edge without triangles contributes
/// nothing).
pub fn edge_records(adj: &EdgeAdjacency, max: u32) -> Vec<[u32; 4]> {
    record_ranges(adj, max as usize)
        .map(|r| {
            let [a, b] = adj.edges[r.edge];
            [a, b, r.first, r.count]
        })
        .collect()
}

/// Per-mesh buffers.
struct Mesh {
    scene: SceneId,
    records: wgpu::Buffer,
    slots: wgpu::Buffer,
    record_count: u32,
    opposites: u64,
    /// The caster's pieces and their flags, for the GPU cull.
    cull: CullMesh,
}

/// One light's outputs.
struct PerLight {
    orientation: wgpu::Buffer,
    sides_command: wgpu::Buffer,
    caps_command: wgpu::Buffer,
    quads: wgpu::Buffer,
    caps: wgpu::Buffer,
    clip: ClipPositions,
    orient_group: wgpu::BindGroup,
    /// The orientation pass's bindings with the cull's pieces and flags.
    orient_kept_group: wgpu::BindGroup,
    sides_group: wgpu::BindGroup,
    draw_group: wgpu::BindGroup,
    /// The triangles kept by the last frame's cull (one word, copied from the flags).
    kept: wgpu::Buffer,
    /// Whether the last frame culled this light's volume, and the scene's triangles.
    culled: bool,
    triangles: u32,
}

impl PerLight {
    fn bytes(&self) -> u64 {
        [
            &self.orientation,
            &self.sides_command,
            &self.caps_command,
            &self.quads,
            &self.caps,
            &self.clip.buffer,
            &self.kept,
        ]
        .iter()
        .map(|b| b.size())
        .sum()
    }
}

/// See the module documentation.
pub struct CsSilhouette {
    orient_layout: wgpu::BindGroupLayout,
    orient_kept_layout: wgpu::BindGroupLayout,
    sides_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
    orient: wgpu::ComputePipeline,
    orient_and_caps: wgpu::ComputePipeline,
    orient_kept: wgpu::ComputePipeline,
    orient_kept_and_caps: wgpu::ComputePipeline,
    sides: wgpu::ComputePipeline,
    transform: Transform,
    /// [z-fail, z-pass].
    draw_sides: [wgpu::RenderPipeline; 2],
    draw_caps: wgpu::RenderPipeline,
    /// `{0, 1, 0, 0}`: copied over each command before its compute pass.
    reset: wgpu::Buffer,
    mesh: Option<Mesh>,
    lights: Vec<PerLight>,
    /// The GPU cull (made on the first culled frame).
    cull: Option<GpuCull>,
}

impl CsSilhouette {
    /// Pipelines for the pass formats of `common`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Self {
        let compute = wgpu::ShaderStages::COMPUTE;
        let layout = |label, entries: &[(bool,)]| {
            let entries: Vec<_> = entries
                .iter()
                .enumerate()
                .map(|(i, &(read_only,))| storage_entry(i as u32, compute, read_only))
                .collect();
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
        };
        // positions, indices, orientation, caps command, caps
        let orient_layout = layout("cs-silhouette orientation", &[(true,), (true,), (false,), (false,), (false,)]);
        // ... and the cull's pieces and flags (the orient_kept entries).
        let orient_kept_layout = layout(
            "cs-silhouette orientation after the cull",
            &[(true,), (true,), (false,), (false,), (false,), (true,), (false,)],
        );
        // records, slots, orientation, sides command, quads
        let sides_layout = layout("cs-silhouette sides", &[(true,), (true,), (true,), (false,), (false,)]);
        let vertex = wgpu::ShaderStages::VERTEX;
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cs-silhouette draw"),
            entries: &[storage_entry(0, vertex, true), storage_entry(1, vertex, true), storage_entry(2, vertex, true)],
        });
        let enable = "enable clip_distances;";
        let orient_module =
            Common::module(device, "cs-silhouette orientation.wgsl", &[enable, VOLUME, MULTIPLICITY, ORIENTATION]);
        let sides_module = Common::module(device, "cs-silhouette cs_sides.wgsl", &[enable, VOLUME, SIDES]);
        let draw_module = Common::module(device, "cs-silhouette cs_draw.wgsl", &[enable, VOLUME, DRAW]);
        let orient_pl = common.pipeline_layout(device, "cs-silhouette orientation", &[&orient_layout]);
        let orient = compute_pipeline(device, "cs-silhouette orient", &orient_pl, &orient_module, "orient");
        let orient_and_caps =
            compute_pipeline(device, "cs-silhouette orient+caps", &orient_pl, &orient_module, "orient_and_caps");
        let kept_pl =
            common.pipeline_layout(device, "cs-silhouette orientation after the cull", &[&orient_kept_layout]);
        let orient_kept =
            compute_pipeline(device, "cs-silhouette orient kept", &kept_pl, &orient_module, "orient_kept");
        let orient_kept_and_caps = compute_pipeline(
            device,
            "cs-silhouette orient kept+caps",
            &kept_pl,
            &orient_module,
            "orient_kept_and_caps",
        );
        let sides_pl = common.pipeline_layout(device, "cs-silhouette sides", &[&sides_layout]);
        let sides = compute_pipeline(device, "cs-silhouette sides", &sides_pl, &sides_module, "sides");
        let draw_pl = common.pipeline_layout(device, "cs-silhouette draw", &[&draw_layout]);
        let ccw = wgpu::FrontFace::Ccw;
        let draw_sides = [false, true].map(|zpass| {
            common.counting_pipeline(device, "cs-silhouette sides", &draw_module, "vs_sides", &draw_pl, &[], zpass, ccw)
        });
        let draw_caps =
            common.counting_pipeline(device, "cs-silhouette caps", &draw_module, "vs_caps", &draw_pl, &[], false, ccw);
        let reset = buffer_init(
            device,
            "cs-silhouette command reset",
            bytemuck::cast_slice(&[0u32, 1, 0, 0]),
            wgpu::BufferUsages::COPY_SRC,
        )
        .expect("16 bytes fit every device");
        Self {
            transform: Transform::new(device, common),
            orient_layout,
            orient_kept_layout,
            sides_layout,
            draw_layout,
            orient,
            orient_and_caps,
            orient_kept,
            orient_kept_and_caps,
            sides,
            draw_sides,
            draw_caps,
            reset,
            mesh: None,
            lights: Vec::new(),
            cull: None,
        }
    }

    /// The buffers of lights `0..=slot` for `scene` (made on first use, per scene).
    fn per_light(&mut self, device: &wgpu::Device, scene: &SceneGpu, slot: usize) -> Result<(), WgpuError> {
        while self.lights.len() <= slot {
            let light = self.make_light(device, scene)?;
            self.lights.push(light);
        }
        Ok(())
    }

    /// One light's outputs and bind groups.
    fn make_light(&self, device: &wgpu::Device, scene: &SceneGpu) -> Result<PerLight, WgpuError> {
        let Some(mesh) = &self.mesh else {
            return Err(WgpuError::InvalidParams("cs-silhouette: per-light buffers before prepare_scene".into()));
        };
        let triangles = scene.triangle_count() as u64;
        let storage = wgpu::BufferUsages::STORAGE;
        let buffer = |label, bytes, usage| buffer_zeroed(device, label, bytes, usage);
        let command =
            storage | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        let orientation = buffer("cs-silhouette orientation", 4 * triangles, storage)?;
        let sides_command = buffer("cs-silhouette sides command", COMMAND_BYTES, command)?;
        let caps_command = buffer("cs-silhouette caps command", COMMAND_BYTES, command)?;
        let quads = buffer("cs-silhouette quads", 8 * mesh.opposites, storage)?;
        let caps = buffer("cs-silhouette caps", 12 * triangles, storage)?;
        let orient_group = buffers_group(
            device,
            "cs-silhouette orientation",
            &self.orient_layout,
            &[scene.position_buffer(), scene.index_buffer(), &orientation, &caps_command, &caps],
        );
        let orient_kept_group = buffers_group(
            device,
            "cs-silhouette orientation after the cull",
            &self.orient_kept_layout,
            &[
                scene.position_buffer(),
                scene.index_buffer(),
                &orientation,
                &caps_command,
                &caps,
                &mesh.cull.piece,
                &mesh.cull.needed,
            ],
        );
        let kept =
            buffer("cs-silhouette triangles kept", 4, wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC)?;
        let sides_group = buffers_group(
            device,
            "cs-silhouette sides",
            &self.sides_layout,
            &[&mesh.records, &mesh.slots, &orientation, &sides_command, &quads],
        );
        let clip = self.transform.buffers(device, scene)?;
        let draw_group = buffers_group(device, "cs-silhouette draw", &self.draw_layout, &[&clip.buffer, &quads, &caps]);
        Ok(PerLight {
            orientation,
            sides_command,
            caps_command,
            quads,
            caps,
            clip,
            orient_group,
            orient_kept_group,
            sides_group,
            draw_group,
            kept,
            culled: false,
            triangles: scene.triangle_count() as u32,
        })
    }
}

impl Method for CsSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Counting { silhouette_sides: true }
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.mesh.as_ref().map(|m| m.scene)
    }

    fn prepare_scene(&mut self, device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        self.mesh = None;
        self.lights.clear();
        let adj = scene.adjacency();
        let slots = scene.slots()?;
        let records = edge_records(adj, MAX_TRIANGLES_PER_RECORD);
        let opposites = adj.opposites.len() as u64;
        // 6 vertices per worst-case quad and per cap must fit one indirect draw's count.
        if u32::try_from(6 * opposites.max(scene.triangle_count() as u64)).is_err() {
            return Err(WgpuError::InvalidParams(format!(
                "cs-silhouette: {opposites} opposite vertices / {} triangles exceed one indirect draw",
                scene.triangle_count()
            )));
        }
        let storage = wgpu::BufferUsages::STORAGE;
        self.mesh = Some(Mesh {
            scene: scene.id(),
            records: buffer_init(device, "cs-silhouette edge records", bytemuck::cast_slice(&records), storage)?,
            slots: buffer_init(device, "cs-silhouette slots", bytemuck::cast_slice(slots.slots()), storage)?,
            record_count: records.len() as u32,
            opposites,
            cull: CullMesh::new(device, scene)?,
        });
        Ok(())
    }

    fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame,
    ) -> Result<(), WgpuError> {
        self.per_light(device, scene, frame.slot)?;
        let Some(mesh) = &self.mesh else {
            return Err(WgpuError::InvalidParams("cs-silhouette: prepare_light before prepare_scene".into()));
        };
        let mut data = frame.data;
        data.records = mesh.record_count;
        common.write_slot(queue, frame.slot, &data);
        // The cull first (its scatter is a render pass of its own), where the caller gave its
        // depth; a light it cannot cull exactly is drawn whole.
        let culled = match (frame.receivers, scene.bounds()) {
            (Some(depth), Some(bounds)) => {
                if self.cull.is_none() {
                    self.cull = Some(GpuCull::new(device, common)?);
                }
                let cull = self.cull.as_mut().expect("made above");
                cull.record(device, queue, encoder, scene, common, frame, depth, bounds, &mesh.cull)?
            }
            _ => false,
        };
        let l = &mut self.lights[frame.slot];
        l.culled = culled;
        for command in [&l.sides_command, &l.caps_command] {
            encoder.copy_buffer_to_buffer(&self.reset, 0, command, 0, COMMAND_BYTES);
        }
        let caps = !frame.plan.zpass;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cs-silhouette"),
                timestamp_writes: None,
            });
            common.bind_slot_compute(&mut pass, frame.slot);
            // Orientation once per triangle (and the caps under z-fail); each dispatch is its
            // own synchronisation scope in WebGPU, so the sides below see every orientation.
            if data.triangles > 0 {
                let pipeline = match (culled, caps) {
                    (false, false) => &self.orient,
                    (false, true) => &self.orient_and_caps,
                    (true, false) => &self.orient_kept,
                    (true, true) => &self.orient_kept_and_caps,
                };
                pass.set_pipeline(pipeline);
                pass.set_bind_group(1, if culled { &l.orient_kept_group } else { &l.orient_group }, &[]);
                let (x, y) = dispatch_size(data.triangles);
                pass.dispatch_workgroups(x, y, 1);
            }
            if mesh.record_count > 0 {
                pass.set_pipeline(&self.sides);
                pass.set_bind_group(1, &l.sides_group, &[]);
                let (x, y) = dispatch_size(mesh.record_count);
                pass.dispatch_workgroups(x, y, 1);
            }
            self.transform.dispatch(&mut pass, &l.clip, data.vertices);
        }
        if culled {
            // The count of the triangles kept, before the next light's cull clears it.
            encoder.copy_buffer_to_buffer(&mesh.cull.needed, 0, &l.kept, 0, 4);
        }
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan) {
        let Some(l) = self.lights.get(slot) else { return };
        common.bind_slot_render(pass, slot);
        pass.set_bind_group(1, &l.draw_group, &[]);
        pass.set_pipeline(&self.draw_sides[plan.zpass as usize]);
        pass.draw_indirect(&l.sides_command, 0);
        if !plan.zpass {
            pass.set_pipeline(&self.draw_caps);
            pass.draw_indirect(&l.caps_command, 0);
        }
    }

    fn copy_counts(&self, encoder: &mut wgpu::CommandEncoder, slot: usize, readback: &wgpu::Buffer) -> bool {
        let Some(l) = self.lights.get(slot) else { return false };
        encoder.copy_buffer_to_buffer(&l.sides_command, 0, readback, 0, COMMAND_BYTES);
        encoder.copy_buffer_to_buffer(&l.caps_command, 0, readback, COMMAND_BYTES, COMMAND_BYTES);
        encoder.copy_buffer_to_buffer(&l.kept, 0, readback, 2 * COMMAND_BYTES, 4);
        true
    }

    fn drawn_from_counts(&self, slot: usize, words: &[u32]) -> Option<DrawnVolume> {
        let l = self.lights.get(slot)?;
        Some(DrawnVolume {
            triangles: u64::from(if l.culled { words[8] } else { l.triangles }),
            // Six vertices per side quad, one quad per unit of |m|.
            edges: u64::from(words[0] / 6),
            culled: l.culled,
            clamped: false,
        })
    }

    fn culls_volumes(&self) -> bool {
        true
    }

    fn gpu_bytes(&self) -> u64 {
        let mesh = self.mesh.as_ref().map_or(0, |m| m.records.size() + m.slots.size() + m.cull.bytes());
        mesh + self.lights.iter().map(PerLight::bytes).sum::<u64>() + self.cull.as_ref().map_or(0, GpuCull::bytes)
    }
}
