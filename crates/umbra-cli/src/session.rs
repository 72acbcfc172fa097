//! One headless GL session for a checked view: context, uploaded scene, renderer. Shared by
//! `render` and `verify` so both draw exactly the same frame.

use std::sync::Arc;

use umbra_geom::weld::{weld, WeldedMesh};
use umbra_gl::{Camera, FrameParams, HeadlessContext, Projection, Renderer, SceneGpu};

use crate::config::ViewConfig;
use crate::error::CliError;

pub struct Session {
    pub context: HeadlessContext,
    pub scene: SceneGpu,
    pub renderer: Renderer,
    pub welded: Arc<WeldedMesh>,
}

fn gl_err(e: impl std::fmt::Display) -> CliError {
    CliError::Gl(e.to_string())
}

/// The view's mesh welded, as every backend draws it. An empty scene is an error that says so
/// (there is nothing to draw).
pub fn welded_scene(view: &ViewConfig) -> Result<Arc<WeldedMesh>, CliError> {
    let welded = Arc::new(weld(&view.mesh));
    if welded.triangles.is_empty() {
        return Err(CliError::Other(format!(
            "scene {:?} has no triangles to draw ({} triangles in the file, {} degenerate)",
            view.scene_spec,
            view.mesh.triangles.len(),
            welded.degenerate_triangles
        )));
    }
    Ok(welded)
}

impl Session {
    /// Welds the mesh ([`welded_scene`]), creates the context and uploads the scene.
    pub fn new(view: &ViewConfig) -> Result<Self, CliError> {
        let welded = welded_scene(view)?;
        let context = HeadlessContext::new().map_err(gl_err)?;
        let gl = context.gl();
        let scene = SceneGpu::upload(gl, welded.clone()).map_err(gl_err)?;
        let renderer = Renderer::new(gl).map_err(gl_err)?.with_error_log(context.error_log().cloned());
        Ok(Session { context, scene, renderer, welded })
    }

    /// The frame parameters for a view (camera near plane scaled to the scene).
    pub fn frame_params(&self, view: &ViewConfig) -> FrameParams {
        frame_params_for(view, self.scene.bounds())
    }
}

/// The frame parameters `render`, `verify` and `view` use for `view` of a scene with
/// `bounds` (those of its triangles, [`umbra_gl::scene::triangle_bounds`]).
pub fn frame_params_for(view: &ViewConfig, bounds: Option<umbra_geom::Aabb>) -> FrameParams {
    let diagonal = bounds.map_or(1.0, |b| b.diagonal() as f64).max(1e-6);
    let c = &view.camera;
    // The infinite far plane puts all depth precision near the near plane: keep it as far
    // out as the scene allows.
    let near = near_plane(diagonal);
    let projection = match c.ortho {
        None => Projection::Perspective,
        // The far plane is fitted below.
        Some(height) => Projection::Orthographic { height, far: f64::INFINITY },
    };
    let mut camera =
        Camera { eye: c.eye, target: c.target, up: c.up, fov_y_degrees: c.fov_y_degrees, near, projection };
    fit_ortho_far(&mut camera, bounds);
    // `--ortho-far`: the far plane another renderer drew with (its depth steps), as given.
    if let (Projection::Orthographic { height, .. }, Some(far)) = (camera.projection, view.ortho_far) {
        camera.projection = Projection::Orthographic { height, far };
    }
    FrameParams {
        camera,
        width: view.width,
        height: view.height,
        lights: view.lights.clone(),
        zpass: view.zpass,
        auto_zpass: view.auto_zpass,
        volume_cull: view.volume_cull,
        receivers: view.receivers,
        ..FrameParams::default()
    }
}

/// The far plane of an orthographic view of a scene with `bounds`: beyond the farthest corner
/// of the box along the view direction by 1 % of its diagonal, so that the depth pass clips
/// nothing of the scene (the volumes, closed beyond the box, are drawn with depth clamp and
/// need no far plane of their own; docs/exactness.md, "Orthographic views").
/// Re-fit whenever the eye or the target moves. A perspective camera is left as it is.
pub fn fit_ortho_far(camera: &mut Camera, bounds: Option<umbra_geom::Aabb>) {
    let Projection::Orthographic { height, .. } = camera.projection else { return };
    let diagonal = bounds.map_or(1.0, |b| b.diagonal() as f64).max(1e-6);
    let f = camera.forward();
    let farthest = bounds.map_or(0.0, |b| {
        (0..8)
            .map(|i: usize| {
                let p: [f64; 3] = std::array::from_fn(|k| f64::from(if i >> k & 1 == 0 { b.min[k] } else { b.max[k] }));
                (0..3).map(|k| (p[k] - camera.eye[k]) * f[k]).sum::<f64>()
            })
            .fold(f64::MIN, f64::max)
    });
    let far = farthest.max(camera.near) + 0.01 * diagonal + camera.near;
    camera.projection = Projection::Orthographic { height, far };
}

/// A near-plane distance for a scene of `diagonal` seen from `eye`: a small fraction of the
/// scene size, so nearby geometry is not clipped and depth precision is not wasted.
fn near_plane(diagonal: f64) -> f64 {
    diagonal * 1e-3
}
