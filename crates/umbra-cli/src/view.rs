//! `umbra view`: the interactive window (crate umbra-view) on the scene, camera and lights
//! that `umbra render` would draw with the same flags — same checked [`ViewConfig`], same
//! frame parameters — so a screenshot of the window matches `umbra render`'s PNG.

use std::path::PathBuf;
use std::sync::Arc;

use umbra_geom::weld::weld;
use umbra_geom::{Aabb, WeldedMesh};
use umbra_gl::{Camera, FrameParams};

use crate::args::ViewWindowArgs;
use crate::config::{CliError, ViewConfig};
use crate::session::DEFAULT_METHOD;

/// Bounds of the vertices the triangles use (what `SceneGpu::bounds` reports for `render`).
fn triangle_bounds(mesh: &WeldedMesh) -> Option<Aabb> {
    let mut it = mesh.triangles.iter().flatten().map(|&i| mesh.positions[i as usize]);
    let first = it.next()?;
    Some(it.fold(Aabb { min: first, max: first }, |b, p| Aabb {
        min: [0, 1, 2].map(|k| b.min[k].min(p[k])),
        max: [0, 1, 2].map(|k| b.max[k].max(p[k])),
    }))
}

/// The frame parameters `render` uses for `view` (see `Session::frame_params`: the near plane
/// is 1e-3 of the scene's diagonal).
fn frame_params(view: &ViewConfig, welded: &WeldedMesh) -> FrameParams {
    let diagonal = triangle_bounds(welded).map_or(1.0, |b| b.diagonal() as f64).max(1e-6);
    let c = &view.camera;
    FrameParams {
        camera: Camera {
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_degrees: c.fov_y_degrees,
            near: diagonal * 1e-3,
        },
        width: view.width,
        height: view.height,
        lights: view.lights.clone(),
        zpass: view.zpass,
        ..FrameParams::default()
    }
}

pub fn run(a: &ViewWindowArgs) -> Result<(), CliError> {
    let method = a.method.as_deref().unwrap_or(DEFAULT_METHOD);
    if method == "help" || method == "list" {
        for name in umbra_gl::method_names() {
            println!("{name}");
        }
        return Ok(());
    }
    umbra_gl::create_method(method).map_err(|e| CliError::BadFlag { flag: "--method", message: e.to_string() })?;
    let mut flags = a.view.clone();
    if let Some(scene) = &a.scene_arg {
        flags.scene = scene.clone();
    }
    let view = ViewConfig::from_args(&flags)?;
    let welded = Arc::new(weld(&view.mesh));
    if welded.triangles.is_empty() {
        return Err(CliError::Other(format!("scene {:?} has no triangles to draw", view.scene_spec)));
    }
    let config = umbra_view::ViewerConfig {
        scene_name: view.scene_spec.clone(),
        params: frame_params(&view, &welded),
        mesh: welded,
        method: method.to_string(),
        script: a.script.as_ref().map(PathBuf::from),
        screenshot: a.screenshot.as_ref().map(PathBuf::from),
        mask_view: a.mask,
    };
    let summary = umbra_view::run(config).map_err(|e| CliError::Other(e.to_string()))?;
    if let Some((path, w, h)) = &summary.screenshot {
        eprintln!("umbra: wrote {} ({w}x{h}, {} frames, {})", path.display(), summary.frames, summary.gl_renderer);
    }
    Ok(())
}
