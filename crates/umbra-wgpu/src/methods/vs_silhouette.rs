//! `vs-silhouette` on wgpu: silhouette shadow volumes evaluated in the vertex shader, paper 003
//! (Milet et al., "Fast robust and precise shadow algorithm for WebGL 1.0 platform"),
//! Section 2: sides by Algorithm 1, caps by Algorithm 2 with the light cap shifted to infinity
//! (Eq. 6) and the infinite far plane; multiplicity by paper 001's reference edge. The twin of
//! umbra-gl's `vs-silhouette`: the same `maxMult`
//! ([`umbra_geom::sides_data::choose_max_mult`] with [`MAX_MULT_LIMIT`]), the same records
//! (an edge with more opposite vertices split into several, whose sub-multiplicities add up),
//! the same fixed 6 · maxMult vertices per record with useless ones culled, the same
//! triangles per side (shaders/vs_draw.wgsl).
//!
//! One change WGSL forces (it has no `precise`): the vertex shaders do not evaluate Alg. 4
//! from positions (paper 003's sides-data); a compute pass orients every triangle once per
//! light (shaders/orientation.wgsl) and the records name the triangles behind their opposite
//! vertices ([`umbra_geom::silhouette::TriangleSlots`]), so every vertex of a record and every
//! cap reads the same orientation; likewise every vertex is transformed to clip space once per
//! light, as a point and extruded (shaders/transform.wgsl), and the vertex shaders only pick
//! those clip positions, so sides and caps share bit-identical vertices. Per mesh: records `(A, B, first slot, count | split << 8)`
//! (16 bytes) and the slots (4 bytes per opposite) instead of Eq. 8's `16 (2 + maxMult)` bytes
//! per record; the caps read the scene's index buffer instead of Eq. 9's caps-data. Per light:
//! the orientations (4 bytes per triangle) and clip positions (32 bytes per vertex).

use umbra_geom::sides_data::{choose_max_mult, record_ranges, MAX_MULT_LIMIT};
use umbra_geom::EdgeAdjacency;

use crate::builders::{buffers_group, compute_pipeline, dispatch_size, storage_entry};
use crate::common::{Common, LightPlan};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::methods::transform::{ClipPositions, Transform};
use crate::scene::{buffer_init, buffer_zeroed, SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "vs-silhouette";

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const MULTIPLICITY: &str = include_str!("../shaders/multiplicity.wgsl");
const ORIENTATION: &str = include_str!("../shaders/orientation.wgsl");
const DRAW: &str = include_str!("../shaders/vs_draw.wgsl");

/// The records of `adj` at `max_mult` slots each: `(A, B, first slot, count | split << 8)`,
/// an edge with more opposites split into consecutive chunks (umbra_geom::sides_data's split,
/// [`record_ranges`]); an edge without opposites keeps one empty record.
pub fn records(adj: &EdgeAdjacency, max_mult: usize) -> Vec<[u32; 4]> {
    record_ranges(adj, max_mult)
        .map(|r| {
            let [a, b] = adj.edges[r.edge];
            [a, b, r.first, r.count | u32::from(r.split) << 8]
        })
        .collect()
}

struct Mesh {
    scene: SceneId,
    max_mult: u32,
    record_count: u32,
    records: wgpu::Buffer,
    slots: wgpu::Buffer,
}

struct PerLight {
    /// Triangles x cap vertices per triangle (6 for a point light, 3 for a directional one).
    cap_vertices: u32,
    orientation: wgpu::Buffer,
    clip: ClipPositions,
    orient_group: wgpu::BindGroup,
    draw_group: wgpu::BindGroup,
}

/// See the module documentation.
pub struct VsSilhouette {
    orient_layout: wgpu::BindGroupLayout,
    draw_layout: wgpu::BindGroupLayout,
    orient: wgpu::ComputePipeline,
    transform: Transform,
    /// [z-fail, z-pass].
    sides: [wgpu::RenderPipeline; 2],
    caps: wgpu::RenderPipeline,
    mesh: Option<Mesh>,
    lights: Vec<PerLight>,
}

impl VsSilhouette {
    /// Pipelines for the pass formats of `common`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Self {
        let compute = wgpu::ShaderStages::COMPUTE;
        // positions, indices, orientation (orientation.wgsl's `orient` uses only these three).
        let orient_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vs-silhouette orientation"),
            entries: &[
                storage_entry(0, compute, true),
                storage_entry(1, compute, true),
                storage_entry(2, compute, false),
            ],
        });
        let vertex = wgpu::ShaderStages::VERTEX;
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vs-silhouette draw"),
            entries: &(0..5).map(|i| storage_entry(i, vertex, true)).collect::<Vec<_>>(),
        });
        let enable = "enable clip_distances;";
        let orient_module =
            Common::module(device, "vs-silhouette orientation.wgsl", &[enable, VOLUME, MULTIPLICITY, ORIENTATION]);
        let draw_module = Common::module(device, "vs-silhouette vs_draw.wgsl", &[enable, VOLUME, DRAW]);
        let orient_pl = common.pipeline_layout(device, "vs-silhouette orientation", &[&orient_layout]);
        let orient = compute_pipeline(device, "vs-silhouette orient", &orient_pl, &orient_module, "orient");
        let draw_pl = common.pipeline_layout(device, "vs-silhouette draw", &[&draw_layout]);
        let ccw = wgpu::FrontFace::Ccw;
        let sides = [false, true].map(|zpass| {
            common.counting_pipeline(device, "vs-silhouette sides", &draw_module, "vs_sides", &draw_pl, &[], zpass, ccw)
        });
        let caps =
            common.counting_pipeline(device, "vs-silhouette caps", &draw_module, "vs_caps", &draw_pl, &[], false, ccw);
        Self {
            transform: Transform::new(device, common),
            orient_layout,
            draw_layout,
            orient,
            sides,
            caps,
            mesh: None,
            lights: Vec::new(),
        }
    }

    fn make_light(&self, device: &wgpu::Device, scene: &SceneGpu) -> Result<PerLight, WgpuError> {
        let Some(mesh) = &self.mesh else {
            return Err(WgpuError::InvalidParams("vs-silhouette: per-light buffers before prepare_scene".into()));
        };
        let bytes = 4 * scene.triangle_count() as u64;
        let orientation = buffer_zeroed(device, "vs-silhouette orientation", bytes, wgpu::BufferUsages::STORAGE)?;
        let orient_group = buffers_group(
            device,
            "vs-silhouette orientation",
            &self.orient_layout,
            &[scene.position_buffer(), scene.index_buffer(), &orientation],
        );
        let clip = self.transform.buffers(device, scene)?;
        let draw_group = buffers_group(
            device,
            "vs-silhouette draw",
            &self.draw_layout,
            &[&clip.buffer, &mesh.records, &mesh.slots, &orientation, scene.index_buffer()],
        );
        Ok(PerLight { cap_vertices: 0, orientation, clip, orient_group, draw_group })
    }
}

impl Method for VsSilhouette {
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
        let max_mult = choose_max_mult(adj, MAX_MULT_LIMIT).max(1);
        let records = records(adj, max_mult);
        let vertices = 6 * max_mult as u64 * records.len() as u64;
        if u32::try_from(vertices).is_err() || u32::try_from(6 * scene.triangle_count()).is_err() {
            return Err(WgpuError::InvalidParams(format!(
                "vs-silhouette: {} records x {} vertices exceed one draw",
                records.len(),
                6 * max_mult
            )));
        }
        let storage = wgpu::BufferUsages::STORAGE;
        self.mesh = Some(Mesh {
            scene: scene.id(),
            max_mult: max_mult as u32,
            record_count: records.len() as u32,
            records: buffer_init(device, "vs-silhouette records", bytemuck::cast_slice(&records), storage)?,
            slots: buffer_init(device, "vs-silhouette slots", bytemuck::cast_slice(slots.slots()), storage)?,
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
        while self.lights.len() <= frame.slot {
            let light = self.make_light(device, scene)?;
            self.lights.push(light);
        }
        let Some(mesh) = &self.mesh else {
            return Err(WgpuError::InvalidParams("vs-silhouette: prepare_light before prepare_scene".into()));
        };
        let mut data = frame.data;
        data.records = mesh.record_count;
        data.max_mult = mesh.max_mult;
        common.write_slot(queue, frame.slot, &data);
        self.lights[frame.slot].cap_vertices = data.triangles * data.vertices_per_cap;
        if data.triangles > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("vs-silhouette"),
                timestamp_writes: None,
            });
            common.bind_slot_compute(&mut pass, frame.slot);
            pass.set_pipeline(&self.orient);
            pass.set_bind_group(1, &self.lights[frame.slot].orient_group, &[]);
            let (x, y) = dispatch_size(data.triangles);
            pass.dispatch_workgroups(x, y, 1);
            self.transform.dispatch(&mut pass, &self.lights[frame.slot].clip, data.vertices);
        }
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan) {
        let (Some(mesh), Some(l)) = (&self.mesh, self.lights.get(slot)) else { return };
        common.bind_slot_render(pass, slot);
        pass.set_bind_group(1, &l.draw_group, &[]);
        if mesh.record_count > 0 {
            pass.set_pipeline(&self.sides[plan.zpass as usize]);
            pass.draw(0..6 * mesh.max_mult * mesh.record_count, 0..1);
        }
        if !plan.zpass && l.cap_vertices > 0 {
            pass.set_pipeline(&self.caps);
            pass.draw(0..l.cap_vertices, 0..1);
        }
    }

    fn gpu_bytes(&self) -> u64 {
        let mesh = self.mesh.as_ref().map_or(0, |m| m.records.size() + m.slots.size());
        mesh + self.lights.iter().map(|l| l.orientation.size() + l.clip.buffer.size()).sum::<u64>()
    }
}
