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
//! What umbra adds: the tests are the ray-traced reference's rule (`frustum.glsl`): a sample is
//! shadowed by another triangle whose closed, two-sided surface the segment to the light meets
//! beyond the reference's eps from the sample (half of it, see `frustum.glsl`) and from the
//! light, the sample's own triangle excluded (its facing is the lighting pass's test), with
//! watertight edge planes (computed in f64 from lexicographically ordered endpoints) — so the
//! decision matches `umbra verify`'s reference outside the band, and none of the band's
//! depth-test precision classes concern it (docs/exactness.md).
//!
//! The view samples, their hierarchy and its breadth-first traversal are shared with
//! hier-silhouette ([`crate::methods::hier`]). Per frame (once for all lights;
//! [`VolumeFrame::view_serial`]):
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
//!    turned away; "fallback": the shared walk `hier/walk.comp.glsl` with this method's hooks
//!    (`fallback.comp.glsl`), what is still left, one invocation per triangle descending
//!    depth-first (normally no workgroup at all);
//! 6. "stencil": `resolve.frag.glsl` on a full-screen triangle writes stencil 1 where the sample
//!    is shadowed (its bit, or its leaf or an ancestor covered): [`Classification::StencilZero`]
//!    as every counting method, so the lighting pass, [`crate::Renderer::count_shadows`] and
//!    `umbra verify` read it unchanged ([`ShadowMethod::fills_volumes`] is false: the renderer
//!    clears the stencil to 0 and sets up no counting for it).
//!
//! A node is tested against a triangle's frustum with three bounds of its samples, each
//! conservative by a rounding margin: the world box, the frustum slab and the direction bound
//! (`frustum.glsl`, classify_node). Found while measuring (Sibenik, 320 x 180): with the world
//! box alone, 97 % of the (triangle, leaf) pairs it let through held no sample inside the
//! frustum; the slab, the direction bounds and the triangle's own direction bound (a small
//! triangle's cone is missed by most nodes near it, which its edge planes alone cannot show)
//! halved the pairs, and 4 x 4 leaves instead of 8 x 8 cut the per-sample work by 2.7.
//!
//! Bounds on work and memory: every shader loop runs at most 64 iterations (a leaf's samples,
//! a node's 16 children, the top nodes), except the walk of a leaf's list and the fallback's
//! walk. llvmpipe gives a shader invocation 65,535 loop iterations in all, every loop together
//! (gallivm keeps one loop limiter per function; measured, docs/exactness.md): a leaf's list
//! stays far below it (one pair per triangle of a batch or redo round); the fallback's
//! depth-first walk of a large frustum at 3840x2160 can exceed it, so it runs at most
//! [`layout::FALLBACK_STEPS`] steps per pass and resumes across passes (`hier/walk.comp.glsl`,
//! shared with hier-silhouette). The queues have a fixed capacity per frame size
//! ([`layout::queue_capacity`]); a pair that does not fit sends its triangle to a redo list
//! (bounded by the triangle count): slower, never wrong. The fallback walks depth-first with an
//! explicit stack (not one constant-bound loop per level, which NVIDIA's compiler unrolls 16^7
//! times and never finishes linking) in a program of its own: llvmpipe runs a shader's untaken
//! branches under a mask, so the walk inlined into the main passes made them 10 times slower
//! even when no queue overflowed (measured). Memory: [`layout::Layout::frame_bytes`] per frame
//! size plus [`layout::plane_bytes`] per scene (docs/benchmarks.md states it per resolution).
//! Every allocation is checked: one the GL refuses is [`GlError::OutOfMemory`], nothing is
//! left behind and the method stays usable (at another size, or later).
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
use crate::methods::hier::{self, FrameObjects, LightUniforms, Passes, SharedPrograms, WorkCounter};
use crate::methods::{Classification, ShadowMethod, VolumeFrame};
use crate::program::uniform;
use crate::scene::{SceneGpu, SceneId};
use layout::Layout;

/// Registry name.
pub const NAME: &str = "hier-triangle";

const FRUSTUM: &str = include_str!("frustum.glsl");
const SETUP_COMP: &str = include_str!("setup.comp.glsl");
const DESCEND_COMP: &str = include_str!("descend.comp.glsl");
const LEAVES_COMP: &str = include_str!("leaves.comp.glsl");
const FALLBACK_COMP: &str = include_str!("fallback.comp.glsl");
const RESOLVE_FRAG: &str = include_str!("resolve.frag.glsl");

/// Shader-storage binding of the per-triangle planes (frustum.glsl); the hierarchy's are
/// [`hier::POSITIONS`] .. [`hier::QUEUES`].
const PLANES: u32 = 6;

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

/// The GLSL text before every stage's own source: the hierarchy's header (3 vec4 per node, no
/// lifted points) and frustum.glsl.
fn header() -> String {
    format!("{}{FRUSTUM}\n", hier::header(3, false))
}

struct Programs {
    shared: SharedPrograms,
    fallback: glow::Program,
    setup: glow::Program,
    descend: glow::Program,
    leaves: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> Vec<glow::Program> {
        let mut v = self.shared.all().to_vec();
        v.extend([self.fallback, self.setup, self.descend, self.leaves, self.resolve]);
        v
    }

    fn link(gl: &glow::Context) -> Result<Programs, GlError> {
        let fallback = hier::fallback_source(FALLBACK_COMP);
        let computes = [
            ("setup", "hier_triangle/setup.comp.glsl", SETUP_COMP),
            ("descend", "hier_triangle/descend.comp.glsl", DESCEND_COMP),
            ("leaves", "hier_triangle/leaves.comp.glsl", LEAVES_COMP),
            ("fallback", "hier_triangle/fallback.comp.glsl", &fallback),
        ];
        let p = hier::link_method(
            gl,
            NAME,
            &header(),
            &hier::header(3, false),
            &computes,
            ("hier_triangle/resolve.frag.glsl", RESOLVE_FRAG),
        )?;
        let own = p.own;
        Ok(Programs {
            shared: p.shared,
            setup: own[0],
            descend: own[1],
            leaves: own[2],
            fallback: own[3],
            resolve: own[4],
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

/// See the module documentation.
pub struct HierTriangle {
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
    frame: Option<FrameObjects>,
    queue_scale: f64,
    fallback_steps: u32,
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
        Self {
            prepared: None,
            scene: None,
            frame: None,
            queue_scale: 1.0,
            fallback_steps: layout::FALLBACK_STEPS,
            work: WorkCounter::default(),
        }
    }

    /// The same method with every queue's capacity multiplied by `scale` (> 0): tests shrink
    /// the queues to send pairs down the fallback walk; the decision must not change.
    pub fn with_queue_scale(scale: f64) -> Self {
        Self { queue_scale: if scale > 0.0 && scale.is_finite() { scale } else { 1.0 }, ..Self::new() }
    }

    /// The same method with fallback passes of `steps` steps (at least 1; the default is
    /// [`layout::FALLBACK_STEPS`]): tests make every walk of the fallback stop and resume many
    /// times; the decision must not change.
    pub fn with_fallback_steps(self, steps: u32) -> Self {
        Self { fallback_steps: steps.clamp(1, layout::FALLBACK_STEPS), ..self }
    }

    /// The layout of the last frame size drawn, if any.
    pub fn layout(&self) -> Option<&Layout> {
        self.frame.as_ref().map(|f| &f.layout)
    }

    /// Per level (leaves first): the pairs the last batch of the last light queued at that
    /// level — more than the capacity when some were turned away — and the capacity.
    pub fn queue_counts(&self, gl: &glow::Context) -> Vec<(u32, u32)> {
        let Some(f) = self.frame.as_ref() else { return Vec::new() };
        let words = f.control_words(gl);
        f.layout.levels.iter().enumerate().map(|(l, level)| (words[4 * l], level.queue_capacity)).collect()
    }

    /// Triangles of the last light that a full queue sent to the redo list (processed by the
    /// fallback pass).
    pub fn redo_triangles(&self, gl: &glow::Context) -> u32 {
        self.frame.as_ref().map_or(0, |f| f.control_words(gl).get(layout::REDO_CONTROL).copied().unwrap_or(0))
    }

    fn destroy_frame(&mut self, gl: &glow::Context) {
        if let Some(f) = self.frame.take() {
            f.destroy(gl);
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
        hier::check_places(NAME, &layout)?;
        let names =
            ["hier-triangle samples", "hier-triangle node bounds", "hier-triangle state", "hier-triangle queues"];
        let f = FrameObjects::allocate(gl, layout, names)?;
        let order: Vec<u8> =
            self.scene.as_ref().map_or(&[][..], |s| &s.order[..]).iter().flat_map(|i| i.to_ne_bytes()).collect();
        // SAFETY: the order fits the state buffer's last `triangles` words (Layout::state_words).
        unsafe { gl.named_buffer_sub_data_u8_slice(f.state, (4 * f.layout.order_offset()) as i32, &order) };
        self.frame = Some(f);
        Ok(())
    }
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
        crate::gpu_buffer::checked_size(plane_bytes, "hier-triangle planes")?;
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
        // SAFETY: our plane buffer (written and read by the compute passes).
        unsafe { gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, PLANES, Some(s.planes)) };
        passes.samples_and_hierarchy(scene, frame, f, &light);
        passes.light_bounds(frame, &light);
        let no_uniforms = |_: glow::Program| {};

        frame.mark(gl, "batches");
        // SAFETY: binding our state buffer as the indirect dispatch source (unbound by the
        // fallback).
        unsafe { gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(f.state)) };
        for (i, batch) in layout::batches(triangles).into_iter().enumerate() {
            // SAFETY: barrier only. Reason: the cleared state, or the previous batch's queues
            // (consumed), lists and coverage, are written next.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            if i > 0 {
                passes.reset_queues(&light);
            }
            passes.use_with_common(p.setup, &light);
            // SAFETY: our program; uniform types match setup.comp.glsl.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.setup, "u_batch_end").as_ref(), batch.end as u32);
                gl.uniform_1_u32(uniform(gl, p.setup, "u_from_redo").as_ref(), 0);
            }
            passes.dispatch_from(p.setup, batch.start, batch.len());
            passes.traverse(p.descend, p.leaves, &light, &no_uniforms);
        }
        // Redo rounds: the triangles a full queue turned away, through the same passes; what
        // is left after the last round goes to the fallback pass, whole.
        frame.mark(gl, "redo");
        let traverse = |l: &LightUniforms| passes.traverse(p.descend, p.leaves, l, &no_uniforms);
        let round_light = passes.redo_rounds(p.setup, &light, &no_uniforms, &traverse);
        frame.mark(gl, "fallback");
        passes.fallback(p.fallback, &round_light, &no_uniforms, self.fallback_steps);

        frame.mark(gl, "stencil");
        crate::state::GlState::stencil_mark_resolve().apply(gl);
        // SAFETY: our program and empty vertex array; the frame's target and viewport.
        unsafe {
            // Reason: the fragment shader reads the masks and flags the compute passes wrote.
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
            hier::WORK,
        ]);
        self.work.end(&passes);
        Ok(())
    }

    fn set_count_work(&mut self, on: bool) {
        self.work.set(on);
    }

    fn work_counts(&mut self, gl: &glow::Context) -> Option<crate::WorkCounts> {
        self.work.read(gl, self.frame.as_ref())
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
