//! `umbra render`: one frame to a PNG.

use std::path::Path;

use crate::args::RenderArgs;
use crate::config::{CliError, ViewConfig};
use crate::session::{Session, DEFAULT_METHOD};
use crate::wgpu_backend::Backend;

pub fn run(a: &RenderArgs) -> Result<(), CliError> {
    let backend = Backend::parse(&a.backend)?;
    let method_name = a.method.as_deref().unwrap_or(DEFAULT_METHOD);
    if crate::methods::list_if_help_for(backend, method_name) {
        return Ok(());
    }
    if backend == Backend::Wgpu {
        return crate::wgpu_backend::render(a, method_name);
    }
    let sm = crate::methods::SmOptions::from_args(&a.sm)?;
    let mut method = crate::methods::make_method(method_name, &sm, "--method")?;
    let view = ViewConfig::from_args(&a.view)?;
    let choice = crate::methods::CounterChoice::parse(&a.counter, "--counter")?;
    let mut s = Session::new(&view)?;
    let mut params = s.frame_params(&view);
    let decision = crate::methods::choose_counter(choice, &s.welded.positions, &s.welded.triangles, &params.lights)?;
    crate::methods::report_counter(&decision);
    params.counter = decision.counter;
    let gl = s.context.gl();
    let images =
        s.renderer.render(gl, &s.scene, method.as_mut(), &params, None).map_err(|e| CliError::Gl(e.to_string()))?;
    images.rgba.save_png(Path::new(&a.out)).map_err(|e| CliError::Gl(e.to_string()))?;
    method.destroy(gl);
    eprintln!(
        "umbra: wrote {} ({}x{}, {} triangles, method {}, {})",
        a.out,
        view.width,
        view.height,
        s.welded.triangles.len(),
        method_name,
        s.context.renderer_string()
    );
    Ok(())
}
