//! Live GL objects per kind, counted by probing every name with the glIs* entry points up
//! to a bound above the highest name a new object gets now.

use umbra_gl::glow;

/// `GLboolean glIsX(GLuint)`.
pub(crate) type IsFn = unsafe extern "system" fn(name: u32) -> u8;

/// The glIs* entry points, loaded through EGL (the headless context is an EGL context).
pub(crate) struct IsFunctions(Vec<(&'static str, IsFn)>);

pub(crate) const KINDS: [&str; 11] = [
    "glIsBuffer",
    "glIsTexture",
    "glIsFramebuffer",
    "glIsRenderbuffer",
    "glIsProgram",
    "glIsShader",
    "glIsVertexArray",
    "glIsQuery",
    "glIsSampler",
    "glIsProgramPipeline",
    "glIsTransformFeedback",
];

impl IsFunctions {
    pub(crate) fn load() -> Self {
        use khronos_egl as egl;
        // SAFETY: loads the system libEGL, which the headless context already uses.
        let instance = unsafe { egl::DynamicInstance::<egl::EGL1_4>::load_required() }.expect("libEGL");
        Self(
            KINDS
                .iter()
                .map(|&name| {
                    let f = instance.get_proc_address(name).unwrap_or_else(|| panic!("{name} not found"));
                    // SAFETY: eglGetProcAddress returned this GL entry point; every glIs* has
                    // the C signature GLboolean (GLuint).
                    (name, unsafe { std::mem::transmute::<extern "system" fn(), IsFn>(f) })
                })
                .collect(),
        )
    }
}

/// Live GL objects per kind (in [`KINDS`] order), how many of the programs are only flagged
/// for deletion (`GL_DELETE_STATUS`: deleted by umbra but still referenced by the driver, see
/// [`GlObjects::count`]), and the highest live name.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct GlObjects {
    pub(crate) per_kind: Vec<usize>,
    pub(crate) pending_programs: usize,
    pub(crate) highest: u32,
}

impl GlObjects {
    /// Counts by probing every name up to a doubling bound (see the module doc). The
    /// context of `is` must be current.
    ///
    /// A program umbra deleted stays alive, flagged `GL_DELETE_STATUS`, while the driver
    /// still refers to it (measured after `cs-silhouette` and `ts-silhouette`: one to three
    /// such programs, replaced by newer ones as other methods draw); those are counted in
    /// `pending_programs` too.
    pub(crate) fn count(gl: &glow::Context, is: &IsFunctions) -> Self {
        use glow::HasContext;
        let program_kind = KINDS.iter().position(|&k| k == "glIsProgram").expect("glIsProgram probed");
        let mut bound = 4096u32.max(2 * fresh_names_high_water(gl));
        loop {
            let mut per_kind = vec![0; KINDS.len()];
            let mut pending_programs = 0;
            let mut highest = 0;
            for name in 1..=bound {
                for (k, (_, f)) in is.0.iter().enumerate() {
                    // SAFETY: glIs* accept any name and have no side effects.
                    if unsafe { f(name) } != 0 {
                        per_kind[k] += 1;
                        highest = name;
                        if k == program_kind {
                            let program = glow::NativeProgram(std::num::NonZeroU32::new(name).expect("name >= 1"));
                            // SAFETY: `name` is a program of the current context (glIsProgram).
                            if unsafe { gl.get_program_parameter_i32(program, glow::DELETE_STATUS) } != 0 {
                                pending_programs += 1;
                            }
                        }
                    }
                }
            }
            if highest < bound / 2 {
                return Self { per_kind, pending_programs, highest };
            }
            bound *= 2;
        }
    }

    /// Objects umbra still owns (everything but the programs only flagged for deletion).
    pub(crate) fn owned(&self) -> usize {
        self.total() - self.pending_programs
    }

    pub(crate) fn total(&self) -> usize {
        self.per_kind.iter().sum()
    }

    pub(crate) fn describe(&self) -> String {
        let parts: Vec<String> = KINDS
            .iter()
            .zip(&self.per_kind)
            .filter(|(_, &n)| n > 0)
            .map(|(k, n)| format!("{} {n}", k.trim_start_matches("glIs")))
            .collect();
        format!(
            "{} objects ({}; {} of the programs flagged for deletion; highest name {})",
            self.total(),
            parts.join(", "),
            self.pending_programs,
            self.highest
        )
    }
}

/// The highest name a new object of each kind gets right now (each created and deleted again).
/// Mesa hands out ever higher names per namespace, and programs and shaders share one that
/// grows by about a hundred per recreation of all methods: after a few thousand frames their
/// names lie far above every other kind's, so a bound found from the live names alone stops
/// below them (25 programs uncounted at block 47 of the long soak, measured). Probing up to
/// twice this high-water mark finds them.
pub(crate) fn fresh_names_high_water(gl: &glow::Context) -> u32 {
    use glow::HasContext;
    // SAFETY: each object is created on the current context and deleted at once.
    unsafe {
        let mut names = Vec::new();
        let b = gl.create_buffer().expect("buffer");
        names.push(b.0.get());
        gl.delete_buffer(b);
        let t = gl.create_texture().expect("texture");
        names.push(t.0.get());
        gl.delete_texture(t);
        let f = gl.create_framebuffer().expect("framebuffer");
        names.push(f.0.get());
        gl.delete_framebuffer(f);
        let r = gl.create_renderbuffer().expect("renderbuffer");
        names.push(r.0.get());
        gl.delete_renderbuffer(r);
        let p = gl.create_program().expect("program");
        names.push(p.0.get());
        gl.delete_program(p);
        let v = gl.create_vertex_array().expect("vertex array");
        names.push(v.0.get());
        gl.delete_vertex_array(v);
        let q = gl.create_query().expect("query");
        names.push(q.0.get());
        gl.delete_query(q);
        let s = gl.create_sampler().expect("sampler");
        names.push(s.0.get());
        gl.delete_sampler(s);
        let x = gl.create_transform_feedback().expect("transform feedback");
        names.push(x.0.get());
        gl.delete_transform_feedback(x);
        names.into_iter().max().unwrap_or(0)
    }
}
