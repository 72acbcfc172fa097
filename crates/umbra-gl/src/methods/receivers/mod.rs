//! The receiver map pass: the frame's visible samples scattered into one light's
//! [`ReceiverMap`] on the GPU (`scatter.frag.glsl`), read back for the CPU's exact culling and
//! clamping of the shadow volumes ([`ReceiverMap::cull_and_clamp`], docs/exactness.md,
//! "Volumes clamped to their receivers").
//!
//! CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004) with the receivers taken
//! from the frame itself. One scene draw per light over the depth pass's depth (depth func
//! EQUAL, nothing of the frame written), an atomicMax per sample into a buffer of
//! [`ReceiverGrid::cells`] words, and a read-back of that buffer (a stall: the CPU needs the
//! map before it can extract the volume).

use glow::HasContext;
use umbra_geom::receivers::{ReceiverGrid, ReceiverMap, RECEIVER_SIDE};
use umbra_geom::{Aabb, Light};

use crate::error::GlError;
use crate::methods::method::VolumeFrame;
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::SceneGpu;
use crate::state::GlState;

const SCATTER_FRAG: &str = include_str!("scatter.frag.glsl");
/// The cells and the encoding, shared with hier-triangle's receiver map.
const RECEIVER_CELL_GLSL: &str = include_str!("../shared/receiver_cell.glsl");

/// Shader-storage binding of the map during the scatter (unbound afterwards). Binding 0 is the
/// scene's triangle normals.
pub const RECEIVERS_BINDING: u32 = 9;

/// The receiver pass's program and buffer (sized for a point light's cube).
pub(crate) struct ReceiverPass {
    program: glow::Program,
    buffer: glow::Buffer,
    bytes: usize,
    /// `bytes` zero bytes, the empty map.
    zeros: Vec<u8>,
}

impl ReceiverPass {
    /// Links the scatter program and allocates the map's buffer.
    pub(crate) fn new(gl: &glow::Context) -> Result<Self, GlError> {
        let binding = format!("UMBRA_RECEIVERS_BINDING {RECEIVERS_BINDING}");
        let fragment = format!("#version 450 core\n{RECEIVER_CELL_GLSL}\n{SCATTER_FRAG}");
        let program = link_program(
            gl,
            "receiver map scatter",
            &[
                ShaderSource::vertex("shaders/scene.vert.glsl", crate::scene::SCENE_VERT),
                ShaderSource::fragment("receivers/scatter.frag.glsl", &fragment),
            ],
            &[&binding],
        )?;
        let bytes = 4 * ReceiverGrid::Cube { light: [0.0; 3], side: RECEIVER_SIDE }.cells();
        let buffers = match crate::methods::hier::buffers::allocate_buffers(gl, &[bytes], &["receiver map"]) {
            Ok(b) => b,
            Err(e) => {
                // SAFETY: our program, not used afterwards.
                unsafe { gl.delete_program(program) };
                return Err(e);
            }
        };
        Ok(Self { program, buffer: buffers[0], bytes, zeros: vec![0; bytes] })
    }

    /// Bytes of GPU memory held.
    pub(crate) fn gpu_bytes(&self) -> usize {
        self.bytes
    }

    /// The map of `frame`'s light over the frame's visible samples (the depth buffer bound with
    /// the frame's target). `bounds`: the scene's box (a directional light's grid spans it).
    pub(crate) fn build(
        &self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &VolumeFrame<'_>,
        bounds: Aabb,
    ) -> Result<ReceiverMap, GlError> {
        let grid = ReceiverGrid::new(frame.light, bounds, RECEIVER_SIDE);
        self.scatter(gl, scene, frame, &grid, self.buffer);
        // The barrier before the read is read_words' own.
        let words = crate::methods::hier::buffers::read_words(gl, self.buffer, 0, grid.cells());
        ReceiverMap::from_encoded(grid, &words)
            .ok_or_else(|| GlError::InvalidParams("receiver map: read back a map of the wrong size".into()))
    }

    /// Scatters the frame's visible samples (the depth buffer bound with the frame's target)
    /// into the first [`ReceiverGrid::cells`] words of `buffer` (at least
    /// [`ReceiverPass::gpu_bytes`] long), cleared first: `frame.light`'s map of `grid`. The
    /// caller orders its own reads after it (a shader-storage barrier).
    pub(crate) fn scatter(
        &self,
        gl: &glow::Context,
        scene: &SceneGpu,
        frame: &VolumeFrame<'_>,
        grid: &ReceiverGrid,
        buffer: glow::Buffer,
    ) {
        let light: Light = frame.light;
        let cells = grid.cells();
        GlState::visible_samples(frame.receivers).apply(gl);
        // Reason: the scene's vertex shader writes no gl_ClipDistance, and the renderer may
        // have enabled them for the volume pass this runs in: off for this draw (as the depth
        // pass had them), restored below.
        // Reason: every sample of the view must reach the scatter, whatever polygon mode the
        // pass runs under (the volume wireframe draws this pass with LINE); restored below.
        let mut polygon_mode = [glow::FILL as i32; 2];
        // SAFETY: a state query and a state call on the current context.
        unsafe {
            gl.get_parameter_i32_slice(glow::POLYGON_MODE, &mut polygon_mode);
            gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
        }
        // SAFETY: capability queries and toggles on the current context.
        let clip: [bool; 8] = std::array::from_fn(|i| unsafe { gl.is_enabled(glow::CLIP_DISTANCE0 + i as u32) });
        for i in 0..8 {
            // SAFETY: as above.
            unsafe { gl.disable(glow::CLIP_DISTANCE0 + i) };
        }
        // SAFETY: our program and buffer; the scene's vertex array and normal buffer; the
        // frame's own target.
        unsafe {
            // Reason: every cell starts empty (the word 0 is below every encoded value).
            // (glClearBufferData is not among the entry points glow loads: an upload of zeros.)
            gl.named_buffer_sub_data_u8_slice(buffer, 0, &self.zeros[..4 * cells]);
            // Reason: the clear must land before the fragment shader's atomics.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, frame.width as i32, frame.height as i32);
            gl.use_program(Some(self.program));
            let p = self.program;
            gl.uniform_matrix_4_f32_slice(
                uniform(gl, p, "u_clip_from_world").as_ref(),
                false,
                &frame.clip_from_world_f32(),
            );
            gl.uniform_4_f32_slice(uniform(gl, p, "u_light").as_ref(), &light);
            gl.uniform_1_u32(uniform(gl, p, "u_side").as_ref(), grid.side());
            if let ReceiverGrid::Flat { origin, u, v, travel, lo, scale, .. } = *grid {
                gl.uniform_3_f32_slice(uniform(gl, p, "u_origin").as_ref(), &origin);
                gl.uniform_3_f32_slice(uniform(gl, p, "u_u").as_ref(), &u);
                gl.uniform_3_f32_slice(uniform(gl, p, "u_v").as_ref(), &v);
                gl.uniform_3_f32_slice(uniform(gl, p, "u_travel").as_ref(), &travel);
                gl.uniform_2_f32_slice(uniform(gl, p, "u_lo").as_ref(), &lo);
                gl.uniform_2_f32_slice(uniform(gl, p, "u_scale").as_ref(), &scale);
            }
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, 0, Some(scene.normal_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RECEIVERS_BINDING, Some(buffer));
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);
        // SAFETY: as above.
        unsafe {
            // Leave no binding of ours behind for the caller.
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RECEIVERS_BINDING, None);
            // Reason: the polygon mode the pass runs under, as it was.
            gl.polygon_mode(glow::FRONT_AND_BACK, polygon_mode[0] as u32);
            // Reason: the volume pass's clip planes as the renderer set them.
            for (i, &on) in clip.iter().enumerate() {
                if on {
                    gl.enable(glow::CLIP_DISTANCE0 + i as u32);
                }
            }
        }
    }

    /// Frees the program and buffer.
    pub(crate) fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own objects, not used afterwards.
        unsafe {
            gl.delete_program(self.program);
            gl.delete_buffer(self.buffer);
        }
    }
}
