//! The hierarchy's programs: the GLSL header every hier stage starts with, the five programs
//! both hier methods share ([`SharedPrograms`]), and [`link_method`], which links a method's own
//! compute stages and its resolve together with them (one place for both methods' linking).

use glow::HasContext;

use crate::error::GlError;
use crate::program::{link_program, ShaderSource};

use super::layout::{BRANCH_SIDE, CHILDREN, LEAF_SAMPLES, LEAF_SIDE, MAX_LEVELS, PLACE_NODE_BITS};
use super::RESOLVE_VERT;

const HIERARCHY: &str = include_str!("hierarchy.glsl");
const REGION: &str = include_str!("region.glsl");
const CLEAR_COMP: &str = include_str!("clear.comp.glsl");
const BOUNDS_COMP: &str = include_str!("bounds.comp.glsl");
const LIGHT_BOUNDS_COMP: &str = include_str!("light_bounds.comp.glsl");
const ARGS_COMP: &str = include_str!("args.comp.glsl");
const SAMPLES_FRAG: &str = include_str!("samples.frag.glsl");
const WALK_COMP: &str = include_str!("walk.comp.glsl");

/// A method's fallback program body: its walk hooks (its own fallback.comp.glsl), then the shared
/// resumable walk (walk.comp.glsl), which calls them.
pub fn fallback_source(hooks: &str) -> String {
    format!("{hooks}\n{WALK_COMP}")
}

/// The GLSL text before every stage's own source: version, the layout constants (the fallback
/// walk's place bits among them), hierarchy.glsl
/// and region.glsl. `lift`: the nodes bound their samples' lifted points and carry a point of
/// their own (hier-silhouette) in their fourth vec4; otherwise that vec4 holds the node's depth
/// occupancy (region.glsl, hier-triangle). The node stride follows `layout`.
pub fn header(node_vec4s: usize, lift: bool) -> String {
    format!(
        "#version 450 core\n#define LEAF_SIDE {LEAF_SIDE}u\n#define LEAF_SAMPLES {LEAF_SAMPLES}u\n\
         #define BRANCH_SIDE {BRANCH_SIDE}u\n#define CHILDREN {CHILDREN}u\n#define MAX_LEVELS {MAX_LEVELS}\n\
         #define NO_TRIANGLE 0xFFFFFFFFu\n#define NODE_VEC4S {node_vec4s}u\n#define LIFT {}\n#define OCCUPANCY {}\n\
         #define PLACE_NODE_BITS {PLACE_NODE_BITS}u\n{HIERARCHY}\n{REGION}\n",
        u32::from(lift),
        u32::from(!lift)
    )
}

/// Links one program per `(label, stages)`; on any failure deletes what was linked and
/// returns the error.
pub fn link_all(gl: &glow::Context, specs: &[(String, Vec<ShaderSource<'_>>)]) -> Result<Vec<glow::Program>, GlError> {
    let mut done: Vec<glow::Program> = Vec::with_capacity(specs.len());
    for (name, stages) in specs {
        match link_program(gl, name, stages, &[]) {
            Ok(p) => done.push(p),
            Err(e) => {
                delete_programs(gl, &done);
                return Err(e);
            }
        }
    }
    Ok(done)
}

/// Deletes programs we created (not used afterwards).
pub fn delete_programs(gl: &glow::Context, programs: &[glow::Program]) {
    // SAFETY: programs we created, not used afterwards.
    unsafe {
        for &p in programs {
            gl.delete_program(p);
        }
    }
}

/// The hierarchy's own programs, linked with the method's header (its node stride and lift).
pub struct SharedPrograms {
    /// clear.comp.glsl.
    pub clear: glow::Program,
    /// bounds.comp.glsl.
    pub bounds: glow::Program,
    /// light_bounds.comp.glsl.
    pub light_bounds: glow::Program,
    /// args.comp.glsl.
    pub args: glow::Program,
    /// The scene's vertex shader with samples.frag.glsl.
    pub samples: glow::Program,
}

impl SharedPrograms {
    /// Links the five programs, labelled `"{method} clear"` etc.
    pub fn link(gl: &glow::Context, method: &str, head: &str) -> Result<SharedPrograms, GlError> {
        let comp = |body: &str| format!("{head}\n{body}");
        let sources = [
            ("clear", comp(CLEAR_COMP), "hier/clear.comp.glsl"),
            ("bounds", comp(BOUNDS_COMP), "hier/bounds.comp.glsl"),
            ("light bounds", comp(LIGHT_BOUNDS_COMP), "hier/light_bounds.comp.glsl"),
            ("args", comp(ARGS_COMP), "hier/args.comp.glsl"),
        ];
        let mut specs: Vec<(String, Vec<ShaderSource<'_>>)> = sources
            .iter()
            .map(|(label, source, file)| {
                (format!("{method} {label}"), vec![ShaderSource { stage: glow::COMPUTE_SHADER, name: file, source }])
            })
            .collect();
        specs.push((
            format!("{method} samples"),
            vec![
                ShaderSource::vertex("shaders/scene.vert.glsl", crate::scene::SCENE_VERT),
                ShaderSource::fragment("hier/samples.frag.glsl", SAMPLES_FRAG),
            ],
        ));
        let p = link_all(gl, &specs)?;
        Ok(SharedPrograms { clear: p[0], bounds: p[1], light_bounds: p[2], args: p[3], samples: p[4] })
    }

    /// All five, for deletion.
    pub fn all(&self) -> [glow::Program; 5] {
        [self.clear, self.bounds, self.light_bounds, self.args, self.samples]
    }
}

/// A hier method's programs: the shared five, then its own, in the order given.
pub struct MethodPrograms {
    /// The hierarchy's programs, linked with `shared_head`.
    pub shared: SharedPrograms,
    /// `computes` in order, then the resolve.
    pub own: Vec<glow::Program>,
}

/// Links a hier method's programs: each `(label, file, body)` of `computes` as a compute
/// program `"{method} {label}"` from `head` + body, the resolve from shaders/fullscreen.vert.glsl and
/// `head` + `resolve_frag` (named `resolve_file` in errors), and the shared five with
/// `shared_head`. On any failure nothing is left linked.
pub fn link_method(
    gl: &glow::Context,
    method: &str,
    head: &str,
    shared_head: &str,
    computes: &[(&str, &'static str, &str)],
    resolve: (&'static str, &str),
) -> Result<MethodPrograms, GlError> {
    let sources: Vec<(String, &'static str, String)> = computes
        .iter()
        .map(|(label, file, body)| (format!("{method} {label}"), *file, format!("{head}\n{body}")))
        .collect();
    // The resolve counts no work: WORK_STUB right after the #version line gives it the no-op
    // count_work and no work-counter block (hierarchy.glsl).
    let resolve_head = head.replacen("#version 450 core\n", "#version 450 core\n#define WORK_STUB 1\n", 1);
    let resolve_frag = format!("{resolve_head}\n{}", resolve.1);
    let mut specs: Vec<(String, Vec<ShaderSource<'_>>)> = sources
        .iter()
        .map(|(name, file, source)| {
            (name.clone(), vec![ShaderSource { stage: glow::COMPUTE_SHADER, name: file, source }])
        })
        .collect();
    specs.push((
        format!("{method} resolve"),
        vec![
            ShaderSource::vertex("shaders/fullscreen.vert.glsl", RESOLVE_VERT),
            ShaderSource::fragment(resolve.0, &resolve_frag),
        ],
    ));
    let own = link_all(gl, &specs)?;
    match SharedPrograms::link(gl, method, shared_head) {
        Ok(shared) => Ok(MethodPrograms { shared, own }),
        Err(e) => {
            delete_programs(gl, &own);
            Err(e)
        }
    }
}
