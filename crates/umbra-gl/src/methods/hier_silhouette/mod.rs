//! `hier-silhouette`: exact stencil shadow-volume counts per view sample, computed by testing
//! the silhouette's shadow-volume faces against a hierarchy of the frame's samples in compute
//! shaders — no shadow volume is rasterized or depth-tested.
//!
//! The idea of the seed authors' unpublished RSSV (dormon/Shadows, read, not copied): the
//! faces of paper 001's silhouette shadow volumes (Milet, Kobrtek, Zemčík: the edges of
//! nonzero deterministic multiplicity through the reference edge, Alg. 2-4, and every
//! triangle's light cap oriented by the same test) are tested against the view-sample cluster
//! hierarchy of Sintorn, Kämpe, Olsson, Assarsson ("Per-Triangle Shadow Volumes Using a
//! View-Sample Cluster Hierarchy", I3D 2014), and each sample's count is the sum of the signed
//! crossings of "bridges": from the light to the root's point, from each node's point to its
//! children's points, from a leaf's point to its samples. A face costs only where it passes
//! through the bounds of a cluster of samples, not wherever it covers the screen (the
//! rasterizing methods) nor wherever a triangle's frustum reaches (hier-triangle).
//!
//! Why counting along bridges gives the stencil's count. The faces form a closed surface,
//! each counter-clockwise seen from outside (umbra_geom::silhouette); the z-fail count of
//! cpu-silhouette at a sample is that surface's winding number `W` just in front of the
//! sample's surface. Along a segment `a -> b`, `W(b) = W(a) +` the signed crossings of the
//! faces (+1 into a volume, `m` for a side quad of multiplicity `m`). `W` is 0 at the light,
//! and a segment from the light crosses no side quad (its plane holds the light), so `W` at
//! the root's point is the light caps crossed on the way there. A sample is shadowed iff
//! `W != 0`, exactly as the counting methods' stencil (`faces.glsl` states the conventions).
//!
//! What makes it exact (details in `faces.glsl`, docs/exactness.md):
//! * every decision is the sign of a determinant of differences of f32 inputs, computed in f32
//!   and then f64 with a bound on the rounding error (a sign returned is the exact one);
//! * bridge ends are *lifted* samples: a sample moved towards the eye by 2^-12 of its distance
//!   (at least 128 units in the last place of its coordinates; `hier/hierarchy.glsl`,
//!   `lifted()`), so that no bridge between node points runs inside a surface (two samples of
//!   a floor joined by a bridge in the floor's plane would meet every floor triangle edge-on);
//!   a node's point is the lifted point of its most central sample or child, and the
//!   hierarchy's bounds hold the lifted points too, so every bridge below a node lies within
//!   the node's bounds and a face that misses the bounds crosses none of them;
//! * a point on a face's plane counts as moved towards the eye, a bridge through an edge's line
//!   passes on one fixed side of the edge's canonical orientation, the same for every face
//!   sharing it; a sample's count is taken at a point moved along its ray towards the eye,
//!   2^-21 of its coordinates in front of its own plane (within its envelope): the count in
//!   front of its surface, the stencil's (`faces.glsl`, `count_point`);
//! * unsure decisions the rules had to resolve are counted ([`HierSilhouette::unsure_counts`]).
//!
//! Band (umbra_oracle::envelope; judged with `BandParts::SILHOUETTE`, as the rasterizing
//! silhouette methods). It rasterizes no face, so nothing in its decision is a depth test's
//! resolution: of the parts that come from depth-testing rasterized faces, CANCELLING does not
//! apply (no faces on edges that cast nothing, [`ShadowMethod::silhouette_sides`]); SIDE_FACE
//! and SURFACE stay in its band because their size is the sample's envelope, whose position
//! part (the f32 world position interpolated by the depth pass, moved onto its own plane) is
//! this method's own uncertainty too — a face passing that close to the sample decides it by
//! rounding. FACING, ORIENTATION (it orients faces with the same f32 test, bit for bit
//! cpu-silhouette's), REFERENCE_EPS (no eps) and NEAR_CUT (its samples are the depth pass's,
//! clipped by the near plane) apply as to every method.
//!
//! Per frame (shared with hier-triangle, [`crate::methods::hier`]): "samples", "hierarchy"
//! (with the lifted points and the nodes' points). Per light:
//! 1. "light-bounds": the nodes' direction bounds from the light; the counts cleared;
//! 2. "batches": the faces in batches ([`hier::layout::batches`]); per batch `setup.comp.glsl`
//!    (one invocation per face: a triangle's orientation or an edge record's multiplicity,
//!    bit for bit cpu-silhouette's; a light cap's crossings of the segments from the light to
//!    the top nodes' points; the face against the top nodes), per level `descend.comp.glsl`
//!    (each queued pair: the bridges to the node's children and the children the face may
//!    meet), then `descend.comp.glsl` again with `u_negate` over the pairs of faces a full queue
//!    turned away (their bridges subtracted: they are counted again whole; no workgroup unless
//!    a queue overflowed), then `leaves.comp.glsl` (one workgroup per leaf with pairs, one
//!    invocation per sample: the bridge from the leaf's point to the sample against the leaf's
//!    list);
//! 3. "redo": [`hier::layout::REDO_ROUNDS`] rounds of the same passes over the turned-away
//!    faces; "fallback": the shared walk `hier/walk.comp.glsl` with this method's hooks
//!    (`fallback.comp.glsl`), what is still left, one invocation per face descending
//!    depth-first with atomic counts (normally no workgroup at all);
//! 4. "sum": `sum.comp.glsl`, per sample `W` = the top node's count + its ancestors' bridge
//!    counts + its own;
//! 5. "stencil": `resolve.frag.glsl` writes stencil 1 where `W != 0`
//!    ([`Classification::StencilZero`], [`ShadowMethod::fills_volumes`] false).
//!
//! Bounds on work and memory as hier-triangle's: every shader loop runs at most 64 iterations
//! except the walk of a leaf's list (one pair per face of a batch or redo round), the
//! fallback's walk (at most [`layout::FALLBACK_STEPS`] per pass, resumed across passes: llvmpipe
//! gives an invocation 65,535 loop iterations in all, every loop together) and an edge
//! record's multiplicity (at most [`layout::MAX_OPPOSITES_PER_RECORD`] opposites); the queues
//! have a fixed capacity per frame size and what does not fit is counted again, never dropped.
//! Memory: [`layout::Faces::edge_bytes`] per scene plus [`layout::frame_bytes`] per frame size
//! (docs/benchmarks.md states it per resolution); every allocation is checked, one the GL
//! refuses is [`GlError::OutOfMemory`], nothing is left behind and the method stays usable.
//!
//! Stages reported: "samples", "hierarchy", "light-bounds", "batches", "redo", "fallback",
//! "sum", "stencil".

pub mod layout;

use glow::HasContext;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_with_data, checked_size, BufferApi, BufferData};
use crate::methods::hier::layout::Layout;
use crate::methods::hier::{self, FrameObjects, LightUniforms, Passes, SharedPrograms, WorkCounter};
use crate::methods::method::{Classification, ShadowMethod, VolumeFrame};
use crate::program::uniform;
use crate::scene::{SceneGpu, SceneId};
use layout::{Counts, Faces, FALLBACK_STEPS, MAX_OPPOSITES_PER_RECORD};

/// Registry name.
pub const NAME: &str = "hier-silhouette";

const MULTIPLICITY: &str = include_str!("../shared/multiplicity.glsl");
const FACES: &str = include_str!("faces.glsl");
const SETUP_COMP: &str = include_str!("setup.comp.glsl");
const DESCEND_COMP: &str = include_str!("descend.comp.glsl");
const LEAVES_COMP: &str = include_str!("leaves.comp.glsl");
const FALLBACK_COMP: &str = include_str!("fallback.comp.glsl");
const SUM_COMP: &str = include_str!("sum.comp.glsl");
const ZERO_COMP: &str = include_str!("zero.comp.glsl");
const RESOLVE_FRAG: &str = include_str!("resolve.frag.glsl");

/// Shader-storage binding of the edge records and opposites (faces.glsl).
const EDGES: u32 = 6;
/// Shader-storage binding of the counts (faces.glsl).
const COUNTS: u32 = 8;

/// vec4 per node: bounds, direction bound, point.
const NODE_VEC4S: usize = 4;

/// The GLSL text before every stage's own source: the hierarchy's header (4 vec4 per node,
/// lifted points), the shared multiplicity and faces.glsl.
fn header() -> String {
    format!("{}{MULTIPLICITY}\n{FACES}\n", hier::header(NODE_VEC4S, true))
}

struct Programs {
    shared: SharedPrograms,
    setup: glow::Program,
    descend: glow::Program,
    leaves: glow::Program,
    fallback: glow::Program,
    sum: glow::Program,
    zero: glow::Program,
    resolve: glow::Program,
}

impl Programs {
    fn all(&self) -> Vec<glow::Program> {
        let mut v = self.shared.all().to_vec();
        v.extend([self.setup, self.descend, self.leaves, self.fallback, self.sum, self.zero, self.resolve]);
        v
    }

    fn link(gl: &glow::Context) -> Result<Programs, GlError> {
        let fallback = hier::fallback_source(FALLBACK_COMP);
        let computes = [
            ("setup", "hier_silhouette/setup.comp.glsl", SETUP_COMP),
            ("descend", "hier_silhouette/descend.comp.glsl", DESCEND_COMP),
            ("leaves", "hier_silhouette/leaves.comp.glsl", LEAVES_COMP),
            ("fallback", "hier_silhouette/fallback.comp.glsl", &fallback),
            ("sum", "hier_silhouette/sum.comp.glsl", SUM_COMP),
            ("zero", "hier_silhouette/zero.comp.glsl", ZERO_COMP),
        ];
        let p = hier::link_method(
            gl,
            NAME,
            &header(),
            &hier::header(NODE_VEC4S, true),
            &computes,
            ("hier_silhouette/resolve.frag.glsl", RESOLVE_FRAG),
        )?;
        let own = p.own;
        Ok(Programs {
            shared: p.shared,
            setup: own[0],
            descend: own[1],
            leaves: own[2],
            fallback: own[3],
            sum: own[4],
            zero: own[5],
            resolve: own[6],
        })
    }
}

/// Per scene: programs, the edge buffer, the resolve's empty vertex array.
struct SceneObjects {
    programs: Programs,
    edges: glow::Buffer,
    empty_vao: glow::VertexArray,
    faces: Faces,
    max_groups: u32,
    /// The origin of directional planes (the centre of the scene's bounds).
    centre: [f32; 3],
}

/// Per frame size: the hierarchy and the counts.
struct FrameCounts {
    hierarchy: FrameObjects,
    counts: glow::Buffer,
    regions: Counts,
}

/// A node's point (world space) and the count `W` there ([`HierSilhouette::node_counts`]).
pub type NodeCount = ([f32; 3], i32);

/// A view sample: its world position (f32) and its triangle ([`HierSilhouette::samples`]).
pub type Sample = ([f32; 3], u32);

/// See the module documentation.
pub struct HierSilhouette {
    prepared: Option<SceneId>,
    scene: Option<SceneObjects>,
    frame: Option<FrameCounts>,
    queue_scale: f64,
    fallback_steps: u32,
    work: WorkCounter,
}

impl Default for HierSilhouette {
    fn default() -> Self {
        Self::new()
    }
}

impl HierSilhouette {
    /// Builds the method (no GL calls).
    pub fn new() -> Self {
        Self {
            prepared: None,
            scene: None,
            frame: None,
            queue_scale: 1.0,
            fallback_steps: FALLBACK_STEPS,
            work: WorkCounter::default(),
        }
    }

    /// The same method with every queue's capacity multiplied by `scale` (> 0): tests shrink
    /// the queues to send faces through the redo rounds and the fallback; the counts must not
    /// change.
    pub fn with_queue_scale(scale: f64) -> Self {
        Self { queue_scale: if scale > 0.0 && scale.is_finite() { scale } else { 1.0 }, ..Self::new() }
    }

    /// The same method with fallback passes of `steps` steps (at least 1; the default is
    /// [`layout::FALLBACK_STEPS`]): tests make every walk of the fallback stop and resume many
    /// times, as llvmpipe's loop budget makes the long walks of a large frame do; the counts must
    /// not change.
    pub fn with_fallback_steps(self, steps: u32) -> Self {
        Self { fallback_steps: steps.clamp(1, FALLBACK_STEPS), ..self }
    }

    /// The hierarchy of the last frame size drawn, if any.
    pub fn layout(&self) -> Option<&Layout> {
        self.frame.as_ref().map(|f| &f.hierarchy.layout)
    }

    /// The prepared scene's faces, if any.
    pub fn faces(&self) -> Option<Faces> {
        self.scene.as_ref().map(|s| s.faces)
    }

    /// Per level (leaves first): the pairs the last batch (or redo round) of the last light
    /// queued at that level — more than the capacity when some were turned away — and the
    /// capacity.
    pub fn queue_counts(&self, gl: &glow::Context) -> Vec<(u32, u32)> {
        let Some(f) = self.frame.as_ref() else { return Vec::new() };
        let words = f.hierarchy.control_words(gl);
        f.hierarchy.layout.levels.iter().enumerate().map(|(l, level)| (words[4 * l], level.queue_capacity)).collect()
    }

    /// Faces of the last light that a full queue turned away during the batches (counted again
    /// by the redo rounds).
    pub fn redo_faces(&self, gl: &glow::Context) -> u32 {
        self.frame
            .as_ref()
            .map_or(0, |f| f.hierarchy.control_words(gl).get(hier::layout::REDO_CONTROL).copied().unwrap_or(0))
    }

    /// The last light's per-sample counts `W` (the stencil counts of cpu-silhouette): rows top
    /// first (as [`crate::StencilImage`]), 0 where no sample; `None` before a frame. A read-back
    /// (a stall): for tests and statistics.
    pub fn sample_counts(&self, gl: &glow::Context) -> Option<Vec<i32>> {
        let f = self.frame.as_ref()?;
        let (w, h) = (f.hierarchy.layout.width as usize, f.hierarchy.layout.height as usize);
        let words = hier::read_words(gl, f.counts, f.regions.partial, w * h);
        let present = hier::read_words(gl, f.hierarchy.samples, 0, 4 * w * h);
        let mut out = vec![0i32; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if present[4 * i + 3] != u32::MAX {
                    out[(h - 1 - y) * w + x] = words[i] as i32;
                }
            }
        }
        Some(out)
    }

    /// The last frame's view samples: per pixel, rows top first (as [`Self::sample_counts`]),
    /// the world position (f32, as the depth pass interpolated it) and the triangle, `None`
    /// where no sample; `None` before a frame. A read-back (a stall): for tests, which recount
    /// a sample's bridges on the CPU.
    pub fn samples(&self, gl: &glow::Context) -> Option<Vec<Option<Sample>>> {
        let f = self.frame.as_ref()?;
        let (w, h) = (f.hierarchy.layout.width as usize, f.hierarchy.layout.height as usize);
        let words = hier::read_words(gl, f.hierarchy.samples, 0, 4 * w * h);
        let mut out = vec![None; w * h];
        for y in 0..h {
            for x in 0..w {
                let s = &words[4 * (y * w + x)..4 * (y * w + x) + 4];
                if s[3] != u32::MAX {
                    out[(h - 1 - y) * w + x] = Some(([s[0], s[1], s[2]].map(f32::from_bits), s[3]));
                }
            }
        }
        Some(out)
    }

    /// The last light's unsure decisions that a fixed rule resolved (faces.glsl): on bridges
    /// between node points, on bridges to samples, on the segments from the light to the top
    /// nodes' points. `[0; 3]` before a frame.
    pub fn unsure_counts(&self, gl: &glow::Context) -> [u32; 3] {
        self.frame.as_ref().map_or([0; 3], |f| {
            let w = hier::read_words(gl, f.counts, 0, 3);
            [w[0], w[1], w[2]]
        })
    }

    /// The last light's count `W` at every node's point, level by level (leaves first, each
    /// level row by row), with the point: `None` for an empty node. A read-back (a stall): for
    /// tests, which check the bridges against a brute-force count at the points.
    pub fn node_counts(&self, gl: &glow::Context) -> Option<Vec<Vec<Option<NodeCount>>>> {
        let f = self.frame.as_ref()?;
        let layout = &f.hierarchy.layout;
        let nodes = hier::read_words(gl, f.hierarchy.nodes, 0, 4 * NODE_VEC4S * layout.nodes() as usize);
        let bridges = hier::read_words(gl, f.counts, f.regions.bridges, layout.nodes() as usize);
        let top = hier::read_words(gl, f.counts, f.regions.top, layout.top().nodes() as usize);
        let float = |i: usize| f32::from_bits(nodes[i]);
        let mut out = Vec::with_capacity(layout.levels.len());
        for (l, level) in layout.levels.iter().enumerate() {
            let mut row = Vec::with_capacity(level.nodes() as usize);
            for node in 0..level.nodes() {
                let g = (level.first_node + node) as usize;
                let base = 4 * NODE_VEC4S * g;
                if float(base + 3) > float(base + 7) {
                    row.push(None);
                    continue;
                }
                let point = [float(base + 12), float(base + 13), float(base + 14)];
                // W at the point: the top node's count plus the bridges down to this node.
                let (mut x, mut y) = (node % level.width, node / level.width);
                let mut w = 0i32;
                for (k, up) in layout.levels.iter().enumerate().skip(l) {
                    let here = y * up.width + x;
                    if k + 1 == layout.levels.len() {
                        w += top[here as usize] as i32;
                    } else {
                        w += bridges[(up.first_node + here) as usize] as i32;
                    }
                    x /= hier::layout::BRANCH_SIDE;
                    y /= hier::layout::BRANCH_SIDE;
                }
                row.push(Some((point, w)));
            }
            out.push(row);
        }
        Some(out)
    }

    fn destroy_frame(&mut self, gl: &glow::Context) {
        if let Some(f) = self.frame.take() {
            f.hierarchy.destroy(gl);
            // SAFETY: our own buffer, not used afterwards.
            unsafe { gl.delete_buffer(f.counts) };
        }
    }

    /// The frame-size objects for `width x height`, (re)allocated when the size changed.
    fn ensure_frame(&mut self, gl: &glow::Context, width: u32, height: u32) -> Result<(), GlError> {
        let Some(faces) = self.scene.as_ref().map(|s| s.faces) else {
            return Err(GlError::InvalidParams("hier-silhouette: draw_volumes before prepare".into()));
        };
        if self.frame.as_ref().is_some_and(|f| f.hierarchy.layout.width == width && f.hierarchy.layout.height == height)
        {
            return Ok(());
        }
        self.destroy_frame(gl);
        let layout = Layout::with_points(width, height, faces.count(), self.queue_scale);
        hier::check_places(NAME, &layout)?;
        let regions = Counts::new(&layout, &faces);
        let counts = hier::allocate_buffers(gl, &[regions.bytes()], &["hier-silhouette counts"])?[0];
        let names = [
            "hier-silhouette samples",
            "hier-silhouette node bounds",
            "hier-silhouette state",
            "hier-silhouette queues",
        ];
        match FrameObjects::allocate(gl, layout, names) {
            Ok(hierarchy) => {
                self.frame = Some(FrameCounts { hierarchy, counts, regions });
                Ok(())
            }
            Err(e) => {
                // SAFETY: our own buffer, never handed out.
                unsafe { gl.delete_buffer(counts) };
                Err(e)
            }
        }
    }
}

/// faces.glsl's uniforms on `program` (current).
fn set_face_uniforms(gl: &glow::Context, program: glow::Program, faces: &Faces, regions: &Counts, negate: bool) {
    let u = |name| uniform(gl, program, name);
    // SAFETY: our linked program, current; uniform types match faces.glsl / descend.comp.glsl.
    unsafe {
        gl.uniform_1_u32(u("u_caps").as_ref(), faces.triangles as u32);
        gl.uniform_1_u32(u("u_opposites_offset").as_ref(), faces.opposites_offset() as u32);
        gl.uniform_1_u32(u("u_counts_bridges").as_ref(), regions.bridges as u32);
        gl.uniform_1_u32(u("u_counts_partial").as_ref(), regions.partial as u32);
        gl.uniform_1_u32(u("u_counts_top").as_ref(), regions.top as u32);
        gl.uniform_1_u32(u("u_counts_orient").as_ref(), regions.orient as u32);
        gl.uniform_1_u32(u("u_counts_mult").as_ref(), regions.mult as u32);
        gl.uniform_1_u32(u("u_negate").as_ref(), u32::from(negate));
    }
}

impl ShadowMethod for HierSilhouette {
    fn name(&self) -> &'static str {
        NAME
    }

    fn stages(&self) -> &'static [&'static str] {
        &["samples", "hierarchy", "light-bounds", "batches", "redo", "fallback", "sum", "stencil"]
    }

    fn fills_volumes(&self) -> bool {
        false
    }

    /// True: its faces are paper 001's silhouette sides (edges of nonzero multiplicity) and the
    /// light caps, none on an edge that casts nothing, so the reference's CANCELLING band part
    /// (two opposite per-triangle faces that cancel only if ordered alike) does not apply to it
    /// (umbra_verify::band_mask: `BandParts::SILHOUETTE`). See the module doc, "Band".
    fn silhouette_sides(&self) -> bool {
        true
    }

    fn classification(&self) -> Classification {
        Classification::StencilZero
    }

    fn prepare(&mut self, gl: &glow::Context, scene: &SceneGpu) -> Result<(), GlError> {
        self.destroy(gl);
        let mesh = scene.mesh();
        let adj = scene.adjacency();
        // SAFETY: plain limit queries on the current context.
        let (fragment_blocks, max_groups) = unsafe {
            (
                gl.get_parameter_i32(glow::MAX_FRAGMENT_SHADER_STORAGE_BLOCKS),
                gl.get_parameter_indexed_i32(glow::MAX_COMPUTE_WORK_GROUP_COUNT, 0),
            )
        };
        if fragment_blocks < 8 {
            return Err(GlError::Unsupported {
                method: NAME,
                reason: format!(
                    "needs 8 shader storage blocks in the fragment shader, the driver offers {fragment_blocks}"
                ),
            });
        }
        // Edge records as cs-silhouette's: an edge with more opposites than a record holds is
        // split over consecutive records (their multiplicities add up to the edge's).
        let mut words: Vec<u32> = Vec::with_capacity(4 * adj.len() + adj.opposites.len());
        for (e, &[a, b]) in adj.edges.iter().enumerate() {
            let (mut start, end) = (adj.opposite_start[e], adj.opposite_start[e + 1]);
            loop {
                let n = (end - start).min(MAX_OPPOSITES_PER_RECORD);
                words.extend_from_slice(&[a, b, start, n]);
                start += n;
                if start >= end {
                    break;
                }
            }
        }
        let faces = Faces { triangles: mesh.triangles.len(), records: words.len() / 4, opposites: adj.opposites.len() };
        words.extend_from_slice(&adj.opposites);
        if u32::try_from(faces.count()).is_err() || u32::try_from(words.len()).is_err() {
            return Err(GlError::InvalidParams(format!(
                "hier-silhouette: {} faces / {} edge words exceed 32-bit indices",
                faces.count(),
                words.len()
            )));
        }
        checked_size(faces.edge_bytes(), "hier-silhouette edges")?;
        let programs = Programs::link(gl)?;
        // An empty mesh still gets a (one-word) buffer so every binding stays valid.
        if words.is_empty() {
            words.push(0);
        }
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_ne_bytes()).collect();
        let edges = match buffer_with_data(
            gl,
            BufferApi::Dsa,
            BufferData::Bytes(&bytes),
            glow::STATIC_DRAW,
            "hier-silhouette edges",
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
                // SAFETY: our own buffer.
                unsafe { gl.delete_buffer(edges) };
                hier::delete_programs(gl, &programs.all());
                return Err(GlError::Create { what: "hier-silhouette vertex array", detail });
            }
        };
        let centre = scene.bounds().map_or([0.0; 3], |b| b.center());
        self.scene = Some(SceneObjects {
            programs,
            edges,
            empty_vao,
            faces,
            max_groups: max_groups.clamp(1, i32::MAX) as u32,
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
        let faces = self
            .scene
            .as_ref()
            .map(|s| s.faces)
            .ok_or_else(|| GlError::InvalidParams("hier-silhouette: draw_volumes before prepare".into()))?;
        if faces.triangles == 0 {
            // Nothing casts a shadow: the stencil stays 0 everywhere.
            return Ok(());
        }
        let fresh = !self
            .frame
            .as_ref()
            .is_some_and(|f| f.hierarchy.layout.width == frame.width && f.hierarchy.layout.height == frame.height);
        self.ensure_frame(gl, frame.width, frame.height)?;
        let (Some(s), Some(fc)) = (self.scene.as_ref(), self.frame.as_mut()) else {
            return Err(GlError::InvalidParams("hier-silhouette: objects missing".into()));
        };
        let regions = fc.regions;
        let f = &mut fc.hierarchy;
        let layout = f.layout.clone();
        let light = LightUniforms::new(frame, 0.0, s.centre);
        let p = &s.programs;
        let passes = Passes::new(gl, &p.shared, &layout, s.max_groups, self.work.on());
        self.work.begin(gl, f, fresh);
        passes.bind(scene, f);
        // SAFETY: our buffers (edges only read; counts written and read by the passes).
        unsafe {
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, EDGES, Some(s.edges));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, COUNTS, Some(fc.counts));
        }
        passes.samples_and_hierarchy(scene, frame, f, &light);
        passes.light_bounds(frame, &light);
        let counting = |program: glow::Program| set_face_uniforms(gl, program, &faces, &regions, false);
        let negating = |program: glow::Program| set_face_uniforms(gl, program, &faces, &regions, true);
        // The counts of the previous light (or frame) are read by nothing any more.
        passes.use_with_common(p.zero, &light);
        counting(p.zero);
        // SAFETY: our program; uniform type matches zero.comp.glsl.
        unsafe { gl.uniform_1_u32(uniform(gl, p.zero, "u_count").as_ref(), regions.cleared_words() as u32) };
        passes.dispatch(p.zero, regions.cleared_words());

        // A batch's (or round's) passes after its setup: the levels counting; the levels again
        // subtracting the turned-away faces' bridges (no workgroup while the output redo list
        // is empty); the leaves.
        let traverse = |l: &LightUniforms| {
            passes.descend_levels(p.descend, l, &counting, None);
            let redo_out = hier::layout::REDO_CONTROL + 4 * l.redo_out as usize;
            passes.descend_levels(p.descend, l, &negating, Some(redo_out));
            passes.leaves(p.leaves, l, &counting);
        };
        frame.mark(gl, "batches");
        // SAFETY: binding our state buffer as the indirect dispatch source (unbound by the
        // fallback).
        unsafe { gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, Some(f.state)) };
        for (i, batch) in hier::layout::batches(faces.count()).into_iter().enumerate() {
            // SAFETY: barrier only. Reason: the cleared state and counts, or the previous
            // batch's queues (consumed) and lists, are written next.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            if i > 0 {
                passes.reset_queues(&light);
            }
            passes.use_with_common(p.setup, &light);
            counting(p.setup);
            // SAFETY: our program; uniform types match setup.comp.glsl.
            unsafe {
                gl.uniform_1_u32(uniform(gl, p.setup, "u_batch_end").as_ref(), batch.end as u32);
                gl.uniform_1_u32(uniform(gl, p.setup, "u_from_redo").as_ref(), 0);
            }
            passes.dispatch_from(p.setup, batch.start, batch.len());
            traverse(&light);
        }
        frame.mark(gl, "redo");
        let round_light = passes.redo_rounds(p.setup, &light, &counting, &traverse);
        frame.mark(gl, "fallback");
        passes.fallback(p.fallback, &round_light, &counting, self.fallback_steps);

        frame.mark(gl, "sum");
        // SAFETY: barrier only. Reason: the sum reads every count the passes above wrote.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        passes.use_with_common(p.sum, &light);
        counting(p.sum);
        passes.dispatch(p.sum, layout.width as usize * layout.height as usize);

        frame.mark(gl, "stencil");
        crate::state::GlState::stencil_mark_resolve().apply(gl);
        // SAFETY: our program and empty vertex array; the frame's target and viewport.
        unsafe {
            // Reason: the fragment shader reads the counts the sum wrote.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, frame.target_framebuffer);
            gl.viewport(0, 0, layout.width as i32, layout.height as i32);
        }
        passes.use_with_common(p.resolve, &light);
        counting(p.resolve);
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
            EDGES,
            hier::QUEUES,
            COUNTS,
            hier::WORK,
        ]);
        self.work.end(&passes);
        Ok(())
    }

    fn set_count_work(&mut self, on: bool) {
        self.work.set(on);
    }

    fn work_counts(&mut self, gl: &glow::Context) -> Option<crate::WorkCounts> {
        self.work.read(gl, self.frame.as_ref().map(|f| &f.hierarchy))
    }

    fn gpu_bytes(&self) -> usize {
        self.scene.as_ref().map_or(0, |s| s.faces.edge_bytes().max(4))
            + self.frame.as_ref().map_or(0, |f| f.hierarchy.layout.frame_bytes() + f.regions.bytes())
    }

    fn destroy(&mut self, gl: &glow::Context) {
        self.destroy_frame(gl);
        if let Some(s) = self.scene.take() {
            hier::delete_programs(gl, &s.programs.all());
            // SAFETY: our own objects, not used afterwards.
            unsafe {
                gl.delete_buffer(s.edges);
                gl.delete_vertex_array(s.empty_vao);
            }
        }
        self.prepared = None;
    }
}
