//! `hier-triangle`: exact per-triangle shadows tested against a hierarchy of the frame's view
//! samples, in compute shaders — no shadow volume is rasterized or depth-tested.
//!
//! Erik Sintorn, Viktor Kämpe, Ola Olsson, Ulf Assarsson, "Per-Triangle Shadow Volumes Using a
//! View-Sample Cluster Hierarchy", I3D 2014. Each triangle's shadow volume is a frustum of four
//! planes (its own plane and three planes through the light and an edge); it is tested against
//! a hierarchy of clusters of view samples with 3-D bounds, top-down: a node outside the
//! frustum is dropped, a node inside is cleared from a global bitmask of live nodes (every
//! later triangle skips it), a node it cuts is refined, and at the leaves every live sample is
//! tested exactly. A sample is shadowed when any triangle's frustum holds it (an OR: no
//! counting, no multiplicity, no adjacency, no caps, no z-pass / z-fail).
//!
//! What umbra adds: the tests are the ray-traced reference's rule (`frustum.glsl`): a sample is
//! shadowed by another triangle whose closed, two-sided surface the segment to the light meets
//! beyond the reference's eps from the sample (half of it, see `frustum.glsl`) and from the
//! light, the sample's own triangle excluded (its facing is the lighting pass's test), with
//! watertight edge planes (computed in f64 from lexicographically ordered endpoints) — so the
//! decision matches `umbra verify`'s reference outside the band, and none of the band's
//! depth-test precision classes concern it (docs/exactness.md).
//!
//! The view samples and their hierarchy are shared with hier-silhouette
//! ([`crate::methods::hier`]). Per frame (once for all lights; [`VolumeFrame::view_serial`]):
//! 1. "samples": the scene drawn with the renderer's own vertex shader over the frame's depth,
//!    depth func EQUAL, all writes masked: the fragment shader (`hier/samples.frag.glsl`) stores
//!    each visible sample's world position and triangle id, and whether the rasterizer saw its
//!    triangle's front;
//! 2. "hierarchy": `hier/bounds.comp.glsl`, per node (leaves of 4 x 4 pixels, then 4 x 4
//!    children per level up to one root, [`layout`]) the world box of its samples, the range
//!    of their clip w (with the node's screen tile: a frustum slab) and their depth occupancy:
//!    32 bins of that range, a bit set where a sample may lie (`hier/region.glsl`).
//!
//! Per light:
//! 3. "light-bounds": `hier/light_bounds.comp.glsl`, per node the bound of its samples'
//!    directions from the light;
//! 4. "setup": `setup.comp.glsl`, one invocation per triangle: its planes in f64 and its
//!    direction bound; `init.comp.glsl`, per level from the leaves up: the live bitmask
//!    (`live.glsl`): the samples present, less those whose seen side certainly faces away from
//!    the light (the lighting pass never lights them: they are dropped before any triangle is
//!    tested), and per node its children with live samples; `receivers.comp.glsl`: the
//!    receiver map (`receivers.glsl`), per light-space cell the farthest live sample from the
//!    light, with which setup drops every triangle whose cone holds no live sample beyond it
//!    (its shadow falls on nothing the eye sees) before it tests a single node;
//! 5. "traverse": `traverse.comp.glsl`, one persistent dispatch: each workgroup takes triangles,
//!    largest first ([`largest_first`]), from an atomic job counter and walks the hierarchy
//!    depth-first with each, a node's 16 children tested in parallel ([`lanes`] invocations
//!    per workgroup, one child each, or two), their mask exchanged through shared memory (the
//!    ballot), a child inside the shadow cleared with atomicAnd, a leaf's live samples tested
//!    exactly. No per-level dispatch, no queue, no fallback;
//! 6. "stencil": `resolve.frag.glsl` on a full-screen triangle, the merge: stencil 1 where the
//!    sample's bit or a node on its path was cleared ([`Classification::StencilZero`] as every
//!    counting method, so the lighting pass, [`crate::Renderer::count_shadows`] and `umbra
//!    verify` read it unchanged; [`ShadowMethod::fills_volumes`] is false: the renderer clears
//!    the stencil to 0 and sets up no counting for it).
//!
//! A node is tested against a triangle's frustum with four bounds of its samples, each
//! conservative by a rounding margin: the world box, the frustum slab, the direction bound
//! (`frustum.glsl`, classify_node; the triangle's own direction bound rejects the nodes off the
//! corners of a small triangle's cone, which its edge planes alone cannot) and the depth
//! occupancy: the depths at which the frustum meets the node's tile, against the bins its
//! samples occupy, reject a node across a depth discontinuity (an arch before a far wall) that
//! the frustum crosses only in the empty depth between its surfaces. Those nodes were 99 % of
//! the leaves tested sample by sample without one sample inside.
//!
//! Bounds on work and memory: llvmpipe gives a shader invocation 65,535 loop iterations in all,
//! every loop together, and ends them silently after that (docs/exactness.md). There the
//! traversal runs with a loop budget below it ([`LOOP_BUDGET`]): a workgroup that spends it
//! saves its triangle and stack in its slot of the job buffer and the dispatch is repeated
//! (after reading back how many workgroups it left unfinished) until none is; each repetition
//! resumes every walk where it stopped. On other drivers one dispatch runs to the end. The
//! stack holds one entry per level (no recursion, no constant-bound loop nest, which NVIDIA's
//! compiler unrolls without end). Memory: [`layout::frame_layout`]'s
//! [`layout::Layout::frame_bytes`] per frame size plus [`layout::scene_bytes`] per scene
//! (planes, order and slots; docs/benchmarks.md states it per resolution), independent of how
//! much work a frame holds. Every allocation is checked: one the GL refuses is
//! [`GlError::OutOfMemory`], nothing is left behind and the method stays usable (at another
//! size, or later).
//!
//! Samples are the visible surfaces of *umbra's scene*: with
//! [`crate::Renderer::count_shadows`] on a caller's depth that also holds other geometry, the
//! pixels of that geometry get no sample and stay lit (stencil 0).
//!
//! Stages reported: "samples", "hierarchy", "light-bounds", "setup", "traverse", "stencil".

pub mod layout;

use glow::HasContext;

use crate::error::GlError;
use crate::methods::hier::{self, FrameObjects, LightUniforms, Passes, SharedPrograms, WorkCounter};
use crate::methods::method::{Classification, ShadowMethod, VolumeFrame};
use crate::program::uniform;
use crate::scene::{SceneGpu, SceneId};
use layout::{Jobs, Layout};

/// Registry name.
pub const NAME: &str = "hier-triangle";

const FRUSTUM: &str = include_str!("frustum.glsl");
const LIVE: &str = include_str!("live.glsl");
const SETUP_COMP: &str = include_str!("setup.comp.glsl");
const INIT_COMP: &str = include_str!("init.comp.glsl");
const TRAVERSE_COMP: &str = include_str!("traverse.comp.glsl");
const RECEIVERS: &str = include_str!("receivers.glsl");
/// `receiver_encode`, `receiver_decode`, `receiver_cell`, `receiver_cube_cell`, shared with
/// cpu-silhouette's receiver scatter.
const RECEIVER_CELL: &str = include_str!("../shared/receiver_cell.glsl");
const RECEIVERS_COMP: &str = include_str!("receivers.comp.glsl");
const RESOLVE_FRAG: &str = include_str!("resolve.frag.glsl");

/// Shader-storage binding of the per-triangle planes (frustum.glsl); the hierarchy's are
/// [`hier::POSITIONS`] .. [`hier::QUEUES`].
const PLANES: u32 = 6;
/// Shader-storage binding of the job buffer (traverse.comp.glsl, init.comp.glsl).
const JOBS: u32 = 8;
/// Shader-storage binding of the receiver map (receivers.glsl).
const RECEIVERS_MAP: u32 = 10;

/// The traversal's loop budget per workgroup and dispatch where the driver ends loops after
/// 65,535 iterations (llvmpipe): below it by more than one step's iterations and the final
/// stores' (traverse.comp.glsl counts them).
pub const LOOP_BUDGET: u32 = 60_000;

/// Invocations per traversal workgroup on a driver whose renderer string is `renderer`: 8 on
/// llvmpipe (its vector width: a workgroup is one vector, each invocation tests two children),
/// 16 elsewhere (one child per invocation).
pub fn lanes(renderer: &str) -> u32 {
    if renderer.contains("llvmpipe") {
        8
    } else {
        16
    }
}

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

/// The GLSL text before every stage's own source: the hierarchy's header (4 vec4 per node, the
/// fourth the depth occupancy), the traversal's constants, frustum.glsl and live.glsl.
fn header(lanes: u32) -> String {
    // The extensions right after #version: GLSL allows #extension only before any code.
    let version = "#version 450 core\n";
    let extensions =
        "#version 450 core\n#extension GL_ARB_shader_ballot : require\n#extension GL_ARB_gpu_shader_int64 : require\n";
    format!(
        "{}#define LANES {lanes}u\n#define SLOT_WORDS {}u\n#define RECEIVER_SIDE {}u\n#define RECEIVER_FLAT {}u\n\
         {FRUSTUM}\n{LIVE}\n{RECEIVER_CELL}\n{RECEIVERS}\n",
        hier::header(4, false).replacen(version, extensions, 1),
        layout::SLOT_WORDS,
        layout::RECEIVER_SIDE,
        layout::RECEIVER_FLAT
    )
}

struct Programs {
    shared: SharedPrograms,
    setup: glow::Program,
    init: glow::Program,
    receivers: glow::Program,
    traverse: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> Vec<glow::Program> {
        let mut v = self.shared.all().to_vec();
        v.extend([self.setup, self.init, self.receivers, self.traverse, self.resolve]);
        v
    }

    fn link(gl: &glow::Context, lanes: u32) -> Result<Programs, GlError> {
        let computes = [
            ("setup", "hier_triangle/setup.comp.glsl", SETUP_COMP),
            ("init", "hier_triangle/init.comp.glsl", INIT_COMP),
            ("receivers", "hier_triangle/receivers.comp.glsl", RECEIVERS_COMP),
            ("traverse", "hier_triangle/traverse.comp.glsl", TRAVERSE_COMP),
        ];
        let p = hier::link_method(
            gl,
            NAME,
            &header(lanes),
            &hier::header(4, false),
            &computes,
            ("hier_triangle/resolve.frag.glsl", RESOLVE_FRAG),
        )?;
        let own = p.own;
        Ok(Programs {
            shared: p.shared,
            setup: own[0],
            init: own[1],
            receivers: own[2],
            traverse: own[3],
            resolve: own[4],
        })
    }
}

/// Per scene: programs, the plane and job buffers, the resolve's empty vertex array.
struct SceneObjects {
    programs: Programs,
    planes: glow::Buffer,
    jobs_buffer: glow::Buffer,
    /// The receiver map (receivers.glsl), per light.
    receivers: glow::Buffer,
    jobs: Jobs,
    empty_vao: glow::VertexArray,
    triangles: usize,
    max_groups: u32,
    /// The reference's eps for this scene, and the origin of directional planes (the centre
    /// of the scene's bounds).
    eps: f32,
    centre: [f32; 3],
    /// Whether loops end after 65,535 iterations (llvmpipe): the traversal then runs in
    /// budgeted dispatches.
    loop_limited: bool,
}

/// See the module documentation.
pub struct HierTriangle {
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
    frame: Option<FrameObjects>,
    loop_budget: Option<u32>,
    rounds: u32,
    work: WorkCounter,
}

impl Default for HierTriangle {
    fn default() -> Self {
        Self::new()
    }
}

impl HierTriangle {
    /// Builds the method (no GL calls).
    pub fn new() -> Self {
        Self { prepared: None, scene: None, frame: None, loop_budget: None, rounds: 0, work: WorkCounter::default() }
    }

    /// The same method with a traversal loop budget of `budget` iterations per workgroup and
    /// dispatch (at least one step's) on every driver: tests make every walk stop and resume
    /// many times; the decision must not change.
    pub fn with_loop_budget(self, budget: u32) -> Self {
        Self { loop_budget: Some(budget.clamp(64, LOOP_BUDGET)), ..self }
    }

    /// The layout of the last frame size drawn, if any.
    pub fn layout(&self) -> Option<&Layout> {
        self.frame.as_ref().map(|f| &f.layout)
    }

    /// Traversal dispatches of the last light drawn (1 unless the loop budget stopped some
    /// workgroups).
    pub fn last_rounds(&self) -> u32 {
        self.rounds
    }

    fn destroy_frame(&mut self, gl: &glow::Context) {
        if let Some(f) = self.frame.take() {
            f.destroy(gl);
        }
    }

    /// The frame-size objects for `width x height`, (re)allocated when the size changed.
    fn ensure_frame(&mut self, gl: &glow::Context, width: u32, height: u32) -> Result<(), GlError> {
        if self.frame.as_ref().is_some_and(|f| f.layout.width == width && f.layout.height == height) {
            return Ok(());
        }
        self.destroy_frame(gl);
        let layout = layout::frame_layout(width, height);
        if layout.top().nodes() > hier::layout::CHILDREN {
            return Err(GlError::InvalidParams(format!(
                "hier-triangle: {width}x{height} has {} top nodes, more than the root's {} children",
                layout.top().nodes(),
                hier::layout::CHILDREN
            )));
        }
        let names =
            ["hier-triangle samples", "hier-triangle node bounds", "hier-triangle state", "hier-triangle queues"];
        self.frame = Some(FrameObjects::allocate(gl, layout, names)?);
        Ok(())
    }

    /// Stage "traverse": the persistent dispatch, repeated while the loop budget leaves
    /// workgroups unfinished. Returns the dispatches issued.
    fn traverse(&self, passes: &Passes<'_>, light: &LightUniforms) -> Result<u32, GlError> {
        let Some(s) = self.scene.as_ref() else {
            return Err(GlError::InvalidParams("hier-triangle: objects missing".into()));
        };
        let gl = passes.gl;
        let p = &s.programs;
        let budget = match (self.loop_budget, s.loop_limited) {
            (Some(b), _) => b,
            (None, true) => LOOP_BUDGET,
            (None, false) => u32::MAX,
        };
        passes.use_with_common(p.traverse, light);
        // SAFETY: our program; uniform types match traverse.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, p.traverse, "u_jobs_list").as_ref(), s.jobs.list_offset() as u32);
            gl.uniform_1_u32(uniform(gl, p.traverse, "u_slots_offset").as_ref(), s.jobs.slots_offset() as u32);
            gl.uniform_1_u32(uniform(gl, p.traverse, "u_loop_budget").as_ref(), budget);
        }
        let mut rounds = 0u32;
        loop {
            // SAFETY: barrier and dispatch of our current program (workgroups <= WORKGROUPS,
            // within every driver's limit).
            unsafe {
                // Reason: the init pass (or the last round) wrote the live words and slots read
                // next.
                gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
                gl.dispatch_compute(s.jobs.workgroups as u32, 1, 1);
            }
            passes.counted();
            rounds += 1;
            if budget == u32::MAX {
                break;
            }
            // Workgroups left unfinished (a read-back stall: only where the budget applies).
            let unfinished = hier::read_words(gl, s.jobs_buffer, 1, 1)[0];
            if unfinished == 0 {
                break;
            }
            // A round always moves every unfinished walk on; this many cannot be needed by
            // any frame the layout allows, but ends a broken driver's loop.
            if rounds >= 1 << 20 {
                return Err(GlError::InvalidParams("hier-triangle: the traversal did not finish".into()));
            }
            // SAFETY: our own buffer; word 1 is this round's count of unfinished workgroups.
            unsafe {
                // Reason: the read-back above must see the shaders' writes, the reset below
                // must not race them.
                gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
                gl.named_buffer_sub_data_u8_slice(s.jobs_buffer, 4, &0u32.to_ne_bytes());
            }
        }
        Ok(rounds)
    }
}

impl ShadowMethod for HierTriangle {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["samples", "hierarchy", "light-bounds", "setup", "traverse", "stencil"]
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
        let jobs = Jobs::new(triangles);
        let plane_bytes = layout::plane_bytes(triangles.max(1));
        crate::gpu_buffer::checked_size(plane_bytes, "hier-triangle planes")?;
        crate::gpu_buffer::checked_size(jobs.bytes(), "hier-triangle jobs")?;
        let renderer = crate::context::renderer_string(gl);
        // The traversal's child mask is a subgroup ballot (64-bit masks).
        let extensions = gl.supported_extensions();
        if let Some(missing) =
            ["GL_ARB_shader_ballot", "GL_ARB_gpu_shader_int64"].into_iter().find(|e| !extensions.contains(*e))
        {
            return Err(GlError::Unsupported { method: NAME, reason: format!("needs {missing}") });
        }
        let programs = Programs::link(gl, lanes(&renderer))?;
        let buffers = match hier::allocate_buffers(
            gl,
            &[plane_bytes, jobs.bytes(), layout::RECEIVER_BYTES],
            &["hier-triangle planes", "hier-triangle jobs", "hier-triangle receiver map"],
        ) {
            Ok(b) => b,
            Err(e) => {
                hier::delete_programs(gl, &programs.all());
                return Err(e);
            }
        };
        // SAFETY: object creation on the current context; deleted on the error path.
        let empty_vao = match unsafe { gl.create_named_vertex_array() } {
            Ok(v) => v,
            Err(detail) => {
                // SAFETY: our own buffers.
                unsafe {
                    for b in &buffers {
                        gl.delete_buffer(*b);
                    }
                }
                hier::delete_programs(gl, &programs.all());
                return Err(GlError::Create { what: "hier-triangle vertex array", detail });
            }
        };
        let order: Vec<u8> =
            largest_first(&mesh.positions, &mesh.triangles).iter().flat_map(|i| i.to_ne_bytes()).collect();
        // SAFETY: the order fits the job buffer's order region (Jobs::words).
        unsafe { gl.named_buffer_sub_data_u8_slice(buffers[1], (4 * jobs.order_offset()) as i32, &order) };
        let centre = scene.bounds().map_or([0.0; 3], |b| b.center());
        self.scene = Some(SceneObjects {
            programs,
            planes: buffers[0],
            jobs_buffer: buffers[1],
            receivers: buffers[2],
            jobs,
            empty_vao,
            triangles,
            max_groups: max_groups.clamp(1, i32::MAX) as u32,
            eps: segment_epsilon(&mesh.positions) as f32,
            centre,
            loop_limited: renderer.contains("llvmpipe"),
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
        let fresh =
            !self.frame.as_ref().is_some_and(|f| f.layout.width == frame.width && f.layout.height == frame.height);
        self.ensure_frame(gl, frame.width, frame.height)?;
        let (Some(s), Some(f)) = (self.scene.as_ref(), self.frame.as_mut()) else {
            return Err(GlError::InvalidParams("hier-triangle: objects missing".into()));
        };
        let layout = f.layout.clone();
        let light = LightUniforms::new(frame, s.eps, s.centre);
        let p = &s.programs;
        let passes = Passes::new(gl, &p.shared, &layout, s.max_groups, self.work.on());
        self.work.begin(gl, f, fresh);
        passes.bind(scene, f);
        // SAFETY: our plane and job buffers (written and read by the compute passes).
        unsafe {
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, PLANES, Some(s.planes));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, JOBS, Some(s.jobs_buffer));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, RECEIVERS_MAP, Some(s.receivers));
        }
        passes.samples_and_hierarchy(scene, frame, f, &light);
        passes.light_bounds(frame, &light);

        frame.mark(gl, "setup");
        // The live bitmask, level by level from the leaves up to the virtual root.
        for level in 0..=layout.levels.len() {
            // Level 0's dispatch also resets the slots: at least one invocation per workgroup.
            let nodes = layout.levels.get(level).map_or(1, |l| l.nodes() as usize);
            let count = if level == 0 { nodes.max(s.jobs.workgroups) } else { nodes };
            // SAFETY: barrier only. Reason: each level reads the words of the level below (the
            // first, the light bounds' clear).
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            passes.use_with_common(p.init, &light);
            // SAFETY: our program; uniform types match init.comp.glsl.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.init, "u_init_level").as_ref(), level as u32);
                gl.uniform_1_u32(uniform(gl, p.init, "u_slots_offset").as_ref(), s.jobs.slots_offset() as u32);
                gl.uniform_1_u32(uniform(gl, p.init, "u_workgroups").as_ref(), s.jobs.workgroups as u32);
            }
            passes.dispatch(p.init, count);
        }
        // The receiver map: cleared, then every live sample raises its cell.
        for mode in 0..2u32 {
            // SAFETY: barrier only. Reason: the fill reads the live words init wrote (and writes
            // the cells the clear zeroed).
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            passes.use_with_common(p.receivers, &light);
            // SAFETY: our program; uniform type matches receivers.comp.glsl.
            unsafe { gl.uniform_1_u32(uniform(gl, p.receivers, "u_receiver_mode").as_ref(), mode) };
            // The clear: every cell, and one invocation more for the directional grid's box.
            let count = if mode == 0 { layout::RECEIVER_CELLS + 1 } else { (layout.width * layout.height) as usize };
            passes.dispatch(p.receivers, count);
        }
        // The frusta, and the job list of those that cut a top node and whose cone holds a live
        // sample beyond them.
        // SAFETY: barrier only. Reason: setup reads the live words, the receiver map and the
        // reset job list.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        passes.use_with_common(p.setup, &light);
        // SAFETY: our program; uniform types match setup.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, p.setup, "u_jobs_triangles").as_ref(), triangles as u32);
            gl.uniform_1_u32(uniform(gl, p.setup, "u_jobs_order").as_ref(), s.jobs.order_offset() as u32);
            gl.uniform_1_u32(uniform(gl, p.setup, "u_jobs_list").as_ref(), s.jobs.list_offset() as u32);
        }
        passes.dispatch(p.setup, triangles);

        frame.mark(gl, "traverse");
        let rounds = self.traverse(&passes, &light)?;

        frame.mark(gl, "stencil");
        crate::state::GlState::stencil_mark_resolve().apply(gl);
        // SAFETY: our program and empty vertex array; the frame's target and viewport.
        unsafe {
            // Reason: the fragment shader reads the live words the traversal cleared.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, layout.width as i32, layout.height as i32);
        }
        passes.use_with_common(p.resolve, &light);
        // SAFETY: as above; three vertices of the full-screen triangle.
        unsafe {
            gl.bind_vertex_array(Some(s.empty_vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
            gl.bind_vertex_array(None);
        }
        // Leave no binding of ours behind (the renderer restores the caller's).
        passes.unbind(&[
            hier::POSITIONS,
            hier::INDICES,
            hier::SAMPLES,
            hier::NODES,
            hier::STATE,
            PLANES,
            hier::QUEUES,
            JOBS,
            hier::WORK,
            RECEIVERS_MAP,
        ]);
        self.work.end(&passes);
        self.rounds = rounds;
        Ok(())
    }

    fn set_count_work(&mut self, on: bool) {
        self.work.set(on);
    }

    fn work_counts(&mut self, gl: &glow::Context) -> Option<crate::WorkCounts> {
        self.work.read(gl, self.frame.as_ref())
    }

    fn gpu_bytes(&self) -> usize {
        self.scene.as_ref().map_or(0, |s| layout::scene_bytes(s.triangles))
            + self.frame.as_ref().map_or(0, |f| f.layout.frame_bytes())
    }

    fn destroy(&mut self, gl: &glow::Context) {
        self.destroy_frame(gl);
        if let Some(s) = self.scene.take() {
            hier::delete_programs(gl, &s.programs.all());
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_buffer(s.planes);
                gl.delete_buffer(s.jobs_buffer);
                gl.delete_buffer(s.receivers);
                gl.delete_vertex_array(s.empty_vao);
            }
        }
        self.prepared = None;
    }
}
