//! `cpu-silhouette`: silhouette shadow volumes built on the CPU every frame.
//!
//! Paper 001, Sections 2.2-2.3 (deterministic edge multiplicity with a reference edge,
//! Alg. 2-4; sides extruded with Eq. 2; caps oriented by the same test), via
//! [`umbra_geom::silhouette::extract`] (rayon-parallel). Light caps are pushed to the far
//! plane in the vertex shader (paper 003, Eq. 6); z-fail counting by default (Everitt &
//! Kilgard 2002), z-pass without caps when asked (Heidmann 1991).
//!
//! Once per mesh ([`ShadowMethod::prepare`]): edge adjacency (shared through
//! [`SceneGpu::adjacency`]), program, vertex array, one vertex buffer.
//! Per light per frame: extract into a reused [`VolumeGeometry`] (its Vecs keep their
//! capacity), orphan the vertex buffer with glNamedBufferData (grown geometrically, never
//! shrunk) and upload sides | dark caps | light caps with glNamedBufferSubData, then three
//! draws with [`VolumeFrame::shadow_volume_state`] (the frame's depth convention; light caps
//! pushed to [`VolumeFrame::far_clip_z`]).
//!
//! Stages reported: "silhouette" (CPU extraction), "upload", "sides", "caps".

use glow::HasContext;
use umbra_geom::silhouette::{extract, VolumeGeometry};

use crate::error::GlError;
use crate::methods::{ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{checked_size, SceneGpu, SceneId};

pub const NAME: &str = "cpu-silhouette";

const VERT: &str = include_str!("volume.vert.glsl");
const FRAG: &str = include_str!("volume.frag.glsl");
/// `umbra_push_to_far` and `u_far_clip_z` (paper 003 Eq. 6 in either depth convention).
const DEPTH_GLSL: &str = include_str!("../shared/depth.glsl");

struct Gpu {
    program: glow::Program,
    u_clip_from_world: Option<glow::UniformLocation>,
    u_push_to_far: Option<glow::UniformLocation>,
    u_far_clip_z: Option<glow::UniformLocation>,
    vao: glow::VertexArray,
    buffer: glow::Buffer,
    capacity: usize,
}

/// See the module documentation.
#[derive(Default)]
pub struct CpuSilhouette {
    prepared: Option<SceneId>,
    gpu: Option<Gpu>,
    geometry: VolumeGeometry,
}

fn as_bytes(v: &[[f32; 4]]) -> &[u8] {
    // SAFETY: [f32; 4] has no padding and every byte is initialised.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

impl CpuSilhouette {
    pub fn new() -> Self {
        Self::default()
    }

    /// Vertex counts (sides, dark caps, light caps) of the last extracted volume.
    pub fn last_counts(&self) -> (usize, usize, usize) {
        (self.geometry.sides.len(), self.geometry.dark_caps.len(), self.geometry.light_caps.len())
    }
}

impl ShadowMethod for CpuSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["silhouette", "upload", "sides", "caps"]
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        // Preprocessing once per mesh: the adjacency (cached on the scene).
        scene.adjacency();
        if self.gpu.is_none() {
            let vert = format!("#version 450 core\n{DEPTH_GLSL}\n{VERT}");
            let program = link_program(
                gl,
                "cpu-silhouette volume",
                &[ShaderSource::vertex("cpu_silhouette/volume.vert.glsl", &vert), ShaderSource::fragment("cpu_silhouette/volume.frag.glsl", FRAG)],
                &[],
            )?;
            // SAFETY: DSA creation on the current context; the program is deleted if a later
            // creation fails.
            unsafe {
                let cleanup = |e| {
                    gl.delete_program(program);
                    e
                };
                let buffer = gl
                    .create_named_buffer()
                    .map_err(|detail| cleanup(GlError::Create { what: "volume buffer", detail }))?;
                let vao = match gl.create_named_vertex_array() {
                    Ok(v) => v,
                    Err(detail) => {
                        gl.delete_buffer(buffer);
                        return Err(cleanup(GlError::Create { what: "volume vertex array", detail }));
                    }
                };
                // Attribute 0: vec4 homogeneous world position, tightly packed.
                gl.vertex_array_vertex_buffer(vao, 0, Some(buffer), 0, 16);
                gl.vertex_array_attrib_format_f32(vao, 0, 4, glow::FLOAT, false, 0);
                gl.vertex_array_attrib_binding_f32(vao, 0, 0);
                gl.enable_vertex_array_attrib(vao, 0);
                self.gpu = Some(Gpu {
                    u_clip_from_world: uniform(gl, program, "u_clip_from_world"),
                    u_push_to_far: uniform(gl, program, "u_push_to_far"),
                    u_far_clip_z: uniform(gl, program, "u_far_clip_z"),
                    program,
                    vao,
                    buffer,
                    capacity: 0,
                });
            }
        }
        self.prepared = Some(scene.id());
        Ok(())
    }

    fn prepared_scene(&self) -> Option<SceneId> {
        self.prepared
    }

    fn draw_volumes(&mut self, gl: &glow::Context, scene: &SceneGpu, frame: &mut VolumeFrame<'_>) -> Result<(), GlError> {
        let gpu = self
            .gpu
            .as_mut()
            .ok_or_else(|| GlError::InvalidParams("cpu-silhouette: draw_volumes before prepare".into()))?;

        frame.mark(gl, "silhouette");
        // z-pass needs no caps (it counts only faces in front of the sample).
        extract(scene.mesh(), scene.adjacency(), frame.light, !frame.zpass, &mut self.geometry);
        let g = &self.geometry;

        frame.mark(gl, "upload");
        let parts = [as_bytes(&g.sides), as_bytes(&g.dark_caps), as_bytes(&g.light_caps)];
        let total: usize = parts.iter().map(|p| p.len()).sum();
        let vertex_count = g.sides.len() + g.dark_caps.len() + g.light_caps.len();
        if i32::try_from(vertex_count).is_err() {
            return Err(GlError::InvalidParams(format!("{vertex_count} shadow-volume vertices exceed one draw call")));
        }
        if total > gpu.capacity {
            gpu.capacity = total.max(gpu.capacity + gpu.capacity / 2);
        }
        let capacity = checked_size(gpu.capacity, "cpu-silhouette volume buffer")?;
        // SAFETY: uploads into our own buffer; offsets + lengths sum to total <= capacity.
        unsafe {
            // Orphaning: a fresh store each frame, so the driver never waits for the GPU to
            // finish reading last frame's volume.
            gl.named_buffer_data_size(gpu.buffer, capacity, glow::STREAM_DRAW);
            let mut offset = 0;
            for p in parts {
                if !p.is_empty() {
                    gl.named_buffer_sub_data_u8_slice(gpu.buffer, offset as i32, p);
                }
                offset += p.len();
            }
        }

        // Counting state: z-fail or z-pass two-sided stencil, depth clamp, no colour/depth
        // writes, depth func of the frame's convention; the reason for every field is in
        // GlState::shadow_volume_for.
        frame.shadow_volume_state().apply(gl);
        let (sides, dark, light) = (g.sides.len() as i32, g.dark_caps.len() as i32, g.light_caps.len() as i32);
        // SAFETY: our program and VAO; draw ranges lie within the uploaded vertices.
        unsafe {
            gl.use_program(Some(gpu.program));
            gl.bind_vertex_array(Some(gpu.vao));
            gl.uniform_matrix_4_f32_slice(gpu.u_clip_from_world.as_ref(), false, &frame.clip_from_world_f32());
            gl.uniform_1_i32(gpu.u_push_to_far.as_ref(), 0);
            gl.uniform_1_f32(gpu.u_far_clip_z.as_ref(), frame.far_clip_z());
            frame.mark(gl, "sides");
            if sides > 0 {
                gl.draw_arrays(glow::TRIANGLES, 0, sides);
            }
            frame.mark(gl, "caps");
            if dark > 0 {
                gl.draw_arrays(glow::TRIANGLES, sides, dark);
            }
            if light > 0 {
                // Light caps to the far plane, paper 003 Eq. 6 (see volume.vert.glsl).
                gl.uniform_1_i32(gpu.u_push_to_far.as_ref(), 1);
                gl.draw_arrays(glow::TRIANGLES, sides + dark, light);
            }
        }
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        self.gpu.as_ref().map_or(0, |g| g.capacity)
    }

    fn destroy(&mut self, gl: &glow::Context) {
        if let Some(g) = self.gpu.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_program(g.program);
                gl.delete_vertex_array(g.vao);
                gl.delete_buffer(g.buffer);
            }
        }
        self.prepared = None;
    }
}
