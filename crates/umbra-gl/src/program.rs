//! Compiling and linking GLSL programs, with the `.glsl` file name in every error.

use glow::HasContext;

use crate::error::GlError;

/// One shader stage's source: GL stage enum, file name (for errors), text.
#[derive(Clone, Copy, Debug)]
pub struct ShaderSource<'a> {
    /// GL stage enum (`glow::VERTEX_SHADER`, ...).
    pub stage: u32,
    /// File name, for error messages.
    pub name: &'a str,
    /// GLSL text (with `#version`).
    pub source: &'a str,
}

impl<'a> ShaderSource<'a> {
    /// A vertex shader.
    pub fn vertex(name: &'a str, source: &'a str) -> Self {
        Self { stage: glow::VERTEX_SHADER, name, source }
    }
    /// A fragment shader.
    pub fn fragment(name: &'a str, source: &'a str) -> Self {
        Self { stage: glow::FRAGMENT_SHADER, name, source }
    }
}

fn stage_name(stage: u32) -> &'static str {
    match stage {
        glow::VERTEX_SHADER => "vertex",
        glow::FRAGMENT_SHADER => "fragment",
        glow::GEOMETRY_SHADER => "geometry",
        glow::TESS_CONTROL_SHADER => "tessellation control",
        glow::TESS_EVALUATION_SHADER => "tessellation evaluation",
        glow::COMPUTE_SHADER => "compute",
        _ => "unknown stage",
    }
}

/// Compiles every stage and links them; `defines` are inserted as `#define NAME` lines right
/// after the `#version` line of each source.
pub fn link_program(
    gl: &glow::Context,
    program_name: &str,
    stages: &[ShaderSource<'_>],
    defines: &[&str],
) -> Result<glow::Program, GlError> {
    // SAFETY: object creation, compilation and linking on the current context; every object
    // created here is deleted on every error path.
    unsafe {
        let program = gl.create_program().map_err(|detail| GlError::Create { what: "program", detail })?;
        let mut shaders = Vec::with_capacity(stages.len());
        let mut failure = None;
        for s in stages {
            let shader = match gl.create_shader(s.stage) {
                Ok(sh) => sh,
                Err(detail) => {
                    failure = Some(GlError::Create { what: "shader", detail });
                    break;
                }
            };
            gl.shader_source(shader, &with_defines(s.source, defines));
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                failure = Some(GlError::Compile {
                    name: s.name.to_string(),
                    stage: stage_name(s.stage),
                    log: gl.get_shader_info_log(shader),
                });
                gl.delete_shader(shader);
                break;
            }
            gl.attach_shader(program, shader);
            shaders.push(shader);
        }
        if failure.is_none() {
            gl.link_program(program);
            if !gl.get_program_link_status(program) {
                failure = Some(GlError::Link { name: program_name.to_string(), log: gl.get_program_info_log(program) });
            }
        }
        for sh in shaders {
            gl.detach_shader(program, sh);
            gl.delete_shader(sh);
        }
        match failure {
            Some(e) => {
                gl.delete_program(program);
                Err(e)
            }
            None => Ok(program),
        }
    }
}

fn with_defines(source: &str, defines: &[&str]) -> String {
    if defines.is_empty() {
        return source.to_string();
    }
    let extra: String = defines.iter().map(|d| format!("#define {d}\n")).collect();
    // `#version` must stay the first directive; comments before it are allowed.
    match source.find("#version") {
        Some(start) => {
            let line_end = source[start..].find('\n').map_or(source.len(), |i| start + i + 1);
            format!("{}{}{}", &source[..line_end], extra, &source[line_end..])
        }
        None => format!("{extra}{source}"),
    }
}

/// Uniform location or `None` (optimised away / absent).
pub fn uniform(gl: &glow::Context, program: glow::Program, name: &str) -> Option<glow::UniformLocation> {
    // SAFETY: query on a linked program of the current context.
    unsafe { gl.get_uniform_location(program, name) }
}

#[cfg(test)]
mod tests {
    use super::with_defines;

    #[test]
    fn defines_go_after_the_version_line() {
        let s = with_defines("// header\n#version 450 core\nvoid main(){}\n", &["A 1", "B"]);
        assert_eq!(s, "// header\n#version 450 core\n#define A 1\n#define B\nvoid main(){}\n");
    }
}
