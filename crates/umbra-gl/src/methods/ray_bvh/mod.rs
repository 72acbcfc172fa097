//! `ray-bvh`: one shadow ray per view sample, traced in a compute shader through a BVH of the
//! scene — the exact peer the shadow-volume methods are measured against. No volume is
//! rasterized or depth-tested.
//!
//! The BVH ([`umbra_geom::ray_bvh`]: binned SAH, siblings adjacent with parent indices for an
//! ordered stackless walk, leaves of up to 4 triangles) is built on the CPU once per scene in
//! [`ShadowMethod::prepare`] and uploaded once. Per frame (once for all lights,
//! [`VolumeFrame::view_serial`]):
//! 1. "samples": `clear.comp.glsl` marks every pixel "no sample", then the scene is drawn with
//!    the renderer's own vertex shader over the frame's depth, depth func EQUAL, all writes
//!    masked: `samples.frag.glsl` (early fragment tests) stores each visible sample's world
//!    position and triangle id, the samples the renderer's depth pass produced.
//!
//! Per light:
//! 2. "rays": `trace.comp.glsl`, one invocation per pixel: the sample moved onto its own
//!    triangle's plane (f64), the segment to the light (the ray towards a directional light),
//!    the ordered stackless walk of the BVH with Woop et al.'s watertight test, the sample's own
//!    triangle skipped, the first hit ending it — the reference's rule, see `trace.comp.glsl`
//!    and docs/exactness.md;
//! 3. "resume": a walk stopped by its step budget (llvmpipe's loop limit, see
//!    `trace.comp.glsl`) continues in the next pass from its parked state; the passes are
//!    bounded by the node count over the budget, each sized from the previous one's list
//!    (`args.comp.glsl`, indirect; normally no workgroup at all);
//! 4. "stencil": `resolve.frag.glsl` on a full-screen triangle writes stencil 1 where the ray
//!    hit: [`Classification::StencilZero`] as every counting method, so the lighting pass,
//!    [`crate::Renderer::count_shadows`] and `umbra verify` read it unchanged
//!    ([`ShadowMethod::fills_volumes`] is false: the renderer clears the stencil to 0 and sets
//!    up no counting for it).
//!
//! Samples are the visible surfaces of *umbra's scene*: with
//! [`crate::Renderer::count_shadows`] on a caller's depth that also holds other geometry, the
//! pixels of that geometry get no sample and stay lit (stencil 0).
//!
//! Memory: [`RayBvhMethod::scene_bytes`] per scene (the BVH, [`umbra_geom::ray_bvh::RayBvh::bytes`])
//! plus [`frame_bytes`] per frame size (samples 16, result 4 and two resume lists of 4 bytes
//! per pixel). Every allocation is checked: one the GL refuses is [`GlError::OutOfMemory`],
//! nothing is left behind and the method stays usable.

use std::time::Instant;

use glow::HasContext;
use umbra_geom::ray_bvh::{self, RayBvh};

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, BufferApi, BufferData};
use crate::methods::method::{Classification, ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::GlState;

/// Registry name.
pub const NAME: &str = "ray-bvh";

/// Walk steps per ray and pass. Each step runs at most 1 + 4 loop iterations: 8,192 steps stay
/// below llvmpipe's 65,535 iterations per invocation with room to spare.
pub const DEFAULT_BUDGET: u32 = 8192;

const TRACE_COMP: &str = include_str!("trace.comp.glsl");
const CLEAR_COMP: &str = include_str!("clear.comp.glsl");
const ARGS_COMP: &str = include_str!("args.comp.glsl");
const SAMPLES_FRAG: &str = include_str!("samples.frag.glsl");
const RESOLVE_FRAG: &str = include_str!("resolve.frag.glsl");
const FULLSCREEN_VERT: &str = include_str!("../../shaders/fullscreen.vert.glsl");

// Shader-storage binding points (trace.comp.glsl). Binding 0 is the renderer's normals and
// stays untouched; the renderer restores the caller's bindings after a method ran (saved.rs).
const POSITIONS: u32 = 1;
const INDICES: u32 = 2;
const SAMPLES: u32 = 3;
const NODES: u32 = 4;
const TRIANGLES: u32 = 5;
const RESULTS: u32 = 6;
const LISTS: u32 = 7;

/// Control words at the start of the lists buffer: per list its count and a
/// DispatchIndirectCommand.
const CONTROL_WORDS: usize = 8;

/// Bytes of the per-frame-size buffers at `width x height`: samples (16 per pixel), results
/// (4 per pixel), the control words and two resume lists (4 per pixel each).
pub fn frame_bytes(width: u32, height: u32) -> usize {
    let pixels = width as usize * height as usize;
    16 * pixels + 4 * pixels + 4 * (CONTROL_WORDS + 2 * pixels)
}

struct Programs {
    clear: glow::Program,
    samples: glow::Program,
    trace: glow::Program,
    args: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> [glow::Program; 5] {
        [self.clear, self.samples, self.trace, self.args, self.resolve]
    }

    fn link(gl: &glow::Context) -> Result<Programs, GlError> {
        let trace = format!(
            "#version 450 core\n#define NODE_VEC4S {}u\n#define TRIANGLE_VEC4S {}u\n#define LEAF_COUNT_BITS {}u\n\
             #define LEAF_BIT {}u\n#define FROM_PARENT {}u\n#define FROM_SIBLING {}u\n#define FROM_CHILD {}u\n\
             #define TINY {:e}\n{TRACE_COMP}",
            ray_bvh::NODE_VEC4S,
            ray_bvh::TRIANGLE_VEC4S,
            ray_bvh::LEAF_COUNT_BITS,
            ray_bvh::LEAF_BIT,
            ray_bvh::FROM_PARENT,
            ray_bvh::FROM_SIBLING,
            ray_bvh::FROM_CHILD,
            ray_bvh::Ray::TINY,
        );
        let specs: [(&str, Vec<ShaderSource<'_>>); 5] = [
            (
                "ray-bvh clear",
                vec![ShaderSource { stage: glow::COMPUTE_SHADER, name: "ray_bvh/clear.comp.glsl", source: CLEAR_COMP }],
            ),
            (
                "ray-bvh samples",
                vec![
                    ShaderSource::vertex("shaders/scene.vert.glsl", crate::scene::SCENE_VERT),
                    ShaderSource::fragment("ray_bvh/samples.frag.glsl", SAMPLES_FRAG),
                ],
            ),
            (
                "ray-bvh trace",
                vec![ShaderSource { stage: glow::COMPUTE_SHADER, name: "ray_bvh/trace.comp.glsl", source: &trace }],
            ),
            (
                "ray-bvh args",
                vec![ShaderSource { stage: glow::COMPUTE_SHADER, name: "ray_bvh/args.comp.glsl", source: ARGS_COMP }],
            ),
            (
                "ray-bvh resolve",
                vec![
                    ShaderSource::vertex("shaders/fullscreen.vert.glsl", FULLSCREEN_VERT),
                    ShaderSource::fragment("ray_bvh/resolve.frag.glsl", RESOLVE_FRAG),
                ],
            ),
        ];
        let mut done = Vec::with_capacity(specs.len());
        for (name, stages) in &specs {
            match link_program(gl, name, stages, &[]) {
                Ok(p) => done.push(p),
                Err(e) => {
                    delete_programs(gl, &done);
                    return Err(e);
                }
            }
        }
        Ok(Programs { clear: done[0], samples: done[1], trace: done[2], args: done[3], resolve: done[4] })
    }
}

fn delete_programs(gl: &glow::Context, programs: &[glow::Program]) {
    // SAFETY: programs we created, not used afterwards.
    unsafe {
        for &p in programs {
            gl.delete_program(p);
        }
    }
}

fn delete_buffers(gl: &glow::Context, buffers: &[glow::Buffer]) {
    // SAFETY: buffers we created, not used afterwards.
    unsafe {
        for &b in buffers {
            gl.delete_buffer(b);
        }
    }
}

/// Buffers holding `data` (`STATIC_DRAW` for bytes: uploaded once; `DYNAMIC_COPY` for sizes:
/// written and read by the GPU every frame), named by `names` in errors; on any failure the
/// ones made are deleted and the typed error returned.
fn make_buffers(
    gl: &glow::Context,
    data: &[BufferData<'_>],
    names: &[&'static str],
) -> Result<Vec<glow::Buffer>, GlError> {
    let mut made = Vec::with_capacity(data.len());
    for (d, &what) in data.iter().zip(names) {
        // SAFETY: creating a buffer name on the current context (deleted on error below).
        let b = match unsafe { gl.create_named_buffer() } {
            Ok(b) => b,
            Err(detail) => {
                delete_buffers(gl, &made);
                return Err(GlError::Create { what, detail });
            }
        };
        made.push(b);
        let usage = if matches!(d, BufferData::Bytes(_)) { glow::STATIC_DRAW } else { glow::DYNAMIC_COPY };
        // Checked: a refused store is this call's typed error, never an empty buffer counted
        // as ready.
        if let Err(e) = buffer_store(gl, b, BufferApi::Dsa, *d, usage, what) {
            delete_buffers(gl, &made);
            return Err(e);
        }
    }
    Ok(made)
}

fn vec4_bytes(v: &[[f32; 4]]) -> Vec<u8> {
    // At least one vec4: a buffer store of 0 bytes cannot be bound as a storage block.
    let mut out: Vec<u8> = v.iter().flatten().flat_map(|c| c.to_ne_bytes()).collect();
    if out.is_empty() {
        out.resize(16, 0);
    }
    out
}

/// Per scene: programs, the BVH's two buffers, the resolve's empty vertex array.
struct SceneObjects {
    programs: Programs,
    nodes: glow::Buffer,
    triangles: glow::Buffer,
    empty_vao: glow::VertexArray,
    node_count: u32,
    /// The reference's eps for this scene.
    eps: f32,
    bvh_bytes: usize,
    build_ms: f64,
    depth: usize,
}

/// Per frame size: samples, results, the lists with their control words.
struct FrameObjects {
    width: u32,
    height: u32,
    samples: glow::Buffer,
    results: glow::Buffer,
    lists: glow::Buffer,
    serial: Option<u64>,
}

impl FrameObjects {
    fn destroy(self, gl: &glow::Context) {
        delete_buffers(gl, &[self.samples, self.results, self.lists]);
    }
}

/// See the module documentation.
pub struct RayBvhMethod {
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
    frame: Option<FrameObjects>,
    budget: u32,
}

impl Default for RayBvhMethod {
    fn default() -> Self {
        Self::new()
    }
}

impl RayBvhMethod {
    /// Builds the method (no GL calls).
    pub fn new() -> Self {
        Self { prepared: None, scene: None, frame: None, budget: DEFAULT_BUDGET }
    }

    /// The same method with walks of at most `steps` steps per pass (at least 1; the default
    /// is [`DEFAULT_BUDGET`]): tests make walks stop and resume many times; the decision must
    /// not change.
    pub fn with_budget(steps: u32) -> Self {
        Self { budget: steps.clamp(1, DEFAULT_BUDGET), ..Self::new() }
    }

    /// Bytes of the prepared scene's BVH on the GPU (0 before `prepare`).
    pub fn scene_bytes(&self) -> usize {
        self.scene.as_ref().map_or(0, |s| s.bvh_bytes)
    }

    /// Milliseconds the CPU build of the prepared scene's BVH took (0 before `prepare`).
    pub fn build_ms(&self) -> f64 {
        self.scene.as_ref().map_or(0.0, |s| s.build_ms)
    }

    /// Resume passes a frame runs after the first: enough for the longest walk, at most 3
    /// steps per node ([`umbra_geom::ray_bvh`]).
    fn resume_passes(&self) -> u32 {
        self.scene.as_ref().map_or(0, |s| (3 * s.node_count).div_ceil(self.budget))
    }

    fn destroy_frame(&mut self, gl: &glow::Context) {
        if let Some(f) = self.frame.take() {
            f.destroy(gl);
        }
    }

    /// The frame-size objects for `width x height`, (re)allocated when the size changed.
    fn ensure_frame(&mut self, gl: &glow::Context, width: u32, height: u32) -> Result<(), GlError> {
        if self.frame.as_ref().is_some_and(|f| f.width == width && f.height == height) {
            return Ok(());
        }
        self.destroy_frame(gl);
        let pixels = width as usize * height as usize;
        let sizes = [
            BufferData::Size(16 * pixels),
            BufferData::Size(4 * pixels),
            BufferData::Size(4 * (CONTROL_WORDS + 2 * pixels)),
        ];
        let made = make_buffers(gl, &sizes, &["ray-bvh samples", "ray-bvh results", "ray-bvh lists"])?;
        self.frame =
            Some(FrameObjects { width, height, samples: made[0], results: made[1], lists: made[2], serial: None });
        Ok(())
    }

    /// Stage "samples": every pixel's sample of this frame, unless already made for its view
    /// serial.
    fn samples(&self, gl: &glow::Context, scene: &SceneGpu, frame: &mut VolumeFrame<'_>, f: &mut FrameObjects) {
        let Some(s) = self.scene.as_ref() else { return };
        let p = &s.programs;
        frame.mark(gl, "samples");
        if f.serial == Some(frame.view_serial()) {
            return;
        }
        // SAFETY: our programs and buffers; the scene's vertex array; the frame's target.
        unsafe {
            gl.use_program(Some(p.clear));
            gl.uniform_2_u32(uniform(gl, p.clear, "u_frame").as_ref(), f.width, f.height);
            gl.dispatch_compute(f.width.div_ceil(8), f.height.div_ceil(8), 1);
            // Reason: the clear's writes must land before the fragment shader's.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
        }
        GlState::visible_samples(frame.receivers).apply(gl);
        // SAFETY: as above.
        unsafe {
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, f.width as i32, f.height as i32);
            gl.use_program(Some(p.samples));
            gl.uniform_matrix_4_f32_slice(
                uniform(gl, p.samples, "u_clip_from_world").as_ref(),
                false,
                &frame.clip_from_world_f32(),
            );
            gl.uniform_1_u32(uniform(gl, p.samples, "u_width").as_ref(), f.width);
            gl.bind_vertex_array(Some(scene.vertex_array()));
        }
        scene.draw_triangles(gl);
        f.serial = Some(frame.view_serial());
    }

    /// Sets trace.comp.glsl's per-light uniforms on the current trace program.
    fn trace_uniforms(&self, gl: &glow::Context, s: &SceneObjects, f: &FrameObjects, frame: &VolumeFrame<'_>) {
        let t = s.programs.trace;
        let u = |name| uniform(gl, t, name);
        let l = frame.light;
        // SAFETY: our program, current; uniform types match trace.comp.glsl.
        unsafe {
            gl.uniform_2_u32(u("u_frame").as_ref(), f.width, f.height);
            gl.uniform_1_u32(u("u_pixels").as_ref(), f.width * f.height);
            gl.uniform_4_f32(u("u_light").as_ref(), l[0], l[1], l[2], l[3]);
            gl.uniform_1_f32(u("u_eps").as_ref(), s.eps);
            gl.uniform_1_f32(u("u_eps_near").as_ref(), 0.5 * s.eps);
            gl.uniform_1_u32(u("u_budget").as_ref(), self.budget);
        }
    }
}

impl ShadowMethod for RayBvhMethod {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["samples", "rays", "resume", "stencil"]
    }

    fn fills_volumes(&self) -> bool {
        false
    }

    fn classification(&self) -> Classification {
        Classification::StencilZero
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.destroy(gl);
        let mesh = scene.mesh();
        // SAFETY: a plain limit query on the current context.
        let fragment_blocks = unsafe { gl.get_parameter_i32(glow::MAX_FRAGMENT_SHADER_STORAGE_BLOCKS) };
        if fragment_blocks < 1 {
            return Err(GlError::Unsupported {
                method: NAME,
                reason: format!(
                    "needs a shader storage block in the fragment shader, the driver offers {fragment_blocks}"
                ),
            });
        }
        let started = Instant::now();
        let bvh: RayBvh = ray_bvh::build(&mesh.positions, &mesh.triangles);
        let build_ms = started.elapsed().as_secs_f64() * 1e3;
        let node_bytes = vec4_bytes(&bvh.nodes);
        let triangle_bytes = vec4_bytes(&bvh.triangles);
        let programs = Programs::link(gl)?;
        let buffers = match make_buffers(
            gl,
            &[BufferData::Bytes(&node_bytes), BufferData::Bytes(&triangle_bytes)],
            &["ray-bvh nodes", "ray-bvh triangles"],
        ) {
            Ok(b) => b,
            Err(e) => {
                delete_programs(gl, &programs.all());
                return Err(e);
            }
        };
        // SAFETY: object creation on the current context; deleted on the error path.
        let empty_vao = match unsafe { gl.create_named_vertex_array() } {
            Ok(v) => v,
            Err(detail) => {
                delete_buffers(gl, &buffers);
                delete_programs(gl, &programs.all());
                return Err(GlError::Create { what: "ray-bvh vertex array", detail });
            }
        };
        self.scene = Some(SceneObjects {
            programs,
            nodes: buffers[0],
            triangles: buffers[1],
            empty_vao,
            node_count: bvh.node_count() as u32,
            eps: ray_bvh::segment_epsilon(&mesh.positions) as f32,
            bvh_bytes: node_bytes.len() + triangle_bytes.len(),
            build_ms,
            depth: bvh.depth,
        });
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
        let node_count = self
            .scene
            .as_ref()
            .map(|s| s.node_count)
            .ok_or_else(|| GlError::InvalidParams("ray-bvh: draw_volumes before prepare".into()))?;
        if node_count == 0 {
            // Nothing casts a shadow: the stencil stays 0 everywhere.
            return Ok(());
        }
        self.ensure_frame(gl, frame.width, frame.height)?;
        let mut f = self.frame.take().ok_or_else(|| GlError::InvalidParams("ray-bvh: objects missing".into()))?;
        let s = self.scene.as_ref().ok_or_else(|| GlError::InvalidParams("ray-bvh: objects missing".into()))?;
        let p = &s.programs;
        // SAFETY: our buffers and the scene's (only read).
        unsafe {
            // Reason (SHADER_STORAGE): the previous light's or frame's shaders read the
            // buffers written next; BUFFER_UPDATE: the control words are uploaded next.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT | glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, INDICES, Some(scene.index_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SAMPLES, Some(f.samples));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NODES, Some(s.nodes));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, TRIANGLES, Some(s.triangles));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RESULTS, Some(f.results));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, LISTS, Some(f.lists));
        }
        self.samples(gl, scene, frame, &mut f);

        frame.mark(gl, "rays");
        let zero = [0u8; 4 * CONTROL_WORDS];
        // SAFETY: our programs and buffers; the control words lie at the lists buffer's start.
        unsafe {
            // Both lists empty (the first pass appends to list 0).
            gl.named_buffer_sub_data_u8_slice(f.lists, 0, &zero);
            // Reason: the samples pass's (or clear's) writes and the upload before the trace.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT | glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.use_program(Some(p.trace));
        }
        self.trace_uniforms(gl, s, &f, frame);
        // SAFETY: as above; uniform types match trace.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, p.trace, "u_resume").as_ref(), 0);
            gl.uniform_1_u32(uniform(gl, p.trace, "u_list_in").as_ref(), 1);
            gl.uniform_1_u32(uniform(gl, p.trace, "u_list_out").as_ref(), 0);
            gl.dispatch_compute(f.width.div_ceil(8), f.height.div_ceil(8), 1);
        }

        frame.mark(gl, "resume");
        // SAFETY: our programs; the lists buffer is the indirect source (unbound afterwards).
        unsafe {
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(f.lists));
            for pass in 0..self.resume_passes() {
                let (list_in, list_out) = (pass % 2, (pass + 1) % 2);
                // Reason: the pass before appended to the list whose count is read next.
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
                gl.use_program(Some(p.args));
                gl.uniform_1_u32(uniform(gl, p.args, "u_list_in").as_ref(), list_in);
                gl.dispatch_compute(1, 1, 1);
                // Reason: COMMAND: the next dispatch sources its size from the command just
                // written; SHADER_STORAGE: and its shader reads the lists.
                gl.memory_barrier(glow::COMMAND_BARRIER_BIT | glow::SHADER_STORAGE_BARRIER_BIT);
                gl.use_program(Some(p.trace));
                self.trace_uniforms(gl, s, &f, frame);
                gl.uniform_1_u32(uniform(gl, p.trace, "u_resume").as_ref(), 1);
                gl.uniform_1_u32(uniform(gl, p.trace, "u_list_in").as_ref(), list_in);
                gl.uniform_1_u32(uniform(gl, p.trace, "u_list_out").as_ref(), list_out);
                gl.dispatch_compute_indirect(4 * (4 * list_in as i32 + 1));
            }
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, None);
        }

        frame.mark(gl, "stencil");
        GlState::stencil_mark_resolve().apply(gl);
        // SAFETY: our program and empty vertex array; the frame's target and viewport.
        unsafe {
            // Reason: the fragment shader reads the results the compute passes wrote.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, f.width as i32, f.height as i32);
            gl.use_program(Some(p.resolve));
            gl.uniform_1_u32(uniform(gl, p.resolve, "u_width").as_ref(), f.width);
            gl.bind_vertex_array(Some(s.empty_vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.bind_vertex_array(None);
            // Leave no binding of ours behind (the renderer restores the caller's).
            for b in [POSITIONS, INDICES, SAMPLES, NODES, TRIANGLES, RESULTS, LISTS] {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, b, None);
            }
        }
        self.frame = Some(f);
        Ok(())
    }

    fn scene_figures(&self) -> Vec<(&'static str, f64)> {
        self.scene.as_ref().map_or(Vec::new(), |s| {
            vec![
                ("bvh_build_ms", s.build_ms),
                ("bvh_bytes", s.bvh_bytes as f64),
                ("bvh_nodes", f64::from(s.node_count)),
                ("bvh_depth", s.depth as f64),
            ]
        })
    }

    fn gpu_bytes(&self) -> usize {
        self.scene_bytes() + self.frame.as_ref().map_or(0, |f| frame_bytes(f.width, f.height))
    }

    fn destroy(&mut self, gl: &glow::Context) {
        self.destroy_frame(gl);
        if let Some(s) = self.scene.take() {
            delete_programs(gl, &s.programs.all());
            delete_buffers(gl, &[s.nodes, s.triangles]);
            // SAFETY: our own vertex array, not used afterwards.
            unsafe { gl.delete_vertex_array(s.empty_vao) };
        }
        self.prepared = None;
    }
}
