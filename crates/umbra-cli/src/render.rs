//! `umbra render`: one frame to a PNG.

use std::path::Path;

use crate::backend::Backend;
use crate::config::RenderConfig;
use crate::error::CliError;
use crate::session::Session;

pub fn run(c: &RenderConfig) -> Result<(), CliError> {
    if c.backend == Backend::Wgpu {
        return crate::wgpu_backend::render(c);
    }
    let mut method = crate::methods::make_method(&c.method, &c.sm, "--method")?;
    let view = &c.view;
    let mut s = Session::new(view)?;
    let mut params = s.frame_params(view);
    let decision = crate::methods::choose_counter(c.counter, &s.welded.positions, &s.welded.triangles, &params.lights)?;
    crate::methods::report_counter(&decision);
    params.counter = decision.counter;
    let gl = s.context.gl();
    let images =
        s.renderer.render(gl, &s.scene, method.as_mut(), &params, None).map_err(|e| CliError::Gl(e.to_string()))?;
    images.rgba.save_png(Path::new(&c.out)).map_err(|e| CliError::Gl(e.to_string()))?;
    method.destroy(gl);
    eprintln!(
        "umbra: wrote {} ({}x{}, {} triangles, method {}, {})",
        c.out,
        view.width,
        view.height,
        s.welded.triangles.len(),
        c.method,
        s.context.renderer_string()
    );
    Ok(())
}
