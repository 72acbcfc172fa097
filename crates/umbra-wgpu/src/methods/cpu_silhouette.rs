//! `cpu-silhouette` on wgpu: silhouette shadow volumes built on the CPU every frame.
//!
//! Paper 001, Sections 2.2-2.3 (deterministic edge multiplicity with a reference edge,
//! Alg. 2-4; sides extruded with Eq. 2; caps oriented by the same test), via
//! [`umbra_geom::silhouette::extract_indexed`] (rayon-parallel, every triangle oriented once,
//! orientations summed per edge through the mesh's [`umbra_geom::silhouette::TriangleSlots`]):
//! the twin of umbra-gl's `cpu-silhouette`. Rust never contracts `a * b + c`, so the CPU's
//! orientations are the same bits wherever they are read.
//!
//! Per light and frame: extract into a reused [`IndexedVolume`], expand it to its very
//! vertices ([`IndexedVolume::expand_into`]: sides, light caps, dark caps as homogeneous world
//! positions) and upload them into the light's own buffer (grown geometrically, never
//! shrunk); in the caller's pass ONE draw with one vertex shader (shaders/cpu_draw.wgsl), so
//! a vertex shared by a side and a cap is transformed by the same code into the same bits.
//! umbra-gl draws the caps from the mesh's positions with 12 bytes of indices per cap and
//! relies on GLSL's `invariant`; WGSL has no such guarantee, so wgpu pays 48 (directional) or
//! 96 (point light) bytes per cap.
//!
//! Given the caller's depth ([`crate::VolumeFrame::receivers`]), each light's volume is culled
//! and clamped against its receivers as umbra-gl's is (CC shadow volumes, Lloyd et al. EGSR
//! 2004; docs/exactness.md, "Volumes clamped to their receivers"): the visible samples are
//! scattered into the light's receiver map on the GPU (`receivers.rs`), read back, and
//! [`ReceiverMap::cull_and_clamp`](umbra_geom::receivers::ReceiverMap::cull_and_clamp) keeps
//! the triangles whose frusta may hold a visible sample and ends each vertex's volume beyond
//! the farthest of them; [`extract_kept`] extracts the kept triangles' silhouette, clamped
//! where that costs fewer fragments. The far caps that close it are drawn with the sides'
//! vertex shader, after the light caps (no dark caps: a far cap at infinity is one).

use umbra_geom::camera::{zpass_start_points, DepthConvention};
use umbra_geom::clearance::scene_clip_box;
use umbra_geom::receivers::ReceiverMap;
use umbra_geom::silhouette::{
    extract_indexed, extract_kept, DrawnVolume, IndexedVolume, ScreenClip, VolumeClamp, VolumeGeometry,
};

use crate::common::{Common, LightPlan};
use crate::error::WgpuError;
use crate::methods::method::{LightFrame, Method, MethodKind};
use crate::receivers::ReceiverPass;
use crate::scene::{check_size, SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "cpu-silhouette";

const VOLUME: &str = include_str!("../shaders/volume.wgsl");
const DRAW: &str = include_str!("../shaders/cpu_draw.wgsl");

/// A buffer rewritten every frame, grown geometrically and never shrunk.
struct StreamBuffer {
    buffer: Option<wgpu::Buffer>,
}

impl StreamBuffer {
    /// Uploads `bytes` at offset 0 (a bigger buffer when it does not fit).
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) -> Result<(), WgpuError> {
        let needed = (bytes.len() as u64).max(16).next_multiple_of(4);
        if self.buffer.as_ref().is_none_or(|b| b.size() < needed) {
            let size = needed.next_power_of_two();
            check_size(device, "cpu-silhouette volume", size)?;
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("cpu-silhouette volume"),
                size,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        if let Some(b) = &self.buffer {
            queue.write_buffer(b, 0, bytes);
        }
        Ok(())
    }

    fn bytes(&self) -> u64 {
        self.buffer.as_ref().map_or(0, wgpu::Buffer::size)
    }
}

/// One light's volume.
struct PerLight {
    indexed: IndexedVolume,
    expanded: VolumeGeometry,
    /// Sides, light caps, dark caps, one after the other.
    vertices: Vec<[f32; 4]>,
    buffer: StreamBuffer,
    count: u32,
    /// What the last frame's volume drew.
    drawn: DrawnVolume,
    /// The fragments its receiver map's scatter shaded, when counted.
    scatter_fragments: Option<u64>,
}

/// See the module documentation.
pub struct CpuSilhouette {
    /// [z-fail, z-pass].
    pipelines: [wgpu::RenderPipeline; 2],
    prepared: Option<SceneId>,
    lights: Vec<PerLight>,
    /// The receiver map pass (made on the first culled frame, for the caller's depth format).
    receivers: Option<ReceiverPass>,
    /// The last culled light's kept triangles and far ends (reused across lights).
    clamp: VolumeClamp,
    /// Count the scatter's fragments ([`Method::set_count_fragments`]).
    count_fragments: bool,
}

impl CpuSilhouette {
    /// Pipelines for the pass formats of `common`.
    pub(crate) fn new(device: &wgpu::Device, common: &Common) -> Self {
        let module = Common::module(device, "cpu-silhouette cpu_draw.wgsl", &["enable clip_distances;", VOLUME, DRAW]);
        let layout = common.pipeline_layout(device, "cpu-silhouette", &[]);
        let vec4 = [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x4, offset: 0, shader_location: 0 }];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 16,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &vec4,
        })];
        let pipelines = [false, true].map(|zpass| {
            let label = "cpu-silhouette volume";
            common.counting_pipeline(
                device,
                label,
                &module,
                "vs_volume",
                &layout,
                &buffers,
                zpass,
                wgpu::FrontFace::Ccw,
            )
        });
        Self {
            pipelines,
            prepared: None,
            lights: Vec::new(),
            receivers: None,
            clamp: VolumeClamp::default(),
            count_fragments: false,
        }
    }
}

impl Method for CpuSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn kind(&self) -> MethodKind {
        MethodKind::Counting { silhouette_sides: true }
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn prepare_scene(&mut self, _device: &wgpu::Device, scene: &SceneGpu, _common: &Common) -> Result<(), WgpuError> {
        self.prepared = None;
        // Built once per mesh (shared through the scene): adjacency and slots.
        scene.slots()?;
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        common: &Common,
        frame: &LightFrame<'_>,
    ) -> Result<(), WgpuError> {
        while self.lights.len() <= frame.slot {
            self.lights.push(PerLight {
                indexed: IndexedVolume::default(),
                expanded: VolumeGeometry::default(),
                vertices: Vec::new(),
                buffer: StreamBuffer { buffer: None },
                count: 0,
                drawn: DrawnVolume::default(),
                scatter_fragments: None,
            });
        }
        let light = frame.data.light;
        let zpass = frame.plan.zpass;
        let caps = !zpass;
        let (mesh, adjacency, slots) = (scene.mesh(), scene.adjacency(), scene.slots()?);
        // The receiver map, and from it the triangles kept and their far ends.
        let mut culled = None;
        let mut scatter_fragments = None;
        if let (Some(depth), Some(bounds)) = (frame.receivers, scene.bounds()) {
            if self.receivers.as_ref().is_none_or(|r| r.format() != depth.format()) {
                self.receivers = Some(ReceiverPass::new(device, depth.format()));
            }
            let pass = self.receivers.as_ref().expect("made above");
            let (mut map, fragments): (ReceiverMap, _) =
                pass.build(device, queue, scene, frame.view, light, bounds, depth, self.count_fragments)?;
            scatter_fragments = fragments;
            // z-pass starts every count at the eye's near rectangle with the eye's winding: the
            // near pyramid's cells are raised to its farthest point, so no count inside it
            // changes (clamp.rs). Where the map cannot bound it, this light is drawn unculled.
            let view = frame.view;
            let near_ok = !zpass
                || map.raise_hull(&zpass_start_points(&view.world_from_clip, view.eye, DepthConvention::ReversedZ));
            if near_ok {
                // Whole regions of one orientation: a cut through a surface the light sees as
                // one piece would hang a new side from it (silhouette/regions.rs).
                let regions = Some((adjacency.as_ref(), slots.as_ref()));
                let stats = map.cull_and_clamp(mesh, light, regions, &mut self.clamp);
                let clip = ScreenClip {
                    clip_from_world: view.clip_from_world(),
                    world_planes: if zpass { scene_clip_box(bounds, view.eye).to_vec() } else { Vec::new() },
                    width: depth.width(),
                    height: depth.height(),
                };
                culled = Some((stats, clip));
            }
        }
        let l = &mut self.lights[frame.slot];
        l.scatter_fragments = scatter_fragments;
        let (clamped, triangles) = match culled {
            Some((stats, clip)) => {
                let fill = Some(&clip);
                let clamped = extract_kept(mesh, adjacency, slots, light, caps, &mut self.clamp, fill, &mut l.indexed);
                (Some(clamped), stats.kept)
            }
            None => {
                extract_indexed(mesh, adjacency, slots, light, caps, &mut l.indexed);
                (None, mesh.triangles.len())
            }
        };
        l.indexed.expand_into(&mesh.positions, light, &mut l.expanded);
        l.vertices.clear();
        l.vertices.extend_from_slice(&l.expanded.sides);
        l.vertices.extend_from_slice(&l.expanded.light_caps);
        if clamped.is_some() {
            // A culled volume is closed by its far caps (at infinity where unclamped), never by
            // the dark caps of every triangle.
            l.vertices.extend_from_slice(&l.indexed.far_caps);
        } else {
            l.vertices.extend_from_slice(&l.expanded.dark_caps);
        }
        l.buffer.write(device, queue, bytemuck::cast_slice(&l.vertices))?;
        l.count = l.vertices.len() as u32;
        l.drawn = DrawnVolume {
            triangles: triangles as u64,
            edges: (l.expanded.sides.len() / 6) as u64,
            culled: clamped.is_some(),
            clamped: clamped.unwrap_or(false),
        };
        let mut data = frame.data;
        data.first_light_cap = l.expanded.sides.len() as u32;
        data.first_dark_cap = data.first_light_cap + l.expanded.light_caps.len() as u32;
        common.write_slot(queue, frame.slot, &data);
        Ok(())
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, common: &Common, slot: usize, plan: LightPlan) {
        let Some(l) = self.lights.get(slot) else { return };
        let Some(buffer) = &l.buffer.buffer else { return };
        if l.count == 0 {
            return;
        }
        common.bind_slot_render(pass, slot);
        pass.set_pipeline(&self.pipelines[plan.zpass as usize]);
        pass.set_vertex_buffer(0, buffer.slice(..));
        pass.draw(0..l.count, 0..1);
    }

    fn gpu_bytes(&self) -> u64 {
        self.lights.iter().map(|l| l.buffer.bytes()).sum::<u64>()
            + self.receivers.as_ref().map_or(0, ReceiverPass::gpu_bytes)
    }

    fn culls_volumes(&self) -> bool {
        true
    }

    fn set_count_fragments(&mut self, on: bool) {
        self.count_fragments = on;
    }

    fn own_fragments(&self, slot: usize) -> Option<u64> {
        self.lights.get(slot).and_then(|l| l.scatter_fragments)
    }

    fn drawn_volume(&self, slot: usize) -> Option<DrawnVolume> {
        self.lights.get(slot).map(|l| l.drawn)
    }
}
