//! `cpu-silhouette`: silhouette shadow volumes built on the CPU every frame.
//!
//! Paper 001, Sections 2.2-2.3 (deterministic edge multiplicity with a reference edge,
//! Alg. 2-4; sides extruded with Eq. 2; caps oriented by the same test), via
//! [`umbra_geom::silhouette::extract_indexed`] (rayon-parallel). Light caps are pushed to the
//! far plane in the vertex shader (paper 003, Eq. 6); z-fail counting by default (Everitt &
//! Kilgard 2002), z-pass without caps when asked (Heidmann 1991).
//!
//! Once per mesh ([`ShadowMethod::prepare`]): edge adjacency (shared through
//! [`SceneGpu::adjacency`]), the [`TriangleSlots`] of the mesh (which triangle each of the
//! adjacency's opposite vertices comes from), program, two vertex arrays, two buffers.
//! Per light per frame: extract into a reused [`IndexedVolume`] (its Vecs keep their
//! capacity), orienting every triangle once and summing those orientations per edge: the
//! side quads as homogeneous vertices, the caps as one oriented index triple per triangle
//! (12 bytes instead of 96 bytes of light- and dark-cap vertex copies). Upload
//! both into buffers orphaned with glNamedBufferData (grown geometrically, never shrunk),
//! then three draws with [`VolumeFrame::shadow_volume_state`] (the frame's depth convention):
//! the sides as they are; the light caps from the scene's own static position buffer with
//! our index buffer, pushed to [`VolumeFrame::far_clip_z`]; the dark caps from the same
//! positions and indices, extruded to infinity in the vertex shader (001 Eq. 2, the CPU's
//! expression) and drawn with the front face flipped, which reverses their winding as the
//! volume needs (`P0∞ P2∞ P1∞`, see `umbra_geom::silhouette`). That is the volume
//! `IndexedVolume::expand_into` spells out vertex by vertex, which the property tests of
//! `umbra-geom/tests/volume_props.rs` check for closedness.
//!
//! Stages reported: "silhouette" (CPU extraction), "upload", "sides", "caps".

use glow::HasContext;
use umbra_geom::clearance::scene_clip_box;
use umbra_geom::receivers::{clamp_beyond_box, CullStats};
use umbra_geom::silhouette::{
    extract_indexed, extract_kept, has_dark_caps, IndexedVolume, ScreenClip, TriangleSlots, VolumeClamp,
};

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, BufferApi, BufferData};
use crate::methods::face_depth::{face_depth_fragment, DepthUniforms, SIDE_PLANE_GLSL};
use crate::methods::method::{DrawnVolume, ShadowMethod, VolumeFrame};
use crate::methods::receivers::ReceiverPass;
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};

/// Registry name.
pub const NAME: &str = "cpu-silhouette";

const VERT: &str = include_str!("volume.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");
/// `umbra_push_to_far` and `u_far_clip_z` (paper 003 Eq. 6 in either depth convention).
const DEPTH_GLSL: &str = include_str!("../shared/depth.glsl");
/// `umbra_greater` and `umbra_extrude`, which shared/side_plane.glsl needs.
const MULTIPLICITY_GLSL: &str = include_str!("../shared/multiplicity.glsl");

/// Shader-storage binding of the side vertices in the vertex shader (every fragment's face
/// depth, volume.vert.glsl). Binding 0 is the renderer's normals.
pub const SIDES_BINDING: u32 = 1;

/// `u_mode` of volume.vert.glsl.
const MODE_SIDES: i32 = 0;
const MODE_LIGHT_CAPS: i32 = 1;
const MODE_DARK_CAPS: i32 = 2;
const MODE_NEAR_CAPS: i32 = 3;

/// A buffer re-specified every frame, grown geometrically and never shrunk.
struct StreamBuffer {
    buffer: glow::Buffer,
    capacity: usize,
}

impl StreamBuffer {
    /// Orphans the buffer (a fresh store, so the driver never waits for the GPU to finish
    /// reading last frame's data) and uploads `data` at offset 0. A store the driver refuses
    /// is [`GlError::OutOfMemory`] ([`buffer_store`]); the capacity is then 0 (GL leaves a
    /// refused store empty), so the next frame specifies a new one again.
    fn upload(&mut self, gl: &glow::Context, parts: &[&[u8]], what: &'static str) -> Result<(), GlError> {
        let len: usize = parts.iter().map(|p| p.len()).sum();
        if len > self.capacity {
            self.capacity = len.max(self.capacity + self.capacity / 2);
        }
        if let Err(e) =
            buffer_store(gl, self.buffer, BufferApi::Dsa, BufferData::Size(self.capacity), glow::STREAM_DRAW, what)
        {
            self.capacity = 0;
            return Err(e);
        }
        let mut at = 0;
        for data in parts.iter().filter(|p| !p.is_empty()) {
            // SAFETY: our own buffer, whose store has just been specified with
            // capacity >= the parts' total bytes.
            unsafe { gl.named_buffer_sub_data_u8_slice(self.buffer, at as i32, data) };
            at += data.len();
        }
        Ok(())
    }
}

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_mode: Option<glow::UniformLocation>,
    u_light: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    depth: DepthUniforms,
    /// Sides: attribute 0 = vec4 from `sides`.
    sides_vao: glow::VertexArray,
    sides: StreamBuffer,
    /// Caps: attribute 0 = vec3 from the scene's position buffer (bound per draw), element
    /// buffer `caps`.
    caps_vao: glow::VertexArray,
    caps: StreamBuffer,
}

/// See the module documentation.
#[derive(Default)]
pub struct CpuSilhouette {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
    volume: IndexedVolume,
    /// [`TriangleSlots`] of the scene they were built for.
    slots: Option<(SceneId, TriangleSlots)>,
    /// Whether the last volume has dark caps (a point light with caps).
    last_dark_caps: bool,
    /// The receiver map pass (made on the first culled frame).
    receivers: Option<ReceiverPass>,
    /// The last light's kept triangles and far ends.
    clamp: VolumeClamp,
    /// Whether the last light's volume was clamped (else culled only, or neither).
    last_clamped: bool,
    /// What the last cull did (`None`: not culled).
    last_cull: Option<CullStats>,
    /// Triangles of the prepared scene.
    triangles: usize,
}

/// Where a z-pass count may start ([`umbra_geom::camera::zpass_start_points`]).
fn near_pyramid(frame: &VolumeFrame<'_>) -> Vec<[f64; 3]> {
    umbra_geom::camera::zpass_start_points(&frame.clip_from_world.inverse(), frame.eye, frame.depth_convention())
}

/// The bytes of plain-old-data arrays of `u32` or `f32` (no padding, every byte initialised).
fn as_bytes<T: Pod, const N: usize>(v: &[[T; N]]) -> &[u8] {
    // SAFETY: `T` is `f32` or `u32` (sealed by `Pod`): arrays of them have no padding and
    // every byte is initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Element types [`as_bytes`] accepts.
trait Pod: Copy {}
impl Pod for f32 {}
impl Pod for u32 {}

impl CpuSilhouette {
    /// Unprepared; buffers are made by `prepare`.
    pub fn new() -> Self {
        Self::default()
    }

    /// Vertex counts (sides, dark caps, light caps) of the last extracted volume, as drawn
    /// (degenerate caps of edge-on and dropped triangles included; a clamped volume's far caps
    /// count as its dark caps).
    pub fn last_counts(&self) -> (usize, usize, usize) {
        let caps = 3 * self.volume.caps.len();
        let dark = if self.last_cull.is_some() {
            self.volume.far_caps.len()
        } else if self.last_dark_caps {
            caps
        } else {
            0
        };
        (self.volume.sides.len(), dark, caps)
    }

    /// What the receiver cull of the last light did: triangles kept and kept unclamped;
    /// `None` when the last volume was not culled.
    pub fn last_cull(&self) -> Option<CullStats> {
        self.last_cull
    }

    /// Builds the [`TriangleSlots`] of `scene` unless they are already there.
    fn slots_for(&mut self, scene: &SceneGpu) -> Result<(), GlError> {
        if self.slots.as_ref().is_none_or(|(id, _)| *id != scene.id()) {
            let slots = TriangleSlots::build(scene.mesh(), scene.adjacency())
                .map_err(|e| GlError::InvalidParams(format!("cpu-silhouette: {e}")))?;
            self.slots = Some((scene.id(), slots));
        }
        Ok(())
    }

    /// The last extracted volume (indices into the prepared scene's welded positions).
    pub fn last_volume(&self) -> &IndexedVolume {
        &self.volume
    }
}

impl ShadowMethod for CpuSilhouette {
    fn silhouette_sides(&self) -> bool {
        true
    }

    fn name(&self) -> &'static str {
        NAME
    }

    fn orthographic(&self) -> bool {
        // Orthographic views get volumes closed beyond the scene (draw_volumes).
        true
    }

    fn stages(&self) -> &'static [&'static str] {
        &["receivers", "silhouette", "upload", "sides", "caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        // Preprocessing once per mesh: the adjacency (cached on the scene) and the slots.
        self.slots_for(scene)?;
        if self.gpu.is_none() {
            let vert = format!("#version 450 core\n{MULTIPLICITY_GLSL}\n{DEPTH_GLSL}\n{SIDE_PLANE_GLSL}\n{VERT}");
            let frag = face_depth_fragment(FRAG);
            let sides_binding = format!("UMBRA_SIDES_BINDING {SIDES_BINDING}");
            let program = link_program(
                gl,
                "cpu-silhouette volume",
                &[
                    ShaderSource::vertex("cpu_silhouette/volume.vert.glsl", &vert),
                    ShaderSource::fragment("cpu_silhouette/volume.frag.glsl", &frag),
                ],
                &[&sides_binding],
            )?;
            // SAFETY: DSA creation on the current context; everything created so far is
            // deleted if a later creation fails.
            unsafe {
                let mut buffers = Vec::new();
                let mut vaos = Vec::new();
                let cleanup = |buffers: &[glow::Buffer], vaos: &[glow::VertexArray], e| {
                    for &b in buffers {
                        gl.delete_buffer(b);
                    }
                    for &v in vaos {
                        gl.delete_vertex_array(v);
                    }
                    gl.delete_program(program);
                    e
                };
                for what in ["volume side buffer", "volume cap index buffer"] {
                    match gl.create_named_buffer() {
                        Ok(b) => buffers.push(b),
                        Err(detail) => return Err(cleanup(&buffers, &vaos, GlError::Create { what, detail })),
                    }
                }
                for what in ["volume side vertex array", "volume cap vertex array"] {
                    match gl.create_named_vertex_array() {
                        Ok(v) => vaos.push(v),
                        Err(detail) => return Err(cleanup(&buffers, &vaos, GlError::Create { what, detail })),
                    }
                }
                let (sides, caps) = (buffers[0], buffers[1]);
                let (sides_vao, caps_vao) = (vaos[0], vaos[1]);
                // Sides, attribute 0: vec4 homogeneous world position, tightly packed.
                gl.vertex_array_vertex_buffer(sides_vao, 0, Some(sides), 0, 16);
                gl.vertex_array_attrib_format_f32(sides_vao, 0, 4, glow::FLOAT, false, 0);
                gl.vertex_array_attrib_binding_f32(sides_vao, 0, 0);
                gl.enable_vertex_array_attrib(sides_vao, 0);
                // Caps, attribute 0: vec3 welded position (w = 1 by default), from the scene's
                // buffer, bound in draw_volumes; elements: our oriented cap indices.
                gl.vertex_array_attrib_format_f32(caps_vao, 0, 3, glow::FLOAT, false, 0);
                gl.vertex_array_attrib_binding_f32(caps_vao, 0, 0);
                gl.enable_vertex_array_attrib(caps_vao, 0);
                gl.vertex_array_element_buffer(caps_vao, Some(caps));
                self.gpu = Some(Gpu {
                    u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                    u_mode: uniform(gl, program, "u_mode"),
                    u_light: uniform(gl, program, "u_light"),
                    u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
                    depth: DepthUniforms::locate(gl, program),
                    program,
                    sides_vao,
                    sides: StreamBuffer { buffer: sides, capacity: 0 },
                    caps_vao,
                    caps: StreamBuffer { buffer: caps, capacity: 0 },
                });
            }
        }
        self.triangles = scene.mesh().triangles.len();
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(
        &mut self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
    ) -> Result<(), GlError> {
        // The receiver map, and from it the triangles kept and their far ends (docs/exactness.md,
        // "Volumes clamped to their receivers").
        frame.mark(gl, "receivers");
        self.last_cull = None;
        // An orthographic view cannot draw a far end at infinity (clip w = 0): every volume is
        // closed beyond the scene's box instead, whatever volume_cull says (docs/exactness.md,
        // "Orthographic views").
        let ortho = frame.is_orthographic();
        if let (true, Some(bounds)) = (ortho, scene.bounds()) {
            let stats = clamp_beyond_box(scene.mesh(), frame.light, bounds, &mut self.clamp)
                .map_err(|e| GlError::InvalidParams(format!("cpu-silhouette: {e}")))?;
            self.last_cull = Some(stats);
        } else if frame.volume_cull && !ortho {
            if self.receivers.is_none() {
                self.receivers = Some(ReceiverPass::new(gl)?);
            }
            // The scene's box (a directional light's grid spans it), as the renderer has it.
            if let (Some(pass), Some(bounds)) = (self.receivers.as_ref(), scene.bounds()) {
                let mut map = pass.build(gl, scene, frame, bounds)?;
                // z-pass starts every count at the eye's near rectangle with the eye's winding
                // (the renderer's W0, from the unclamped volumes): the near pyramid's cells are
                // raised to its farthest point, so no count inside it changes (clamp.rs). Where
                // the map cannot bound it, this light is drawn unclamped.
                let near_ok = !frame.zpass || map.raise_hull(&near_pyramid(frame));
                if near_ok {
                    // Whole regions of one orientation: a cut through a surface the light sees
                    // as one piece would hang a new side from it (silhouette/regions.rs).
                    self.slots_for(scene)?;
                    let regions = self.slots.as_ref().map(|(_, slots)| (scene.adjacency().as_ref(), slots));
                    self.last_cull = Some(map.cull_and_clamp(scene.mesh(), frame.light, regions, &mut self.clamp));
                }
            }
        }
        frame.mark(gl, "silhouette");
        // Built in prepare; rebuilt only if drawn with another scene.
        self.slots_for(scene)?;
        let (Some(gpu), Some((_, slots))) = (self.gpu.as_mut(), self.slots.as_ref()) else {
            return Err(GlError::InvalidParams("cpu-silhouette: draw_volumes before prepare".into()));
        };
        // z-pass needs no light caps (they are never in front of a visible sample) and no dark
        // caps at infinity; a clamped volume's far caps it does need (clamp.rs). An
        // orthographic z-pass needs the light caps behind the near plane (MODE_NEAR_CAPS).
        let caps = !frame.zpass || ortho;
        let (mesh, adjacency) = (scene.mesh(), scene.adjacency());
        self.last_clamped = false;
        if self.last_cull.is_some() {
            self.last_dark_caps = false;
            // Clamped only where that costs fewer fragments than the same kept triangles'
            // volumes running to infinity (silhouette/kept.rs); both give every visible sample
            // the same count. Finite volumes are the only ones an orthographic view can draw.
            let clip = ScreenClip {
                clip_from_world: frame.clip_from_world,
                world_planes: match (frame.zpass, scene.bounds()) {
                    (true, Some(b)) => scene_clip_box(b, frame.eye).to_vec(),
                    _ => Vec::new(),
                },
                width: frame.width,
                height: frame.height,
            };
            let fill = (!ortho).then_some(&clip);
            self.last_clamped =
                extract_kept(mesh, adjacency, slots, frame.light, caps, &mut self.clamp, fill, &mut self.volume);
        } else {
            extract_indexed(mesh, adjacency, slots, frame.light, caps, &mut self.volume);
            self.last_dark_caps = caps && has_dark_caps(frame.light);
        }
        let v = &self.volume;

        frame.mark(gl, "upload");
        // The far caps follow the sides in the same buffer and draw: both are plain triangles
        // of homogeneous vertices, each with the face depth of its own plane.
        let (sides, cap_indices) = (v.sides.len() + v.far_caps.len(), 3 * v.caps.len());
        if i32::try_from(sides).is_err() || i32::try_from(cap_indices).is_err() {
            return Err(GlError::InvalidParams(format!(
                "{sides} shadow-volume side vertices or {cap_indices} cap indices exceed one draw call"
            )));
        }
        gpu.sides.upload(gl, &[as_bytes(&v.sides), as_bytes(&v.far_caps)], "cpu-silhouette side buffer")?;
        gpu.caps.upload(gl, &[as_bytes(&v.caps)], "cpu-silhouette cap index buffer")?;

        // Counting state: z-fail or z-pass two-sided stencil, depth clamp, no colour/depth
        // writes, depth func of the frame's convention; the reason for every field is in
        // GlState::shadow_volume_for.
        let state = frame.shadow_volume_state();
        state.apply(gl);
        let (sides, cap_indices) = (sides as i32, cap_indices as i32);
        // SAFETY: our program and VAOs; the side draw lies within the uploaded vertices; the
        // cap indices come from the scene's triangles, all < positions.len() (checked at
        // SceneGpu::upload), and the scene's position buffer holds those positions.
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_4_f32_slice(gpu.u_light.as_ref(), &frame.light);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
        }
        // The face depth functions every fragment's depth comes from (shared/side_plane.glsl).
        gpu.depth.set(gl, frame);
        // SAFETY: as above.
        unsafe {
            frame.mark(gl, "sides");
            if sides > 0 {
                gl.bind_vertex_array(Some(gpu.sides_vao));
                // The side vertices as storage too: the provoking vertex of each triangle reads
                // the other two for its face depth (volume.vert.glsl).
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SIDES_BINDING, Some(gpu.sides.buffer));
                gl.uniform_1_i32(gpu.u_mode.as_ref(), MODE_SIDES);
                gl.draw_arrays(glow::TRIANGLES, 0, sides);
                // Leave no binding of ours behind for the caller.
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SIDES_BINDING, None);
            }
            frame.mark(gl, "caps");
            if cap_indices > 0 {
                // The scene's welded positions (12-byte vec3): the caps' indices refer to them.
                gl.vertex_array_vertex_buffer(gpu.caps_vao, 0, Some(scene.position_buffer()), 0, 12);
                gl.bind_vertex_array(Some(gpu.caps_vao));
                // Light caps to the far plane, paper 003 Eq. 6 (see volume.vert.glsl); under an
                // orthographic z-pass their parts behind the near plane, at its depth.
                let mode = if frame.zpass { MODE_NEAR_CAPS } else { MODE_LIGHT_CAPS };
                gl.uniform_1_i32(gpu.u_mode.as_ref(), mode);
                gl.draw_elements(glow::TRIANGLES, cap_indices, glow::UNSIGNED_INT, 0);
                if self.last_dark_caps {
                    // Dark caps: the same indices extruded to infinity (volume.vert.glsl). They
                    // must face the other way than the light caps (P0∞ P2∞ P1∞): flipping the
                    // front face reverses every triangle's facing for the two-sided stencil ops,
                    // exactly as reversing its indices would.
                    gl.front_face(if state.front_face == glow::CCW { glow::CW } else { glow::CCW });
                    gl.uniform_1_i32(gpu.u_mode.as_ref(), MODE_DARK_CAPS);
                    gl.draw_elements(glow::TRIANGLES, cap_indices, glow::UNSIGNED_INT, 0);
                    // Back to the counting state's front face for whatever draws next.
                    gl.front_face(state.front_face);
                }
            }
        }
        Ok(())
    }

    fn culls_volumes(&self) -> bool {
        true
    }

    fn drawn_volume(&self) -> Option<DrawnVolume> {
        let triangles = self.last_cull.map_or(self.triangles, |c| c.kept);
        let edges = self.volume.sides.len() / 6;
        Some(DrawnVolume {
            triangles: triangles as u64,
            edges: edges as u64,
            culled: self.last_cull.is_some(),
            clamped: self.last_clamped,
        })
    }

    fn gpu_bytes(&self) -> usize {
        self.gpu.as_ref().map_or(0, |g| g.sides.capacity + g.caps.capacity)
            + self.receivers.as_ref().map_or(0, ReceiverPass::gpu_bytes)
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_program(g.program);
                gl.delete_vertex_array(g.sides_vao);
                gl.delete_vertex_array(g.caps_vao);
                gl.delete_buffer(g.sides.buffer);
                gl.delete_buffer(g.caps.buffer);
            }
        }
        if let Some(r) = self.receivers.take() {
            r.destroy(gl);
        }
        self.prepared = None;
    }
}
