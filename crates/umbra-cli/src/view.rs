//! `umbra view`: the interactive window (crate umbra-view) on the scene, camera and lights
//! that `umbra render` would draw with the same flags — same checked
//! [`crate::config::ViewConfig`], same frame parameters — so a screenshot of the window
//! matches `umbra render`'s PNG.

use std::sync::Arc;

use umbra_geom::weld::weld;

use crate::config::WindowConfig;
use crate::error::CliError;

/// Opens the window (see crate umbra_view); returns when it is closed or the script ends.
pub fn run(c: &WindowConfig) -> Result<(), CliError> {
    let view = &c.view;
    let welded = Arc::new(weld(&view.mesh));
    if welded.triangles.is_empty() {
        return Err(CliError::Other(format!("scene {:?} has no triangles to draw", view.scene_spec)));
    }
    let mut params = crate::session::frame_params_for(view, umbra_gl::scene::triangle_bounds(&welded));
    // As `render`: the counter for the initial lights (moving a light in the window keeps it).
    let decision = crate::methods::choose_counter(c.counter, &welded.positions, &welded.triangles, &params.lights)?;
    crate::methods::report_counter(&decision);
    params.counter = decision.counter;
    let config = umbra_view::ViewerConfig {
        scene_name: view.scene_spec.clone(),
        params,
        mesh: welded,
        method: c.method.clone(),
        script: c.script.clone(),
        screenshot: c.screenshot.clone(),
        mask_view: c.mask,
    };
    let summary = umbra_view::run(config).map_err(|e| CliError::Other(e.to_string()))?;
    if let Some((path, w, h)) = &summary.screenshot {
        eprintln!("umbra: wrote {} ({w}x{h}, {} frames, {})", path.display(), summary.frames, summary.gl_renderer);
    }
    Ok(())
}
