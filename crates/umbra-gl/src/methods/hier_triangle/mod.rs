//! `hier-triangle`: exact per-triangle shadows tested against a hierarchy of the frame's view
//! samples, in compute shaders — no shadow volume is rasterized or depth-tested.
//!
//! Erik Sintorn, Viktor Kämpe, Ola Olsson, Ulf Assarsson, "Per-Triangle Shadow Volumes Using a
//! View-Sample Cluster Hierarchy", I3D 2014. Each triangle's shadow volume is a frustum of four
//! planes (its own plane and three planes through the light and an edge); it is tested against
//! a hierarchy of clusters of view samples with 3-D bounds, top-down: a node outside the
//! frustum is dropped, a node inside is marked "all shadowed", a node it cuts is refined, and at
//! the leaves every sample is tested exactly. A sample is shadowed when any triangle's frustum
//! holds it (an OR: no counting, no multiplicity, no adjacency, no caps, no z-pass / z-fail).
//!
//! What umbra adds: the tests are the ray-traced reference's rule (`common.glsl`): a sample is
//! shadowed by another triangle whose closed, two-sided surface the segment to the light meets
//! beyond the reference's eps from the sample (half of it, see `common.glsl`) and from the
//! light, the sample's own triangle excluded (its facing is the lighting pass's test), with
//! watertight edge planes (computed in f64 from lexicographically ordered endpoints) — so the
//! decision matches `umbra verify`'s reference outside the band, and none of the band's
//! depth-test precision classes concern it (docs/exactness.md).
//!
//! Per frame (once for all lights; [`VolumeFrame::view_serial`]):
//! 1. "samples": the samples buffer is cleared, then the scene is drawn with the renderer's own
//!    vertex shader over the frame's depth, depth func EQUAL, all writes masked: the fragment
//!    shader (`samples.frag.glsl`, early fragment tests) stores each visible sample's world
//!    position and triangle id — the same samples the renderer's depth pass produced;
//! 2. "hierarchy": `bounds.comp.glsl`, the boxes of the leaves (8 x 8 pixels) and of every
//!    level above (4 x 4 children), [`layout`].
//!
//! Per light:
//! 3. "frusta": the state (queue counts, covered flags, leaf masks) cleared; `setup.comp.glsl`,
//!    one invocation per triangle: its four planes, then its test against every top node;
//! 4. "traversal": per level from the top, `args.comp.glsl` sizes an indirect dispatch from the
//!    queue's count and `descend.comp.glsl` tests each queued pair's 16 children;
//! 5. "leaves": `leaves.comp.glsl`, one workgroup per (triangle, leaf) pair, one invocation per
//!    sample: the exact test, an atomic OR into the leaf's 64-bit mask;
//! 6. "stencil": `resolve.frag.glsl` on a full-screen triangle writes stencil 1 where the sample
//!    is shadowed (its bit, or its leaf or an ancestor covered): [`Classification::StencilZero`]
//!    as every counting method, so the lighting pass, [`crate::Renderer::count_shadows`] and
//!    `umbra verify` read it unchanged ([`ShadowMethod::fills_volumes`] is false: the renderer
//!    clears the stencil to 0 and sets up no counting for it).
//!
//! Bounds on work and memory: every shader loop runs at most 64 iterations (a leaf's samples,
//! a node's 16 children), except the setup's loop over the top nodes (at most
//! [`layout::MAX_TOP_NODES`] unless the frame is wider than 8 top levels allow), far below
//! llvmpipe's 65,535. The queues have a fixed capacity per frame size and scene
//! ([`layout::queue_capacity`]); a pair that does not fit is processed by the invocation that
//! found it, descending depth-first through nested loops of at most 64 iterations (the
//! generated fallback chain): slower, never wrong. Memory: [`layout::Layout::frame_bytes`] per
//! frame size plus [`layout::plane_bytes`] per scene (docs/benchmarks.md states it per
//! resolution). Every allocation is checked: one the GL refuses is [`GlError::OutOfMemory`],
//! nothing is left behind and the method stays usable (at another size, or later).
//!
//! Samples are the visible surfaces of *umbra's scene*: with
//! [`crate::Renderer::count_shadows`] on a caller's depth that also holds other geometry, the
//! pixels of that geometry get no sample and stay lit (stencil 0).
//!
//! Stages reported: "samples", "hierarchy", "frusta", "traversal", "leaves", "stencil".

pub mod layout;

use glow::HasContext;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, BufferApi, BufferData};
use crate::methods::{Classification, ShadowMethod, VolumeFrame};
use crate::program::{link_program, uniform, ShaderSource};
use crate::scene::{SceneGpu, SceneId};
use crate::state::{GlState, StencilFace};
use layout::{Layout, BRANCH_SIDE, CHILDREN, LEAF_SAMPLES, LEAF_SIDE, MAX_LEVELS, MAX_UPPER_LEVELS};

/// Registry name.
pub const NAME: &str = "hier-triangle";

const COMMON: &str = include_str!("common.glsl");
const CLEAR_COMP: &str = include_str!("clear.comp.glsl");
const BOUNDS_COMP: &str = include_str!("bounds.comp.glsl");
const SETUP_COMP: &str = include_str!("setup.comp.glsl");
const DESCEND_COMP: &str = include_str!("descend.comp.glsl");
const LEAVES_COMP: &str = include_str!("leaves.comp.glsl");
const ARGS_COMP: &str = include_str!("args.comp.glsl");
const SAMPLES_FRAG: &str = include_str!("samples.frag.glsl");
const RESOLVE_VERT: &str = include_str!("resolve.vert.glsl");
const RESOLVE_FRAG: &str = include_str!("resolve.frag.glsl");

// Shader-storage binding points (common.glsl). Binding 0 is the renderer's normals and stays
// untouched; 1-7 are restored by the renderer after the method ran (saved.rs).
const POSITIONS: u32 = 1;
const INDICES: u32 = 2;
const SAMPLES: u32 = 3;
const NODES: u32 = 4;
const STATE: u32 = 5;
const PLANES: u32 = 6;
const QUEUES: u32 = 7;

/// `local_size_x` of every compute shader except args.comp.glsl.
const WORKGROUP: u32 = 64;

/// The reference's self-intersection eps (umbra_oracle::segment_epsilon, which this must
/// equal): `1e-5` of the larger of the bounding-box diagonal and the largest absolute
/// coordinate, over the finite positions; 0 without one.
pub fn segment_epsilon(positions: &[[f32; 3]]) -> f64 {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut largest = 0f64;
    for p in positions.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        for k in 0..3 {
            let c = f64::from(p[k]);
            min[k] = min[k].min(c);
            max[k] = max[k].max(c);
            largest = largest.max(c.abs());
        }
    }
    if min[0] > max[0] {
        return 0.0;
    }
    let diagonal = (0..3).map(|k| (max[k] - min[k]).powi(2)).sum::<f64>().sqrt();
    1e-5 * diagonal.max(largest)
}

/// The GLSL text before every stage's own source: version, the layout constants, and (for the
/// compute shaders and the resolve) common.glsl.
fn header() -> String {
    format!(
        "#version 450 core\n#define LEAF_SIDE {LEAF_SIDE}u\n#define LEAF_SAMPLES {LEAF_SAMPLES}u\n\
         #define BRANCH_SIDE {BRANCH_SIDE}u\n#define CHILDREN {CHILDREN}u\n#define MAX_LEVELS {MAX_LEVELS}\n\
         #define NO_TRIANGLE 0xFFFFFFFFu\n{COMMON}\n"
    )
}

/// The fallback chain: `descend_into(tri, level, node)` queues a pair whose node the
/// triangle's frustum cuts, or, when the level's queue is full, processes it at once with
/// `inline_level{level}` — nested loops, one per level, of at most 64 iterations each (no
/// recursion in GLSL; llvmpipe ends any loop after 65,535 iterations).
fn fallback_chain() -> String {
    let mut s = String::from(
        "void inline_level0(uint tri, uint node) {\n    for (uint k = 0u; k < LEAF_SAMPLES; ++k) {\n        \
         test_sample(tri, node, k);\n    }\n}\n",
    );
    for l in 1..=MAX_UPPER_LEVELS {
        s += &format!(
            "void inline_level{l}(uint tri, uint node) {{\n    for (uint k = 0u; k < CHILDREN; ++k) {{\n        \
             uint child;\n        if (child_of({l}u, node, k, child) && visit(tri, {}u, child) == PARTIAL) {{\n            \
             inline_level{}(tri, child);\n        }}\n    }}\n}}\n",
            l - 1,
            l - 1
        );
    }
    s += "void inline_level(uint level, uint tri, uint node) {\n    switch (level) {\n";
    for l in 0..=MAX_UPPER_LEVELS {
        s += &format!("    case {l}u: inline_level{l}(tri, node); break;\n");
    }
    s += "    default: break;\n    }\n}\n";
    s += "// A pair whose node the frustum cuts: queued for the next pass, or processed at once.\n\
          void descend_into(uint tri, uint level, uint node) {\n    \
          uint slot = atomicAdd(state[4u * level], 1u);\n    \
          if (slot < u_queue_capacity[level]) {\n        queue[u_level[level].w + slot] = uvec2(tri, node);\n    \
          } else {\n        inline_level(level, tri, node);\n    }\n}\n";
    s
}

struct Programs {
    clear: glow::Program,
    samples: glow::Program,
    bounds: glow::Program,
    setup: glow::Program,
    descend: glow::Program,
    leaves: glow::Program,
    args: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> [glow::Program; 8] {
        [self.clear, self.samples, self.bounds, self.setup, self.descend, self.leaves, self.args, self.resolve]
    }

    fn link(gl: &glow::Context) -> Result<Programs, GlError> {
        let head = header();
        let chain = fallback_chain();
        let comp = |body: &str, with_chain: bool| {
            if with_chain {
                format!("{head}{chain}\n{body}")
            } else {
                format!("{head}\n{body}")
            }
        };
        let sources = [
            ("hier-triangle clear", comp(CLEAR_COMP, false), "clear.comp.glsl"),
            ("hier-triangle bounds", comp(BOUNDS_COMP, false), "bounds.comp.glsl"),
            ("hier-triangle setup", comp(SETUP_COMP, true), "setup.comp.glsl"),
            ("hier-triangle descend", comp(DESCEND_COMP, true), "descend.comp.glsl"),
            ("hier-triangle leaves", comp(LEAVES_COMP, false), "leaves.comp.glsl"),
            ("hier-triangle args", comp(ARGS_COMP, false), "args.comp.glsl"),
        ];
        let resolve_frag = format!("{head}\n{RESOLVE_FRAG}");
        let mut done: Vec<glow::Program> = Vec::new();
        let mut link_one = |name: &str, stages: &[ShaderSource<'_>]| -> Result<(), GlError> {
            done.push(link_program(gl, name, stages, &[])?);
            Ok(())
        };
        let mut result = Ok(());
        for (name, source, file) in &sources {
            result = result
                .and_then(|()| link_one(name, &[ShaderSource { stage: glow::COMPUTE_SHADER, name: file, source }]));
        }
        result = result.and_then(|()| {
            link_one(
                "hier-triangle samples",
                &[
                    ShaderSource::vertex("shaders/scene.vert.glsl", crate::renderer::SCENE_VERT),
                    ShaderSource::fragment("samples.frag.glsl", SAMPLES_FRAG),
                ],
            )
        });
        result = result.and_then(|()| {
            link_one(
                "hier-triangle resolve",
                &[
                    ShaderSource::vertex("resolve.vert.glsl", RESOLVE_VERT),
                    ShaderSource::fragment("resolve.frag.glsl", &resolve_frag),
                ],
            )
        });
        if let Err(e) = result {
            // SAFETY: programs we created, not used afterwards.
            unsafe {
                for p in done {
                    gl.delete_program(p);
                }
            }
            return Err(e);
        }
        Ok(Programs {
            clear: done[0],
            bounds: done[1],
            setup: done[2],
            descend: done[3],
            leaves: done[4],
            args: done[5],
            samples: done[6],
            resolve: done[7],
        })
    }
}

/// Per scene: programs, the plane buffer, the resolve's empty vertex array.
struct SceneObjects {
    programs: Programs,
    planes: glow::Buffer,
    empty_vao: glow::VertexArray,
    triangles: usize,
    max_groups: u32,
    /// The reference's eps for this scene, and the origin of directional planes (the centre
    /// of the scene's bounds).
    eps: f32,
    centre: [f32; 3],
}

/// Per frame size: samples, node bounds, state, queues.
struct FrameObjects {
    layout: Layout,
    samples: glow::Buffer,
    nodes: glow::Buffer,
    state: glow::Buffer,
    queues: glow::Buffer,
    /// The view serial the samples and bounds were made for.
    serial: Option<u64>,
}

impl FrameObjects {
    fn buffers(&self) -> [glow::Buffer; 4] {
        [self.samples, self.nodes, self.state, self.queues]
    }
}

/// See the module documentation.
pub struct HierTriangle {
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
    frame: Option<FrameObjects>,
    queue_scale: f64,
}

impl Default for HierTriangle {
    fn default() -> Self {
        Self::new()
    }
}

impl HierTriangle {
    /// Builds the method (no GL calls).
    pub fn new() -> Self {
        Self { prepared: None, scene: None, frame: None, queue_scale: 1.0 }
    }

    /// The same method with every queue's capacity multiplied by `scale` (> 0): tests shrink
    /// the queues to send pairs down the fallback chain; the decision must not change.
    pub fn with_queue_scale(scale: f64) -> Self {
        Self { queue_scale: if scale > 0.0 && scale.is_finite() { scale } else { 1.0 }, ..Self::new() }
    }

    /// The layout of the last frame size drawn, if any.
    pub fn layout(&self) -> Option<&Layout> {
        self.frame.as_ref().map(|f| &f.layout)
    }

    /// Per level (leaves first): the pairs the last light queued at that level — more than the
    /// capacity when some went down the fallback chain — and the capacity. Reads the GPU's
    /// counters back (a stall): for tests and statistics, not for frames.
    pub fn queue_counts(&self, gl: &glow::Context) -> Vec<(u32, u32)> {
        let Some(f) = self.frame.as_ref() else { return Vec::new() };
        let mut bytes = vec![0u8; 4 * layout::CONTROL_WORDS];
        // SAFETY: reading the control words of our own state buffer (at least CONTROL_WORDS
        // long) through COPY_READ_BUFFER, unbound again afterwards (the renderer restores the
        // caller's binding around frames; here we restore none, so leave it unbound).
        unsafe {
            gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(f.state));
            gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, 0, &mut bytes);
            gl.bind_buffer(glow::COPY_READ_BUFFER, None);
        }
        let words: Vec<u32> = bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
        f.layout.levels.iter().enumerate().map(|(l, level)| (words[4 * l], level.queue_capacity)).collect()
    }

    fn destroy_frame(&mut self, gl: &glow::Context) {
        if let Some(f) = self.frame.take() {
            // SAFETY: our own buffers, not used afterwards.
            unsafe {
                for b in f.buffers() {
                    gl.delete_buffer(b);
                }
            }
        }
    }

    /// The frame-size objects for `width x height`, (re)allocated when the size changed.
    fn ensure_frame(&mut self, gl: &glow::Context, width: u32, height: u32, triangles: usize) -> Result<(), GlError> {
        if self.frame.as_ref().is_some_and(|f| f.layout.width == width && f.layout.height == height) {
            return Ok(());
        }
        self.destroy_frame(gl);
        let layout = Layout::new(width, height, triangles, self.queue_scale);
        let sizes = [
            (layout.sample_bytes(), "hier-triangle samples"),
            (layout.node_bytes(), "hier-triangle node bounds"),
            (layout.state_bytes(), "hier-triangle state"),
            (layout.queue_bytes(), "hier-triangle queues"),
        ];
        let mut made = Vec::with_capacity(4);
        let mut failure = None;
        for (bytes, what) in sizes {
            // SAFETY: creating a buffer name on the current context (deleted on error below).
            match unsafe { gl.create_named_buffer() } {
                Ok(b) => {
                    made.push(b);
                    // Written and read by the GPU every frame: DYNAMIC_COPY. Checked: a refused
                    // store is this call's typed error, never an empty buffer counted as ready.
                    if let Err(e) =
                        buffer_store(gl, b, BufferApi::Dsa, BufferData::Size(bytes), glow::DYNAMIC_COPY, what)
                    {
                        failure = Some(e);
                        break;
                    }
                }
                Err(detail) => {
                    failure = Some(GlError::Create { what, detail });
                    break;
                }
            }
        }
        if let Some(e) = failure {
            // SAFETY: our own buffers, never handed out.
            unsafe {
                for b in made {
                    gl.delete_buffer(b);
                }
            }
            return Err(e);
        }
        self.frame = Some(FrameObjects {
            layout,
            samples: made[0],
            nodes: made[1],
            state: made[2],
            queues: made[3],
            serial: None,
        });
        Ok(())
    }

    /// Runs `count` invocations of `program` (current) in chunks of at most `max_groups`
    /// workgroups of [`WORKGROUP`], telling the shader where each chunk starts (`u_first`).
    fn dispatch(gl: &glow::Context, program: glow::Program, count: usize, max_groups: u32) {
        let first = uniform(gl, program, "u_first");
        let per_dispatch = max_groups as usize * WORKGROUP as usize;
        let mut start = 0usize;
        while start < count {
            let n = (count - start).min(per_dispatch);
            // SAFETY: the program is current; n.div_ceil(WORKGROUP) <= max_groups.
            unsafe {
                gl.uniform_1_u32(first.as_ref(), start as u32);
                gl.dispatch_compute(n.div_ceil(WORKGROUP as usize) as u32, 1, 1);
            }
            start += n;
        }
    }

    /// Sets common.glsl's uniforms on `program` (made current here).
    fn use_with_common(gl: &glow::Context, program: glow::Program, layout: &Layout, light: &LightUniforms) {
        let mut level_words = [0u32; 4 * MAX_LEVELS];
        let mut capacities = [0u32; MAX_LEVELS];
        for (l, level) in layout.levels.iter().enumerate() {
            level_words[4 * l..4 * l + 4].copy_from_slice(&[
                level.width,
                level.height,
                level.first_node,
                level.first_pair,
            ]);
            capacities[l] = level.queue_capacity;
        }
        let u = |name| uniform(gl, program, name);
        // SAFETY: our linked program; uniform types match common.glsl.
        unsafe {
            gl.use_program(Some(program));
            gl.uniform_2_u32(u("u_frame").as_ref(), layout.width, layout.height);
            gl.uniform_1_u32(u("u_levels").as_ref(), layout.levels.len() as u32);
            gl.uniform_4_u32_slice(u("u_level").as_ref(), &level_words);
            gl.uniform_1_u32_slice(u("u_queue_capacity").as_ref(), &capacities);
            gl.uniform_1_u32(u("u_covered_offset").as_ref(), layout.covered_offset() as u32);
            gl.uniform_1_u32(u("u_bits_offset").as_ref(), layout.bits_offset() as u32);
            gl.uniform_4_f32_slice(u("u_light").as_ref(), &light.light);
            gl.uniform_3_f32_slice(u("u_dir").as_ref(), &light.dir);
            gl.uniform_3_f32_slice(u("u_origin").as_ref(), &light.origin);
            gl.uniform_1_f32(u("u_eps").as_ref(), light.eps);
            gl.uniform_1_f32(u("u_eps_near").as_ref(), 0.5 * light.eps);
        }
    }

    /// Clears `count` elements of the samples (`what` 0) or state (`what` 1) buffer.
    fn clear(gl: &glow::Context, s: &SceneObjects, layout: &Layout, light: &LightUniforms, what: u32, count: usize) {
        Self::use_with_common(gl, s.programs.clear, layout, light);
        // SAFETY: our program; uniform types match clear.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, s.programs.clear, "u_count").as_ref(), count as u32);
            gl.uniform_1_u32(uniform(gl, s.programs.clear, "u_what").as_ref(), what);
        }
        Self::dispatch(gl, s.programs.clear, count, s.max_groups);
    }
}

/// common.glsl's light uniforms for one light.
struct LightUniforms {
    light: [f32; 4],
    dir: [f32; 3],
    origin: [f32; 3],
    eps: f32,
}

impl LightUniforms {
    fn new(light: [f32; 4], scene: &SceneObjects) -> Self {
        let point = light[3] != 0.0;
        let len = light[..3].iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt();
        let dir = if point || len == 0.0 { [0.0; 3] } else { [0, 1, 2].map(|k| (f64::from(light[k]) / len) as f32) };
        let origin = if point { [0, 1, 2].map(|k| light[k] / light[3]) } else { scene.centre };
        Self { light, dir, origin, eps: scene.eps }
    }
}

impl ShadowMethod for HierTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["samples", "hierarchy", "frusta", "traversal", "leaves", "stencil"]
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
        let triangles = mesh.triangles.len();
        // SAFETY: plain limit queries on the current context.
        let (fragment_blocks, max_groups) = unsafe {
            (
                gl.get_parameter_i32(glow::MAX_FRAGMENT_SHADER_STORAGE_BLOCKS),
                gl.get_parameter_indexed_i32(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 0),
            )
        };
        if fragment_blocks < 7 {
            return Err(GlError::Unsupported {
                method: NAME,
                reason: format!(
                    "needs 7 shader storage blocks in the fragment shader, the driver offers {fragment_blocks}"
                ),
            });
        }
        let plane_bytes = layout::plane_bytes(triangles.max(1));
        crate::scene::checked_size(plane_bytes, "hier-triangle planes")?;
        let programs = Programs::link(gl)?;
        let delete_programs = |gl: &glow::Context, p: &Programs| {
            // SAFETY: programs we created, not used afterwards.
            unsafe {
                for q in p.all() {
                    gl.delete_program(q);
                }
            }
        };
        // SAFETY: object creation on the current context; deleted on every error path.
        let planes = match unsafe { gl.create_named_buffer() } {
            Ok(b) => b,
            Err(detail) => {
                delete_programs(gl, &programs);
                return Err(GlError::Create { what: "hier-triangle planes", detail });
            }
        };
        if let Err(e) = buffer_store(
            gl,
            planes,
            BufferApi::Dsa,
            BufferData::Size(plane_bytes),
            glow::DYNAMIC_COPY,
            "hier-triangle planes",
        ) {
            // SAFETY: our own buffer.
            unsafe { gl.delete_buffer(planes) };
            delete_programs(gl, &programs);
            return Err(e);
        }
        // SAFETY: as above.
        let empty_vao = match unsafe { gl.create_named_vertex_array() } {
            Ok(v) => v,
            Err(detail) => {
                // SAFETY: our own buffer.
                unsafe { gl.delete_buffer(planes) };
                delete_programs(gl, &programs);
                return Err(GlError::Create { what: "hier-triangle vertex array", detail });
            }
        };
        let centre = scene.bounds().map_or([0.0; 3], |b| b.center());
        self.scene = Some(SceneObjects {
            programs,
            planes,
            empty_vao,
            triangles,
            max_groups: max_groups.clamp(1, i32::MAX) as u32,
            eps: segment_epsilon(&mesh.positions) as f32,
            centre,
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
        let triangles = self
            .scene
            .as_ref()
            .map(|s| s.triangles)
            .ok_or_else(|| GlError::InvalidParams("hier-triangle: draw_volumes before prepare".into()))?;
        if triangles == 0 {
            // Nothing casts a shadow: the stencil stays 0 everywhere.
            return Ok(());
        }
        self.ensure_frame(gl, frame.width, frame.height, triangles)?;
        let (Some(s), Some(f)) = (self.scene.as_ref(), self.frame.as_mut()) else {
            return Err(GlError::InvalidParams("hier-triangle: objects missing".into()));
        };
        let layout = f.layout.clone();
        let light = LightUniforms::new(frame.light, s);
        let p = &s.programs;
        let pixels = layout.width as usize * layout.height as usize;
        let serial = frame.view_serial();

        frame.mark(gl, "samples");
        let fresh = f.serial != Some(serial);
        // SAFETY: our programs and buffers; the scene's buffers and vertex array are only read.
        unsafe {
            // Reason (SHADER_STORAGE): the previous light's or frame's shaders read the buffers
            // written below. BUFFER_UPDATE: queue_counts may have read the state.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT | glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, INDICES, Some(scene.index_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SAMPLES, Some(f.samples));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NODES, Some(f.nodes));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, STATE, Some(f.state));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, PLANES, Some(s.planes));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, QUEUES, Some(f.queues));
        }
        if fresh {
            Self::clear(gl, s, &layout, &light, 0, pixels);
            GlState {
                // Reason: exactly the visible surface of each pixel: the renderer's invariant
                // vertex shader gives the depth pass's depths bit for bit, EQUAL selects them
                // (either depth convention), and early_fragment_tests applies the test before
                // the shader's buffer write.
                depth_test: true,
                depth_func: glow::EQUAL,
                // Reason: the frame's depth is final; nothing but the samples buffer is written.
                depth_write: false,
                // Reason: the same clipping as the depth pass, or depths could differ.
                depth_clamp: false,
                stencil_test: false,
                stencil_front: StencilFace::KEEP,
                stencil_back: StencilFace::KEEP,
                // Reason: no colour output (the frame's colour stays untouched).
                color_write: [false; 4],
                // Reason: two-sided surfaces, as in the depth pass.
                cull_face: None,
                front_face: glow::CCW,
                blend: None,
                polygon_offset: None,
            }
            .apply(gl);
            // SAFETY: our program and the scene's vertex array; the frame's target is bound.
            unsafe {
                // Reason: the clear's writes must land before the fragment shader's.
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
                gl.viewport(0, 0, layout.width as i32, layout.height as i32);
                gl.use_program(Some(p.samples));
                gl.uniform_matrix_4_f32_slice(
                    uniform(gl, p.samples, "u_clip_from_world").as_ref(),
                    false,
                    &frame.clip_from_world_f32(),
                );
                gl.uniform_1_u32(uniform(gl, p.samples, "u_width").as_ref(), layout.width);
                gl.bind_vertex_array(Some(scene.vertex_array()));
            }
            scene.draw_triangles(gl);
            frame.mark(gl, "hierarchy");
            for (l, level) in layout.levels.iter().enumerate() {
                // SAFETY: barrier only. Reason: each level reads what the previous one (or the
                // sample pass's fragment shader) wrote.
                unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
                Self::use_with_common(gl, p.bounds, &layout, &light);
                // SAFETY: our program; uniform type matches bounds.comp.glsl.
                unsafe { gl.uniform_1_u32(uniform(gl, p.bounds, "u_bounds_level").as_ref(), l as u32) };
                Self::dispatch(gl, p.bounds, level.nodes() as usize, s.max_groups);
            }
            f.serial = Some(serial);
        } else {
            frame.mark(gl, "hierarchy");
        }

        frame.mark(gl, "frusta");
        // SAFETY: barrier only. Reason: the bounds (or the previous light's passes) are read
        // or overwritten next.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        Self::clear(gl, s, &layout, &light, 1, layout.state_words());
        // SAFETY: barrier only. Reason: the cleared state is read by the setup.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        Self::use_with_common(gl, p.setup, &layout, &light);
        // SAFETY: our program; uniform type matches setup.comp.glsl.
        unsafe { gl.uniform_1_u32(uniform(gl, p.setup, "u_triangle_count").as_ref(), triangles as u32) };
        Self::dispatch(gl, p.setup, triangles, s.max_groups);

        frame.mark(gl, "traversal");
        // SAFETY: our programs and the state buffer as the indirect dispatch source; the
        // commands are written by args.comp.glsl right before each dispatch.
        unsafe {
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(f.state));
            let top = layout.levels.len() - 1;
            for l in (0..=top).rev() {
                // Reason (SHADER_STORAGE): the queue's count and pairs were written by the pass
                // before (atomics and stores).
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
                Self::use_with_common(gl, p.args, &layout, &light);
                let per_group = if l == 0 { 1 } else { WORKGROUP / CHILDREN };
                gl.uniform_1_u32(uniform(gl, p.args, "u_args_level").as_ref(), l as u32);
                gl.uniform_1_u32(uniform(gl, p.args, "u_pairs_per_group").as_ref(), per_group);
                gl.dispatch_compute(1, 1, 1);
                // Reason: COMMAND: the dispatch below sources its size from the command just
                // written; SHADER_STORAGE: and its shader reads that state.
                gl.memory_barrier(glow::COMMAND_BARRIER_BIT | glow::SHADER_STORAGE_BARRIER_BIT);
                let offset = (4 * (4 * l + 1)) as i32;
                if l == 0 {
                    frame.mark(gl, "leaves");
                    Self::use_with_common(gl, p.leaves, &layout, &light);
                } else {
                    Self::use_with_common(gl, p.descend, &layout, &light);
                    gl.uniform_1_u32(uniform(gl, p.descend, "u_pass_level").as_ref(), l as u32);
                }
                gl.dispatch_compute_indirect(offset);
            }
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, None);
        }

        frame.mark(gl, "stencil");
        let shadowed = StencilFace {
            // Reason: every surviving fragment (a shadowed sample) writes 1 = "not lit".
            func: glow::ALWAYS,
            reference: 1,
            value_mask: 0xFF,
            write_mask: 0xFF,
            stencil_fail: glow::KEEP,
            depth_fail: glow::KEEP,
            depth_pass: glow::REPLACE,
        };
        GlState {
            // Reason: the decision is per pixel, already made; no depth involved.
            depth_test: false,
            depth_func: glow::ALWAYS,
            depth_write: false,
            depth_clamp: false,
            stencil_test: true,
            stencil_front: shadowed,
            stencil_back: shadowed,
            // Reason: only the stencil is written.
            color_write: [false; 4],
            cull_face: None,
            front_face: glow::CCW,
            blend: None,
            polygon_offset: None,
        }
        .apply(gl);
        // SAFETY: our program and empty vertex array; the frame's target and viewport.
        unsafe {
            // Reason: the fragment shader reads the masks and flags the compute passes wrote.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, layout.width as i32, layout.height as i32);
        }
        Self::use_with_common(gl, p.resolve, &layout, &light);
        // SAFETY: as above; three vertices of the full-screen triangle.
        unsafe {
            gl.bind_vertex_array(Some(s.empty_vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.bind_vertex_array(None);
            // Leave no binding of ours behind (the renderer restores the caller's 1-7).
            for b in [POSITIONS, INDICES, SAMPLES, NODES, STATE, PLANES, QUEUES] {
                gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, b, None);
            }
        }
        Ok(())
    }

    fn gpu_bytes(&self) -> usize {
        self.scene.as_ref().map_or(0, |s| layout::plane_bytes(s.triangles.max(1)))
            + self.frame.as_ref().map_or(0, |f| f.layout.frame_bytes())
    }

    fn destroy(&mut self, gl: &glow::Context) {
        self.destroy_frame(gl);
        if let Some(s) = self.scene.take() {
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                for p in s.programs.all() {
                    gl.delete_program(p);
                }
                gl.delete_buffer(s.planes);
                gl.delete_vertex_array(s.empty_vao);
            }
        }
        self.prepared = None;
    }
}
