//! The view-sample hierarchy shared by `hier-triangle` and `hier-silhouette`: the frame's
//! samples, a hierarchy of sample clusters with 3-D bounds, and the breadth-first machinery
//! that tests a method's items (triangles' shadow frusta, shadow-volume faces) against it.
//!
//! Erik Sintorn, Viktor Kämpe, Ola Olsson, Ulf Assarsson, "Per-Triangle Shadow Volumes Using a
//! View-Sample Cluster Hierarchy", I3D 2014, Section 4: the depth buffer's samples clustered in
//! a hierarchy with 3-D bounds, built per frame, traversed top-down by each item.
//!
//! What this module owns (one algorithm: the hierarchy and its traversal; the tests of an item
//! against a node and a sample are the methods'):
//! * per frame (once for all lights, [`VolumeFrame::view_serial`]): "samples", the scene drawn
//!   with the renderer's own vertex shader over the frame's depth, depth func EQUAL, writes
//!   masked, the fragment shader (`samples.frag.glsl`) storing each visible sample's world
//!   position and triangle id; "hierarchy", `bounds.comp.glsl` per level bottom-up (leaves of
//!   4 x 4 pixels, 4 x 4 children per node up to one root, [`layout`]): each node's world box
//!   and clip-w range (with its screen tile: a frustum slab), and with `LIFT` (hier-silhouette)
//!   its own point;
//! * per light: `light_bounds.comp.glsl`, each node's bound of its samples' directions from the
//!   light;
//! * work counting ([`WorkCounter`]: dispatches on the CPU, node and leaf tests in GPU atomic
//!   counters, only when asked);
//! * hier-silhouette's traversal of a batch (hier-triangle has its own persistent traversal,
//!   `hier_triangle/traverse.comp.glsl`): per level from the top, one invocation per queued pair running
//!   the method's `descend` program over the 16 children, then the method's `leaves` program,
//!   one workgroup per leaf with pairs (indirect dispatches whose sizes `args.comp.glsl` writes
//!   from the queue counts, [`Passes::traverse`]); redo rounds over the items a full queue
//!   turned away ([`Passes::redo_rounds`]); the stencil state of the final resolve.
//!
//! Bounds: every shader loop here runs at most 64 iterations (llvmpipe gives an invocation
//! 65,535 loop iterations in all, every loop together); the queues have a fixed capacity per frame size. Memory:
//! [`layout::Layout::frame_bytes`]; every allocation is checked, one the GL refuses is
//! [`GlError::OutOfMemory`] and nothing is left behind.

pub(crate) mod buffers;
pub mod layout;
mod programs;
mod work;

pub use buffers::{allocate_buffers, read_words};
pub use programs::{delete_programs, fallback_source, header, link_all, link_method, MethodPrograms, SharedPrograms};
pub use work::WorkCounter;

use glow::HasContext;

use crate::error::GlError;
use crate::methods::method::VolumeFrame;
use crate::program::uniform;
use crate::scene::SceneGpu;
use crate::state::GlState;
use layout::{Layout, MAX_LEVELS};

/// The full-screen triangle of the methods' stencil resolves.
pub const RESOLVE_VERT: &str = include_str!("../../shaders/fullscreen.vert.glsl");

// Shader-storage binding points (hierarchy.glsl). Binding 0 is the renderer's normals and stays
// untouched; the renderer restores the caller's bindings after a method ran (saved.rs).
/// The scene's positions.
pub const POSITIONS: u32 = 1;
/// The scene's indices.
pub const INDICES: u32 = 2;
/// Per pixel: world position and triangle id.
pub const SAMPLES: u32 = 3;
/// Per node: bounds (and point).
pub const NODES: u32 = 4;
/// Control words, flags, lists.
pub const STATE: u32 = 5;
/// The queues of (item, node) pairs and the redo lists.
pub const QUEUES: u32 = 7;
/// The work counters (hierarchy.glsl, `Work`; binding 8 is hier-silhouette's counts).
pub const WORK: u32 = 9;
/// Words of the work-counter buffer (hierarchy.glsl: nodes tested, leaves tested, nodes pruned,
/// and one spare).
pub const WORK_WORDS: usize = layout::WORK_BYTES / 4;

/// `local_size_x` of every compute shader except args.comp.glsl.
pub const WORKGROUP: u32 = 64;

/// Per frame size: samples, node bounds, state, queues.
pub struct FrameObjects {
    /// The hierarchy these buffers were sized for.
    pub layout: Layout,
    /// Per pixel: world position, triangle id.
    pub samples: glow::Buffer,
    /// Per node: bounds (and point).
    pub nodes: glow::Buffer,
    /// Control words, flags, lists (and hier-triangle's order).
    pub state: glow::Buffer,
    /// Queues and redo lists.
    pub queues: glow::Buffer,
    /// The work counters ([`WORK_WORDS`] words).
    pub work: glow::Buffer,
    /// The view serial the samples and bounds were made for.
    pub serial: Option<u64>,
}

impl FrameObjects {
    /// Allocates the four buffers of `layout`, named by `names` (samples, nodes, state,
    /// queues) in errors. A refused store is the typed error and nothing is left behind.
    pub fn allocate(gl: &glow::Context, layout: Layout, names: [&'static str; 4]) -> Result<FrameObjects, GlError> {
        let sizes = [
            layout.sample_bytes(),
            layout.node_bytes(),
            layout.state_bytes(),
            layout.queue_bytes(),
            layout::WORK_BYTES,
        ];
        let names = [names[0], names[1], names[2], names[3], "hier work counters"];
        let made = allocate_buffers(gl, &sizes, &names)?;
        Ok(FrameObjects {
            layout,
            samples: made[0],
            nodes: made[1],
            state: made[2],
            queues: made[3],
            work: made[4],
            serial: None,
        })
    }

    /// The five buffers.
    pub fn buffers(&self) -> [glow::Buffer; 5] {
        [self.samples, self.nodes, self.state, self.queues, self.work]
    }

    /// Sets the work counters to 0.
    pub fn reset_work(&self, gl: &glow::Context) {
        // SAFETY: our own buffer, WORK_WORDS words long.
        unsafe { gl.named_buffer_sub_data_u8_slice(self.work, 0, &[0u8; 4 * WORK_WORDS]) };
    }

    /// The work counters read back (a stall): nodes tested, leaves tested, nodes pruned.
    pub fn read_work(&self, gl: &glow::Context) -> [u64; 3] {
        let w = read_words(gl, self.work, 0, WORK_WORDS);
        [w[0], w[1], w[2]].map(u64::from)
    }

    /// Deletes the buffers.
    pub fn destroy(self, gl: &glow::Context) {
        // SAFETY: our own buffers, not used afterwards.
        unsafe {
            for b in self.buffers() {
                gl.delete_buffer(b);
            }
        }
    }

    /// The control words of the state buffer (queue counts, dispatch commands, redo counts)
    /// read back (a stall): for tests and statistics, not for frames.
    pub fn control_words(&self, gl: &glow::Context) -> Vec<u32> {
        read_words(gl, self.state, 0, layout::CONTROL_WORDS)
    }
}

/// Refuses a frame whose hierarchy has more nodes than a fallback walk's place holds
/// ([`layout::PLACE_NODE_BITS`]; 16,384 x 16,384 has about 2^24): the error names `method` and
/// the size.
pub fn check_places(method: &str, layout: &Layout) -> Result<(), GlError> {
    if u64::from(layout.nodes()) >= 1u64 << layout::PLACE_NODE_BITS {
        return Err(GlError::InvalidParams(format!(
            "{method}: {}x{} has {} hierarchy nodes, more than the fallback's places hold (2^{})",
            layout.width,
            layout.height,
            layout.nodes(),
            layout::PLACE_NODE_BITS
        )));
    }
    Ok(())
}

/// hierarchy.glsl's light and view uniforms for one light of one frame.
#[derive(Clone)]
pub struct LightUniforms {
    /// The light (w = 1 point, w = 0 directional).
    pub light: [f32; 4],
    /// Unit direction towards a directional light (0 for a point light).
    pub dir: [f32; 3],
    /// Origin of plane offsets: the point light, or the scene's centre.
    pub origin: [f32; 3],
    /// hier-triangle's eps (the reference's).
    pub eps: f32,
    /// Row 3 of clip_from_world.
    pub view_w: [f32; 4],
    /// The eye relative to `origin`.
    pub eye_rel: [f32; 3],
    /// The eye in world space (lifted points).
    pub eye: [f32; 3],
    /// The view's rays (see [`view_rays`]).
    pub rays: [[f32; 3]; 3],
    /// A directional light's orthonormal basis of the plane perpendicular to it.
    pub basis: [[f32; 3]; 2],
    /// The redo list turned-away items go to, and the one a redo round reads.
    pub redo_out: u32,
    /// See `redo_out`.
    pub redo_in: u32,
}

impl LightUniforms {
    /// The uniforms of `frame`'s light, with `eps` and a directional light's plane origin
    /// `centre` (the scene's centre).
    pub fn new(frame: &VolumeFrame<'_>, eps: f32, centre: [f32; 3]) -> Self {
        let light = frame.light;
        let point = light[3] != 0.0;
        let len = light[..3].iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt();
        let dir = if point || len == 0.0 { [0.0; 3] } else { [0, 1, 2].map(|k| (f64::from(light[k]) / len) as f32) };
        let origin = if point { [0, 1, 2].map(|k| light[k] / light[3]) } else { centre };
        let (view_w, rays) = view_rays(&frame.clip_from_world);
        let eye_rel = [0, 1, 2].map(|k| (frame.eye[k] - f64::from(origin[k])) as f32);
        let eye = frame.eye.map(|c| c as f32);
        let d = glam::DVec3::from(dir.map(f64::from));
        let u = if d.x.abs() < 0.9 { glam::DVec3::X } else { glam::DVec3::Y }.cross(d).normalize_or_zero();
        let v = d.cross(u).normalize_or_zero();
        let basis = [u, v].map(|b| b.to_array().map(|c| c as f32));
        Self { light, dir, origin, eps, view_w, eye_rel, eye, rays, basis, redo_out: 0, redo_in: 0 }
    }
}

/// Row 3 of `clip_from_world` (a world point's clip w) and the ray directions of the view:
/// the point of NDC (x, y) at clip w is `eye + w (x R_x + y R_y + R_c)`, `[R_x, R_y, R_c]` =
/// the inverse of the 3 x 3 matrix of rows 0, 1 and 3's xyz (rows 0, 1 and 3 vanish at the eye,
/// the centre of projection, whatever the depth convention). Zero rays for a singular matrix
/// (then every slab is empty of meaning: the world boxes alone decide; see region.glsl).
pub fn view_rays(clip_from_world: &glam::DMat4) -> ([f32; 4], [[f32; 3]; 3]) {
    let row = |i: usize| clip_from_world.row(i);
    let (r0, r1, r3) = (row(0), row(1), row(3));
    let m = glam::DMat3::from_cols(r0.truncate(), r1.truncate(), r3.truncate()).transpose();
    let inv = if m.determinant().abs() > 0.0 { m.inverse() } else { glam::DMat3::ZERO };
    let col = |v: glam::DVec3| v.to_array().map(|c| c as f32);
    (r3.to_array().map(|c| c as f32), [col(inv.x_axis), col(inv.y_axis), col(inv.z_axis)])
}

/// One frame size's passes: the shared programs, the layout and the dispatch limit.
pub struct Passes<'a> {
    /// The context.
    pub gl: &'a glow::Context,
    /// The hierarchy's programs.
    pub shared: &'a SharedPrograms,
    /// The frame's hierarchy.
    pub layout: &'a Layout,
    /// GL_MAX_COMPUTE_WORK_GROUP_COUNT along x.
    pub max_groups: u32,
    /// Whether the shaders add to the work counters (`u_count_work`).
    pub count_work: bool,
    /// Compute dispatches issued through these passes.
    pub dispatches: std::cell::Cell<u64>,
}

impl<'a> Passes<'a> {
    /// The passes of one light's draw: no work counted yet.
    pub fn new(
        gl: &'a glow::Context,
        shared: &'a SharedPrograms,
        layout: &'a Layout,
        max_groups: u32,
        count_work: bool,
    ) -> Self {
        Self { gl, shared, layout, max_groups, count_work, dispatches: std::cell::Cell::new(0) }
    }

    /// Counts one dispatch (work counts).
    pub fn counted(&self) {
        self.dispatches.set(self.dispatches.get() + 1);
    }

    /// Runs `count` invocations of `program` (current) in chunks of at most `max_groups`
    /// workgroups of [`WORKGROUP`], telling the shader where each chunk starts (`u_first`).
    pub fn dispatch(&self, program: glow::Program, count: usize) {
        self.dispatch_from(program, 0, count);
    }

    /// [`Passes::dispatch`] of the invocations `first .. first + count`.
    pub fn dispatch_from(&self, program: glow::Program, first: usize, count: usize) {
        let gl = self.gl;
        let u_first = uniform(gl, program, "u_first");
        let per_dispatch = self.max_groups as usize * WORKGROUP as usize;
        let mut start = 0usize;
        while start < count {
            let n = (count - start).min(per_dispatch);
            // SAFETY: the program is current; n.div_ceil(WORKGROUP) <= max_groups.
            unsafe {
                gl.uniform_1_u32(u_first.as_ref(), (first + start) as u32);
                gl.dispatch_compute(n.div_ceil(WORKGROUP as usize) as u32, 1, 1);
            }
            self.counted();
            start += n;
        }
    }

    /// Makes `program` current and sets hierarchy.glsl's uniforms on it.
    pub fn use_with_common(&self, program: glow::Program, light: &LightUniforms) {
        let gl = self.gl;
        let layout = self.layout;
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
        // SAFETY: our linked program; uniform types match hierarchy.glsl.
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
            gl.uniform_3_f32_slice(u("u_eye_world").as_ref(), &light.eye);
            gl.uniform_3_f32_slice(u("u_ray_x").as_ref(), &light.rays[0]);
            gl.uniform_3_f32_slice(u("u_ray_y").as_ref(), &light.rays[1]);
            gl.uniform_3_f32_slice(u("u_ray_c").as_ref(), &light.rays[2]);
            gl.uniform_1_u32(u("u_count_work").as_ref(), u32::from(self.count_work));
        }
    }

    /// Byte offset of the DispatchIndirectCommand after the count at control word `word`.
    pub fn command_offset(word: usize) -> i32 {
        (4 * (word + 1)) as i32
    }

    /// Writes the DispatchIndirectCommand for the entries counted at control word `word`
    /// (clamped to `capacity`), `per_group` entries per workgroup, between the barriers it
    /// needs. The state buffer must be bound as GL_DISPATCH_INDIRECT_BUFFER.
    pub fn indirect(&self, light: &LightUniforms, word: usize, capacity: u32, per_group: u32) {
        self.indirect_gated(light, word, capacity, per_group, None);
    }

    /// [`Passes::indirect`], with no workgroup at all while the state word `gate` is 0.
    pub fn indirect_gated(
        &self,
        light: &LightUniforms,
        word: usize,
        capacity: u32,
        per_group: u32,
        gate: Option<usize>,
    ) {
        let gl = self.gl;
        let args = self.shared.args;
        // SAFETY: barriers and a one-invocation dispatch of our program.
        unsafe {
            // Reason: the list's count and entries were written by the pass before.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
            self.use_with_common(args, light);
            gl.uniform_1_u32(uniform(gl, args, "u_args_word").as_ref(), word as u32);
            gl.uniform_1_u32(uniform(gl, args, "u_args_capacity").as_ref(), capacity);
            gl.uniform_1_u32(uniform(gl, args, "u_pairs_per_group").as_ref(), per_group);
            gl.uniform_1_u32(uniform(gl, args, "u_args_gate").as_ref(), gate.map_or(u32::MAX, |g| g as u32));
            gl.dispatch_compute(1, 1, 1);
            self.counted();
            // Reason: COMMAND: the next dispatch sources its size from the command just
            // written; SHADER_STORAGE: and its shader reads that state.
            gl.memory_barrier(glow::COMMAND_BARRIER_BIT | glow::SHADER_STORAGE_BARRIER_BIT);
        }
    }

    /// One batch's (or redo round's) passes after its setup: [`Passes::descend_levels`], then
    /// [`Passes::leaves`].
    pub fn traverse(
        &self,
        descend: glow::Program,
        leaves: glow::Program,
        light: &LightUniforms,
        with_method: &dyn Fn(glow::Program),
    ) {
        self.descend_levels(descend, light, with_method, None);
        self.leaves(leaves, light, with_method);
    }

    /// Per level from the top, the children of the queued pairs: `descend` (which reads
    /// `u_pass_level`), one invocation per pair. With a `gate`, no workgroup while that state
    /// word is 0. The state buffer must be bound as GL_DISPATCH_INDIRECT_BUFFER. `with_method`
    /// sets the method's own uniforms on the program after the common ones.
    pub fn descend_levels(
        &self,
        descend: glow::Program,
        light: &LightUniforms,
        with_method: &dyn Fn(glow::Program),
        gate: Option<usize>,
    ) {
        let gl = self.gl;
        let layout = self.layout;
        for l in (1..layout.levels.len()).rev() {
            self.indirect_gated(light, 4 * l, layout.levels[l].queue_capacity, WORKGROUP, gate);
            self.use_with_common(descend, light);
            with_method(descend);
            // SAFETY: our program; the command was written by `indirect_gated`.
            unsafe {
                gl.uniform_1_u32(uniform(gl, descend, "u_pass_level").as_ref(), l as u32);
                gl.dispatch_compute_indirect(Self::command_offset(4 * l));
            }
            self.counted();
        }
    }

    /// The active leaves' lists: `leaves`, one workgroup per leaf with pairs (indirect).
    pub fn leaves(&self, leaves: glow::Program, light: &LightUniforms, with_method: &dyn Fn(glow::Program)) {
        self.indirect(light, layout::ACTIVE_CONTROL, self.layout.leaves(), 1);
        self.use_with_common(leaves, light);
        with_method(leaves);
        // SAFETY: our program; the command was written by `indirect`.
        unsafe { self.gl.dispatch_compute_indirect(Self::command_offset(layout::ACTIVE_CONTROL)) };
        self.counted();
    }

    /// Empties the queues, leaf lists and active leaves for the next batch or round (their
    /// counts and the list heads; the redo lists, coverage and masks carry over).
    pub fn reset_queues(&self, light: &LightUniforms) {
        self.clear_state_range(light, 0, layout::REDO_CONTROL);
        self.clear_state_range(light, self.layout.heads_offset(), self.layout.leaves() as usize);
        // SAFETY: barrier only. Reason: the cleared words are read and written next.
        unsafe { self.gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
    }

    /// Sets the state words `first .. first + count` to 0.
    pub fn clear_state_range(&self, light: &LightUniforms, first: usize, count: usize) {
        let gl = self.gl;
        let clear = self.shared.clear;
        self.use_with_common(clear, light);
        // SAFETY: our program; uniform types match clear.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, clear, "u_count").as_ref(), (first + count) as u32);
            gl.uniform_1_u32(uniform(gl, clear, "u_what").as_ref(), 1);
        }
        self.dispatch_from(clear, first, count);
    }

    /// Clears `count` elements of the samples (`what` 0) or state (`what` 1) buffer.
    pub fn clear(&self, light: &LightUniforms, what: u32, count: usize) {
        let gl = self.gl;
        let clear = self.shared.clear;
        self.use_with_common(clear, light);
        // SAFETY: our program; uniform types match clear.comp.glsl.
        unsafe {
            gl.uniform_1_u32(uniform(gl, clear, "u_count").as_ref(), count as u32);
            gl.uniform_1_u32(uniform(gl, clear, "u_what").as_ref(), what);
        }
        self.dispatch(clear, count);
    }

    /// Binds the hierarchy's buffers and the scene's to their binding points (the method binds
    /// its own).
    pub fn bind(&self, scene: &SceneGpu, f: &FrameObjects) {
        let gl = self.gl;
        // SAFETY: our buffers and the scene's (only read).
        unsafe {
            // Reason (SHADER_STORAGE): the previous light's or frame's shaders read the buffers
            // written next. BUFFER_UPDATE: a statistics read-back may have read the state.
            gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT | glow::BUFFER_UPDATE_BARRIER_BIT);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, POSITIONS, Some(scene.position_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, INDICES, Some(scene.index_buffer()));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, SAMPLES, Some(f.samples));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, NODES, Some(f.nodes));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, STATE, Some(f.state));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, QUEUES, Some(f.queues));
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, WORK, Some(f.work));
        }
    }

    /// Unbinds every storage binding in `bindings` (the renderer restores the caller's).
    pub fn unbind(&self, bindings: &[u32]) {
        // SAFETY: unbinding only.
        unsafe {
            for &b in bindings {
                self.gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, b, None);
            }
        }
    }

    /// Stages "samples" and "hierarchy": the frame's samples and the nodes' bounds, unless
    /// `f` already holds them for this frame's view serial (then only the "hierarchy" mark).
    pub fn samples_and_hierarchy(
        &self,
        scene: &SceneGpu,
        frame: &mut VolumeFrame<'_>,
        f: &mut FrameObjects,
        light: &LightUniforms,
    ) {
        let gl = self.gl;
        let layout = self.layout;
        let p = self.shared;
        let pixels = layout.width as usize * layout.height as usize;
        let serial = frame.view_serial();
        frame.mark(gl, "samples");
        if f.serial == Some(serial) {
            frame.mark(gl, "hierarchy");
            return;
        }
        self.clear(light, 0, pixels);
        GlState::visible_samples(frame.receivers).apply(gl);
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
            self.use_with_common(p.bounds, light);
            // SAFETY: our program; uniform type matches bounds.comp.glsl.
            unsafe { gl.uniform_1_u32(uniform(gl, p.bounds, "u_bounds_level").as_ref(), l as u32) };
            self.dispatch(p.bounds, level.nodes() as usize);
        }
        f.serial = Some(serial);
    }

    /// Stage "light-bounds": each node's bound of its samples' directions from the light,
    /// bottom-up; then the per-light state cleared.
    pub fn light_bounds(&self, frame: &mut VolumeFrame<'_>, light: &LightUniforms) {
        let gl = self.gl;
        let p = self.shared;
        frame.mark(gl, "light-bounds");
        for (l, level) in self.layout.levels.iter().enumerate() {
            // SAFETY: barrier only. Reason: each level reads what the level below (or the
            // bounds, or the previous light's passes) wrote.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            self.use_with_common(p.light_bounds, light);
            // SAFETY: our program; uniform type matches light_bounds.comp.glsl.
            unsafe { gl.uniform_1_u32(uniform(gl, p.light_bounds, "u_bounds_level").as_ref(), l as u32) };
            self.dispatch(p.light_bounds, level.nodes() as usize);
        }
        // SAFETY: barrier only. Reason: the previous light's passes read the state cleared next.
        unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
        self.clear(light, 1, self.layout.light_words());
    }

    /// Redo rounds: [`layout::REDO_ROUNDS`] rounds over the items a full queue turned away,
    /// through the method's `setup` (with `u_from_redo` = 1: the items of redo list
    /// `u_redo_in`, indirect) and `traverse` (the method's passes after a setup; list 0 from
    /// the batches, then alternating). Returns the uniforms of the fallback (its `redo_in` is
    /// the list left after the last round). The state buffer must be bound as
    /// GL_DISPATCH_INDIRECT_BUFFER.
    pub fn redo_rounds(
        &self,
        setup: glow::Program,
        light: &LightUniforms,
        with_method: &dyn Fn(glow::Program),
        traverse: &dyn Fn(&LightUniforms),
    ) -> LightUniforms {
        let gl = self.gl;
        let items = self.layout.triangles;
        let mut round_light = light.clone();
        for round in 0..layout::REDO_ROUNDS {
            round_light.redo_in = (round % 2) as u32;
            round_light.redo_out = ((round + 1) % 2) as u32;
            // SAFETY: barrier only. Reason: the last batch's passes wrote what is reset next.
            unsafe { gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT) };
            self.reset_queues(&round_light);
            // The output list's count and the flags saying who is in it.
            let out_count = layout::REDO_CONTROL + 4 * round_light.redo_out as usize;
            self.clear_state_range(&round_light, out_count, 1);
            self.clear_state_range(&round_light, self.layout.redo_flags_offset(), items.div_ceil(32));
            let in_count = layout::REDO_CONTROL + 4 * round_light.redo_in as usize;
            self.indirect(&round_light, in_count, items as u32, WORKGROUP);
            self.use_with_common(setup, &round_light);
            with_method(setup);
            // SAFETY: our program; uniform type matches the setup shaders; command just written.
            unsafe {
                gl.uniform_1_u32(uniform(gl, setup, "u_from_redo").as_ref(), 1);
                gl.dispatch_compute_indirect(Self::command_offset(in_count));
            }
            self.counted();
            traverse(&round_light);
        }
        round_light.redo_in = (layout::REDO_ROUNDS % 2) as u32;
        round_light
    }

    /// The fallback: what the last redo round left, one invocation per item (`fallback`, the
    /// method's hooks with walk.comp.glsl; indirect: normally no workgroup at all), in passes
    /// of at most `steps` walk steps per item ([`layout::FALLBACK_STEPS`] normally; fewer in
    /// tests), as many as the longest walk the layout allows ([`layout::fallback_passes`]):
    /// each pass resumes each item's walk where the pass before left it (llvmpipe's loop
    /// budget, walk.comp.glsl). Unbinds the indirect buffer afterwards.
    pub fn fallback(
        &self,
        fallback: glow::Program,
        round_light: &LightUniforms,
        with_method: &dyn Fn(glow::Program),
        steps: u32,
    ) {
        let gl = self.gl;
        let last = layout::REDO_CONTROL + 4 * round_light.redo_in as usize;
        self.indirect(round_light, last, self.layout.triangles as u32, WORKGROUP);
        self.use_with_common(fallback, round_light);
        with_method(fallback);
        let steps = steps.clamp(1, layout::FALLBACK_STEPS);
        // SAFETY: our program, current; uniform type matches walk.comp.glsl. The fallback has
        // no workgroup unless the last round turned items away.
        unsafe {
            gl.uniform_1_u32(uniform(gl, fallback, "u_fallback_steps").as_ref(), steps);
            for pass in 0..layout::fallback_passes(self.layout, steps) {
                if pass > 0 {
                    // Reason: the next pass reads the places the last one wrote.
                    gl.memory_barrier(glow::SHADER_STORAGE_BARRIER_BIT);
                }
                gl.dispatch_compute_indirect(Self::command_offset(last));
                self.counted();
            }
            gl.bind_buffer(glow::DISPATCH_INDIRECT_BUFFER, None);
        }
    }
}
