//! umbra-verify: renders a frame with a shadow method, reads back what the method decided per
//! sample, and compares it with the CPU ray-traced reference ([`umbra_oracle`]).
//!
//! This is the one tester behind `umbra verify` and the torture suite: the same case goes
//! through every registered method and the same numbers come out.
//!
//! Samples are the renderer's own: the depth pass writes each pixel's rasterized world
//! position and triangle id, and the reference classifies exactly those points (primary
//! visibility is never ray-traced separately). The method's classification is read back from
//! the stencil after its volume pass for that light and interpreted with the method's own
//! [`Classification`].

use std::sync::Arc;
use std::time::Instant;

use umbra_geom::weld::WeldedMesh;
use umbra_gl::glow;
use umbra_gl::{
    create_method, Classification, FrameParams, Renderer, RgbaImage, SceneGpu, ShadowMethod, StencilCapture,
    NO_TRIANGLE,
};
use umbra_oracle::{compare, reference, Bvh, Metrics, Reference, Samples};

/// Why a verification could not run (not: a method that failed it).
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    #[error("GL: {0}")]
    Gl(String),
    #[error("reference: {0}")]
    Oracle(#[from] umbra_oracle::OracleError),
    #[error("method {method}: {message}")]
    Method { method: String, message: String },
}

fn gl_err(e: impl std::fmt::Display) -> VerifyError {
    VerifyError::Gl(e.to_string())
}

/// Methods whose shadows must be exact per sample. The others are measured, never failed:
/// `none` (no shadows), shadow maps (they alias by construction) and `all-edges-invert`
/// (paper 002's trick is inexact wherever volumes of different triangles overlap).
pub fn must_be_exact(method: &str) -> bool {
    !(method == "none" || method.starts_with("shadow-map") || method == "all-edges-invert")
}

/// The reference for one light of one view.
pub struct LightReference {
    pub light: usize,
    pub reference: Reference,
    pub reference_ms: f64,
}

/// Samples of one view (camera + size) and the reference for each of its lights.
pub struct ViewReference {
    pub width: u32,
    pub height: u32,
    pub lights: Vec<LightReference>,
    /// Time to build the BVH (shared by every light and method).
    pub bvh_ms: f64,
}

impl ViewReference {
    /// Total reference time: BVH build plus every light's shadow rays.
    pub fn total_ms(&self) -> f64 {
        self.bvh_ms + self.lights.iter().map(|l| l.reference_ms).sum::<f64>()
    }
}

/// What one method decided for one light, and how that compares with the reference.
pub struct LightResult {
    pub light: usize,
    /// `true` = the method put the pixel in shadow; row-major, top row first.
    pub shadowed: Vec<bool>,
    pub metrics: Metrics,
}

/// A method's verification over every light of a view.
pub struct MethodReport {
    pub method: String,
    pub must_be_exact: bool,
    /// Summed over lights.
    pub metrics: Metrics,
    pub per_light: Vec<LightResult>,
    /// The rendered image (all lights).
    pub image: RgbaImage,
    /// Wall time of the renders (frame + readback), summed over lights.
    pub render_ms: f64,
}

impl MethodReport {
    pub fn passed(&self) -> bool {
        !self.must_be_exact || self.metrics.mismatches_outside_band == 0
    }
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

/// Renders the view's samples (world position + triangle id) and computes the reference for
/// every light in `params`.
pub fn view_reference(
    gl: &glow::Context,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    params: &FrameParams,
) -> Result<ViewReference, VerifyError> {
    let mesh: &Arc<WeldedMesh> = scene.mesh();
    let start = Instant::now();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles)?;
    let bvh_ms = ms(start);

    let mut p = params.clone();
    p.capture.world_pos = true;
    p.capture.triangle_id = true;
    p.capture.stencil = StencilCapture::None;
    let mut none = create_method("none").map_err(gl_err)?;
    let images = renderer.render(gl, scene, none.as_mut(), &p, None).map_err(gl_err);
    none.destroy(gl);
    let images = images?;
    let (Some(world), Some(ids)) = (images.world_pos, images.triangle_id) else {
        return Err(VerifyError::Gl("the renderer returned no world-position / triangle-id images".into()));
    };
    let world_pos: Vec<[f32; 3]> = world.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let triangle: Vec<u32> = ids.pixels.iter().map(|&t| if t == NO_TRIANGLE { u32::MAX } else { t }).collect();
    let samples = Samples { width: params.width, height: params.height, world_pos: &world_pos, triangle: &triangle };
    let eye = params.camera.eye.map(|c| c as f32);
    let mut lights = Vec::new();
    for (i, &light) in params.lights.iter().enumerate() {
        let start = Instant::now();
        let reference = reference(mesh, &bvh, &samples, light, eye)?;
        lights.push(LightReference { light: i, reference, reference_ms: ms(start) });
    }
    Ok(ViewReference { width: params.width, height: params.height, lights, bvh_ms })
}

/// Evaluates a stencil test `(reference & mask) func (stencil & mask)` as GL does.
fn stencil_test_passes(func: u32, reference: i32, mask: u32, stencil: u8) -> bool {
    let r = (reference as u32) & mask;
    let s = u32::from(stencil) & mask;
    match func {
        glow::NEVER => false,
        glow::LESS => r < s,
        glow::LEQUAL => r <= s,
        glow::GREATER => r > s,
        glow::GEQUAL => r >= s,
        glow::EQUAL => r == s,
        glow::NOTEQUAL => r != s,
        _ => true, // ALWAYS
    }
}

/// Renders `method` for every light of `params`, reads its per-sample decision and compares it
/// with `view` (from [`view_reference`] for the same params).
pub fn verify_method(
    gl: &glow::Context,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    method: &mut dyn ShadowMethod,
    params: &FrameParams,
    view: &ViewReference,
) -> Result<MethodReport, VerifyError> {
    let name = method.name().to_string();
    let classification = method.classification();
    let mut per_light = Vec::new();
    let mut metrics = Metrics::default();
    let mut render_ms = 0.0;
    let mut image = None;
    for lr in &view.lights {
        let mut p = params.clone();
        p.capture.stencil = StencilCapture::Light(lr.light);
        let start = Instant::now();
        let images = renderer.render(gl, scene, method, &p, None).map_err(gl_err)?;
        render_ms += ms(start);
        let stencil = images
            .stencil
            .into_iter()
            .find(|m| m.light == lr.light)
            .ok_or_else(|| VerifyError::Gl(format!("no stencil captured for light {}", lr.light)))?;
        let shadowed: Vec<bool> = match classification {
            Classification::StencilZero => stencil.image.pixels.iter().map(|&s| s != 0).collect(),
            Classification::StencilTest { func, reference, value_mask } => {
                stencil.image.pixels.iter().map(|&s| !stencil_test_passes(func, reference, value_mask, s)).collect()
            }
            Classification::Shader => {
                return Err(VerifyError::Method {
                    method: name,
                    message: "shader-classified methods cannot be verified from the stencil yet".into(),
                })
            }
        };
        let m = compare(&lr.reference, &shadowed)?;
        metrics = add(metrics, m);
        per_light.push(LightResult { light: lr.light, shadowed, metrics: m });
        image = Some(images.rgba);
    }
    let image = match image {
        Some(i) => i,
        None => renderer.render(gl, scene, method, params, None).map_err(gl_err)?.rgba,
    };
    Ok(MethodReport { must_be_exact: must_be_exact(&name), method: name, metrics, per_light, image, render_ms })
}

fn add(a: Metrics, b: Metrics) -> Metrics {
    Metrics {
        samples: a.samples + b.samples,
        shadowed_reference: a.shadowed_reference + b.shadowed_reference,
        mismatches: a.mismatches + b.mismatches,
        band_samples: a.band_samples + b.band_samples,
        band_mismatches: a.band_mismatches + b.band_mismatches,
        mismatches_outside_band: a.mismatches_outside_band + b.mismatches_outside_band,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stencil_test_semantics() {
        // paper 002: lit where stencil != 1100b under mask 1101b.
        assert!(stencil_test_passes(glow::NOTEQUAL, 0b1100, 0b1101, 0b0001));
        assert!(!stencil_test_passes(glow::NOTEQUAL, 0b1100, 0b1101, 0b1110));
        assert!(stencil_test_passes(glow::EQUAL, 0, 0xFF, 0));
        assert!(!stencil_test_passes(glow::EQUAL, 0, 0xFF, 3));
    }

    #[test]
    fn exactness_policy() {
        assert!(must_be_exact("cpu-silhouette"));
        assert!(must_be_exact("ts-silhouette"));
        assert!(!must_be_exact("none"));
        assert!(!must_be_exact("shadow-map-cube:2048"));
        assert!(!must_be_exact("all-edges-invert"));
    }
}
