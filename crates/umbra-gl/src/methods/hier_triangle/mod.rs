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
//! 2. "hierarchy": `bounds.comp.glsl`, per node (leaves of 4 x 4 pixels, then 4 x 4 children
//!    per level up to one root, [`layout`]) the world box of its samples and the range of their
//!    clip w (with the node's screen tile: a frustum slab).
//!
//! Per light:
//! 3. "light-bounds": `light_bounds.comp.glsl`, per node the bound of its samples' directions
//!    from the light; the per-light state cleared;
//! 4. "batches": the triangles, largest first, in batches ([`layout::batches`]); per batch
//!    `setup.comp.glsl` (one invocation per triangle: its planes in f64, its direction bound,
//!    its test against the root), per level `args.comp.glsl` + `descend.comp.glsl` (the
//!    children of each queued pair), then `leaves.comp.glsl` (one workgroup per leaf with
//!    pairs, one invocation per sample: the exact test against the leaf's list; afterwards the
//!    leaf, and each ancestor whose samples are then all shadowed, is marked covered, which the
//!    later batches skip);
//! 5. "redo": [`layout::REDO_ROUNDS`] rounds of the same passes over the triangles a full queue
//!    turned away; "fallback": `fallback.comp.glsl`, what is still left, one invocation per
//!    triangle descending depth-first (normally no workgroup at all);
//! 6. "stencil": `resolve.frag.glsl` on a full-screen triangle writes stencil 1 where the sample
//!    is shadowed (its bit, or its leaf or an ancestor covered): [`Classification::StencilZero`]
//!    as every counting method, so the lighting pass, [`crate::Renderer::count_shadows`] and
//!    `umbra verify` read it unchanged ([`ShadowMethod::fills_volumes`] is false: the renderer
//!    clears the stencil to 0 and sets up no counting for it).
//!
//! A node is tested against a triangle's frustum with three bounds of its samples, each
//! conservative by a rounding margin: the world box, the frustum slab and the direction bound
//! (`common.glsl`, classify_node). Found while measuring (Sibenik, 320 x 180): with the world
//! box alone, 97 % of the (triangle, leaf) pairs it let through held no sample inside the
//! frustum; the slab, the direction bounds and the triangle's own direction bound (a small
//! triangle's cone is missed by most nodes near it, which its edge planes alone cannot show)
//! halved the pairs, and 4 x 4 leaves instead of 8 x 8 cut the per-sample work by 2.7.
//!
//! Bounds on work and memory: every shader loop runs at most 64 iterations (a leaf's samples,
//! a node's 16 children, the top nodes), except the walk of a leaf's list, two nested loops of
//! at most 65,535 steps each, so llvmpipe's silent end of a loop at 65,535 iterations can never
//! cut work short. The queues have a fixed capacity per frame size ([`layout::queue_capacity`]);
//! a pair that does not fit sends its triangle to a redo list (bounded by the triangle count):
//! slower, never wrong. The fallback descends through nested loops of at most 64 iterations
//! (the generated chain) in a program of its own: llvmpipe runs a shader's untaken branches
//! under a mask, so the chain inlined into the main passes made them 10 times slower even when
//! no queue overflowed (measured). Memory: [`layout::Layout::frame_bytes`] per frame size plus
//! [`layout::plane_bytes`] per scene (docs/benchmarks.md states it per resolution). Every
//! allocation is checked: one the GL refuses is [`GlError::OutOfMemory`], nothing is left
//! behind and the method stays usable (at another size, or later).
//!
//! Samples are the visible surfaces of *umbra's scene*: with
//! [`crate::Renderer::count_shadows`] on a caller's depth that also holds other geometry, the
//! pixels of that geometry get no sample and stay lit (stencil 0).
//!
//! Stages reported: "samples", "hierarchy", "light-bounds", "batches", "redo", "fallback",
//! "stencil".

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
const LIGHT_BOUNDS_COMP: &str = include_str!("light_bounds.comp.glsl");
const SETUP_COMP: &str = include_str!("setup.comp.glsl");
const DESCEND_COMP: &str = include_str!("descend.comp.glsl");
const LEAVES_COMP: &str = include_str!("leaves.comp.glsl");
const ARGS_COMP: &str = include_str!("args.comp.glsl");
const FALLBACK_COMP: &str = include_str!("fallback.comp.glsl");
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

/// Triangle ids by decreasing area (f64, ties by id): the batches' order. Large triangles cast
/// the large shadows; processed first, they cover whole nodes that the many small triangles of
/// later batches then skip.
pub fn largest_first(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<u32> {
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| glam::DVec3::from(positions[i as usize].map(f64::from)));
        (b - a).cross(c - a).length()
    };
    let mut keyed: Vec<(f64, u32)> = triangles.iter().enumerate().map(|(i, t)| (area(t), i as u32)).collect();
    keyed.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    keyed.into_iter().map(|(_, i)| i).collect()
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

/// The fallback chain of fallback.comp.glsl: `inline_level(level, tri, node)` processes a pair
/// whose node the triangle's frustum cuts down to the samples, through `inline_level{l}` —
/// nested loops, one per level, of at most 64 iterations each (no recursion in GLSL; llvmpipe
/// ends any loop after 65,535 iterations).
fn fallback_chain() -> String {
    let mut s = String::from(
        "void inline_level0(uint tri, uint node) {\n    for (uint k = 0u; k < LEAF_SAMPLES; ++k) {\n        \
         test_sample(tri, node, k);\n    }\n}\n",
    );
    for l in 1..=MAX_UPPER_LEVELS {
        s += &format!(
            "void inline_level{l}(uint tri, uint node) {{\n    for (uint k = 0u; k < CHILDREN; ++k) {{\n        \
             uint child;\n        if (child_of({l}u, node, k, child) && visit(load_frustum(tri), {}u, child) == PARTIAL) {{\n            \
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
    s
}

struct Programs {
    clear: glow::Program,
    light_bounds: glow::Program,
    fallback: glow::Program,
    samples: glow::Program,
    bounds: glow::Program,
    setup: glow::Program,
    descend: glow::Program,
    leaves: glow::Program,
    args: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> [glow::Program; 10] {
        [
            self.clear,
            self.light_bounds,
            self.fallback,
            self.samples,
            self.bounds,
            self.setup,
            self.descend,
            self.leaves,
            self.args,
            self.resolve,
        ]
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
            ("hier-triangle setup", comp(SETUP_COMP, false), "setup.comp.glsl"),
            ("hier-triangle descend", comp(DESCEND_COMP, false), "descend.comp.glsl"),
            ("hier-triangle leaves", comp(LEAVES_COMP, false), "leaves.comp.glsl"),
            ("hier-triangle args", comp(ARGS_COMP, false), "args.comp.glsl"),
            ("hier-triangle light bounds", comp(LIGHT_BOUNDS_COMP, false), "light_bounds.comp.glsl"),
            ("hier-triangle fallback", comp(FALLBACK_COMP, true), "fallback.comp.glsl"),
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
            light_bounds: done[6],
            fallback: done[7],
            samples: done[8],
            resolve: done[9],
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
    /// Triangle ids, largest area first (the order of the batches).
    order: Vec<u32>,
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

    /// The control words of the state buffer (queue counts, dispatch commands, redo count)
    /// read back (a stall): for tests and statistics, not for frames.
    fn control_words(&self, gl: &glow::Context) -> Vec<u32> {
        let Some(f) = self.frame.as_ref() else { return Vec::new() };
        let mut bytes = vec![0u8; 4 * layout::CONTROL_WORDS];
        // SAFETY: reading the control words of our own state buffer (at least CONTROL_WORDS
        // long) through COPY_READ_BUFFER, unbound again afterwards.
        unsafe {
            gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(f.state));
            gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, 0, &mut bytes);
            gl.bind_buffer(glow::COPY_READ_BUFFER, None);
        }
        bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect()
    }

    /// Per level (leaves first): the pairs the last batch of the last light queued at that
    /// level — more than the capacity when some were turned away — and the capacity.
    pub fn queue_counts(&self, gl: &glow::Context) -> Vec<(u32, u32)> {
        let words = self.control_words(gl);
        let Some(f) = self.frame.as_ref() else { return Vec::new() };
        f.layout.levels.iter().enumerate().map(|(l, level)| (words[4 * l], level.queue_capacity)).collect()
    }

    /// Triangles of the last light that a full queue sent to the redo list (processed by the
    /// fallback pass).
    pub fn redo_triangles(&self, gl: &glow::Context) -> u32 {
        self.control_words(gl).get(layout::REDO_CONTROL).copied().unwrap_or(0)
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
    fn ensure_frame(&mut self, gl: &glow::Context, width: u32, height: u32) -> Result<(), GlError> {
        let Some(triangles) = self.scene.as_ref().map(|s| s.triangles) else {
            return Err(GlError::InvalidParams("hier-triangle: draw_volumes before prepare".into()));
        };
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
        let order: Vec<u8> =
            self.scene.as_ref().map_or(&[][..], |s| &s.order[..]).iter().flat_map(|i| i.to_ne_bytes()).collect();
        // SAFETY: the order fits the state buffer's last `triangles` words (Layout::state_words).
        unsafe { gl.named_buffer_sub_data_u8_slice(made[2], (4 * layout.order_offset()) as i32, &order) };
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
        Self::dispatch_from(gl, program, 0, count, max_groups);
    }

    /// [`HierTriangle::dispatch`] of the invocations `first .. first + count`.
    fn dispatch_from(gl: &glow::Context, program: glow::Program, first: usize, count: usize, max_groups: u32) {
        let u_first = uniform(gl, program, "u_first");
        let per_dispatch = max_groups as usize * WORKGROUP as usize;
        let mut start = 0usize;
        while start < count {
            let n = (count - start).min(per_dispatch);
            // SAFETY: the program is current; n.div_ceil(WORKGROUP) <= max_groups.
            unsafe {
                gl.uniform_1_u32(u_first.as_ref(), (first + start) as u32);
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
            gl.uniform_1_u32(u("u_heads_offset").as_ref(), layout.heads_offset() as u32);
            gl.uniform_1_u32(u("u_redo_flags_offset").as_ref(), layout.redo_flags_offset() as u32);
            gl.uniform_1_u32(u("u_redo_offset").as_ref(), layout.redo_offset() as u32);
            gl.uniform_1_u32(u("u_active_offset").as_ref(), layout.active_offset() as u32);
            gl.uniform_1_u32(u("u_triangles").as_ref(), layout.triangles as u32);
            gl.uniform_1_u32(u("u_redo_out").as_ref(), light.redo_out);
            gl.uniform_1_u32(u("u_redo_in").as_ref(), light.redo_in);
            gl.uniform_1_u32(u("u_valid_offset").as_ref(), layout.valid_offset() as u32);
            gl.uniform_1_u32(u("u_order_offset").as_ref(), layout.order_offset() as u32);
            gl.uniform_4_f32_slice(u("u_light").as_ref(), &light.light);
            gl.uniform_3_f32_slice(u("u_dir").as_ref(), &light.dir);
            gl.uniform_3_f32_slice(u("u_origin").as_ref(), &light.origin);
            gl.uniform_1_f32(u("u_eps").as_ref(), light.eps);
            gl.uniform_1_f32(u("u_eps_near").as_ref(), 0.5 * light.eps);
            gl.uniform_4_f32_slice(u("u_view_w").as_ref(), &light.view_w);
            gl.uniform_3_f32_slice(u("u_light_u").as_ref(), &light.basis[0]);
            gl.uniform_3_f32_slice(u("u_light_v").as_ref(), &light.basis[1]);
            gl.uniform_3_f32_slice(u("u_eye_rel").as_ref(), &light.eye_rel);
            gl.uniform_3_f32_slice(u("u_ray_x").as_ref(), &light.rays[0]);
            gl.uniform_3_f32_slice(u("u_ray_y").as_ref(), &light.rays[1]);
            gl.uniform_3_f32_slice(u("u_ray_c").as_ref(), &light.rays[2]);
        }
    }

    /// Byte offset of the DispatchIndirectCommand after the count at control word `word`.
    fn command_offset(word: usize) -> i32 {
        (4 * (word + 1)) as i32
    }

    /// Writes the DispatchIndirectCommand for the entries counted at control word `word`
    /// (clamped to `capacity`), `per_group` entries per workgroup, between the barriers it
    /// needs. The state buffer must be bound as GL_DISPATCH_INDIRECT_BUFFER.
    #[allow(clippy::too_many_arguments)]
    fn indirect(
        gl: &glow::Context,
        p: &Programs,
        layout: &Layout,
        light: &LightUniforms,
        word: usize,
        capacity: u32,
        per_group: u32,
    ) {
        // SAFETY: barriers and a one-invocation dispatch of our program.
        unsafe {
            // Reason: the list's count and entries were written by the pass before.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            Self::use_with_common(gl, p.args, layout, light);
            gl.uniform_1_u32(uniform(gl, p.args, "u_args_word").as_ref(), word as u32);
            gl.uniform_1_u32(uniform(gl, p.args, "u_args_capacity").as_ref(), capacity);
            gl.uniform_1_u32(uniform(gl, p.args, "u_pairs_per_group").as_ref(), per_group);
            gl.dispatch_compute(1, 1, 1);
            // Reason: COMMAND: the next dispatch sources its size from the command just
            // written; SHADER_STORAGE: and its shader reads that state.
            gl.memory_barrier(glow::COMMAND_BARRIER_BIT | glow::SHADER_STORAGE_BARRIER_BIT);
        }
    }

    /// One batch's (or redo round's) passes after its setup: per level from the top, the
    /// children of the queued pairs; then the active leaves' lists (the state buffer must be
    /// bound as GL_DISPATCH_INDIRECT_BUFFER).
    fn traverse(gl: &glow::Context, p: &Programs, layout: &Layout, light: &LightUniforms) {
        for l in (1..layout.levels.len()).rev() {
            Self::indirect(gl, p, layout, light, 4 * l, layout.levels[l].queue_capacity, WORKGROUP);
            Self::use_with_common(gl, p.descend, layout, light);
            // SAFETY: our program; the command was written by `indirect`.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.descend, "u_pass_level").as_ref(), l as u32);
                gl.dispatch_compute_indirect(Self::command_offset(4 * l));
            }
        }
        Self::indirect(gl, p, layout, light, layout::ACTIVE_CONTROL, layout.leaves(), 1);
        Self::use_with_common(gl, p.leaves, layout, light);
        // SAFETY: as above.
        unsafe { gl.dispatch_compute_indirect(Self::command_offset(layout::ACTIVE_CONTROL)) };
    }

    /// Empties the queues, leaf lists and active leaves for the next batch or round (their
    /// counts and the list heads; the redo lists, coverage and masks carry over).
    fn reset_queues(gl: &glow::Context, s: &SceneObjects, layout: &Layout, light: &LightUniforms) {
        Self::clear_state_range(gl, s, layout, light, 0, layout::REDO_CONTROL);
        Self::clear_state_range(gl, s, layout, light, layout.heads_offset(), layout.leaves() as usize);
        // SAFETY: barrier only. Reason: the cleared words are read and written next.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
    }

    /// Sets the state words `first .. first + count` to 0.
    fn clear_state_range(
        gl: &glow::Context,
        s: &SceneObjects,
        layout: &Layout,
        light: &LightUniforms,
        first: usize,
        count: usize,
    ) {
        Self::use_with_common(gl, s.programs.clear, layout, light);
        // SAFETY: our program; uniform types match clear.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, s.programs.clear, "u_count").as_ref(), (first + count) as u32);
            gl.uniform_1_u32(uniform(gl, s.programs.clear, "u_what").as_ref(), 1);
        }
        Self::dispatch_from(gl, s.programs.clear, first, count, s.max_groups);
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

/// common.glsl's light and view uniforms for one light of one frame.
#[derive(Clone)]
struct LightUniforms {
    light: [f32; 4],
    dir: [f32; 3],
    origin: [f32; 3],
    eps: f32,
    view_w: [f32; 4],
    eye_rel: [f32; 3],
    rays: [[f32; 3]; 3],
    /// A directional light's orthonormal basis of the plane perpendicular to it.
    basis: [[f32; 3]; 2],
    /// The redo list turned-away triangles go to, and the one a redo round reads.
    redo_out: u32,
    redo_in: u32,
}

impl LightUniforms {
    fn new(frame: &VolumeFrame<'_>, scene: &SceneObjects) -> Self {
        let light = frame.light;
        let point = light[3] != 0.0;
        let len = light[..3].iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt();
        let dir = if point || len == 0.0 { [0.0; 3] } else { [0, 1, 2].map(|k| (f64::from(light[k]) / len) as f32) };
        let origin = if point { [0, 1, 2].map(|k| light[k] / light[3]) } else { scene.centre };
        let (view_w, rays) = view_rays(&frame.clip_from_world);
        let eye_rel = [0, 1, 2].map(|k| (frame.eye[k] - f64::from(origin[k])) as f32);
        let d = glam::DVec3::from(dir.map(f64::from));
        let u = if d.x.abs() < 0.9 { glam::DVec3::X } else { glam::DVec3::Y }.cross(d).normalize_or_zero();
        let v = d.cross(u).normalize_or_zero();
        let basis = [u, v].map(|b| b.to_array().map(|c| c as f32));
        Self { light, dir, origin, eps: scene.eps, view_w, eye_rel, rays, basis, redo_out: 0, redo_in: 0 }
    }
}

/// Row 3 of `clip_from_world` (a world point's clip w) and the ray directions of the view:
/// the point of NDC (x, y) at clip w is `eye + w (x R_x + y R_y + R_c)`, `[R_x, R_y, R_c]` =
/// the inverse of the 3 x 3 matrix of rows 0, 1 and 3's xyz (rows 0, 1 and 3 vanish at the eye,
/// the centre of projection, whatever the depth convention). Zero rays for a singular matrix
/// (then every slab is empty of meaning: the world boxes alone decide; see common.glsl).
fn view_rays(clip_from_world: &glam::DMat4) -> ([f32; 4], [[f32; 3]; 3]) {
    let row = |i: usize| clip_from_world.row(i);
    let (r0, r1, r3) = (row(0), row(1), row(3));
    let m = glam::DMat3::from_cols(r0.truncate(), r1.truncate(), r3.truncate()).transpose();
    let inv = if m.determinant().abs() > 0.0 { m.inverse() } else { glam::DMat3::ZERO };
    let col = |v: glam::DVec3| v.to_array().map(|c| c as f32);
    (r3.to_array().map(|c| c as f32), [col(inv.x_axis), col(inv.y_axis), col(inv.z_axis)])
}

impl ShadowMethod for HierTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["samples", "hierarchy", "light-bounds", "batches", "redo", "fallback", "stencil"]
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
        let order = largest_first(&mesh.positions, &mesh.triangles);
        self.scene = Some(SceneObjects {
            programs,
            planes,
            empty_vao,
            triangles,
            max_groups: max_groups.clamp(1, i32::MAX) as u32,
            eps: segment_epsilon(&mesh.positions) as f32,
            centre,
            order,
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
        self.ensure_frame(gl, frame.width, frame.height)?;
        let (Some(s), Some(f)) = (self.scene.as_ref(), self.frame.as_mut()) else {
            return Err(GlError::InvalidParams("hier-triangle: objects missing".into()));
        };
        let layout = f.layout.clone();
        let light = LightUniforms::new(frame, s);
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

        frame.mark(gl, "light-bounds");
        for (l, level) in layout.levels.iter().enumerate() {
            // SAFETY: barrier only. Reason: each level reads what the level below (or the
            // bounds, or the previous light's passes) wrote.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            Self::use_with_common(gl, p.light_bounds, &layout, &light);
            // SAFETY: our program; uniform type matches light_bounds.comp.glsl.
            unsafe { gl.uniform_1_u32(uniform(gl, p.light_bounds, "u_bounds_level").as_ref(), l as u32) };
            Self::dispatch(gl, p.light_bounds, level.nodes() as usize, s.max_groups);
        }
        // SAFETY: barrier only. Reason: the previous light's passes read the state cleared next.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        Self::clear(gl, s, &layout, &light, 1, layout.light_words());

        frame.mark(gl, "batches");
        // SAFETY: binding our state buffer as the indirect dispatch source (unbound below).
        unsafe { gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(f.state)) };
        for (i, batch) in layout::batches(triangles).into_iter().enumerate() {
            // SAFETY: barrier only. Reason: the cleared state, or the previous batch's queues
            // (consumed), lists and coverage, are written next.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            if i > 0 {
                Self::reset_queues(gl, s, &layout, &light);
            }
            Self::use_with_common(gl, p.setup, &layout, &light);
            // SAFETY: our program; uniform types match setup.comp.glsl.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.setup, "u_batch_end").as_ref(), batch.end as u32);
                gl.uniform_1_u32(uniform(gl, p.setup, "u_from_redo").as_ref(), 0);
            }
            Self::dispatch_from(gl, p.setup, batch.start, batch.len(), s.max_groups);
            Self::traverse(gl, p, &layout, &light);
        }
        // Redo rounds: the triangles a full queue turned away, through the same passes (list
        // 0 from the batches, then alternating); what is left after the last round goes to the
        // fallback pass, whole.
        frame.mark(gl, "redo");
        let mut round_light = light.clone();
        for round in 0..layout::REDO_ROUNDS {
            round_light.redo_in = (round % 2) as u32;
            round_light.redo_out = ((round + 1) % 2) as u32;
            // SAFETY: barrier only. Reason: the last batch's passes wrote what is reset next.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            Self::reset_queues(gl, s, &layout, &round_light);
            // The output list's count and the flags saying who is in it.
            let out_count = layout::REDO_CONTROL + 4 * round_light.redo_out as usize;
            Self::clear_state_range(gl, s, &layout, &round_light, out_count, 1);
            Self::clear_state_range(gl, s, &layout, &round_light, layout.redo_flags_offset(), triangles.div_ceil(32));
            let in_count = layout::REDO_CONTROL + 4 * round_light.redo_in as usize;
            Self::indirect(gl, p, &layout, &round_light, in_count, triangles as u32, WORKGROUP);
            Self::use_with_common(gl, p.setup, &layout, &round_light);
            // SAFETY: our program; uniform type matches setup.comp.glsl; command just written.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.setup, "u_from_redo").as_ref(), 1);
                gl.dispatch_compute_indirect(Self::command_offset(in_count));
            }
            Self::traverse(gl, p, &layout, &round_light);
        }
        frame.mark(gl, "fallback");
        round_light.redo_in = (layout::REDO_ROUNDS % 2) as u32;
        let last = layout::REDO_CONTROL + 4 * round_light.redo_in as usize;
        Self::indirect(gl, p, &layout, &round_light, last, triangles as u32, WORKGROUP);
        Self::use_with_common(gl, p.fallback, &layout, &round_light);
        // SAFETY: the fallback has no workgroup unless the last round turned triangles away.
        unsafe {
            gl.dispatch_compute_indirect(Self::command_offset(last));
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
