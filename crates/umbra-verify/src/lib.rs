//! umbra-verify: renders a frame with a shadow method, reads back what the method decided per
//! sample, and compares it with the CPU ray-traced reference ([`umbra_oracle`]).
//!
//! This is the one tester behind `umbra verify` and the torture suite: the same case goes
//! through every registered method and the same numbers come out.
//!
//! Samples are the renderer's own: the depth pass writes each pixel's rasterized world
//! position and triangle id, and the reference classifies exactly those points (primary
//! visibility is never ray-traced separately).
//!
//! The method's decision per sample is the renderer's FINAL one, read back as the lit mask
//! ([`umbra_gl::LitMask`]): lit = the method's classification passes (stencil == 0, its own
//! stencil test, or its shader's `umbra_lit`) AND the seen side of the triangle faces the
//! light; shadowed = not lit. That is exactly what the image shows, for every
//! [`Classification`] (shadow maps included), and it matches the reference's definition (the
//! seen side facing away from the light is shadowed). The bare stencil is not that decision:
//! where the seen side faces away from the light its value does not matter, and near-edge-on
//! surfaces make it unreliable while the image is right. The stencil-based count is still
//! reported for stencil-classified methods ([`MethodReport::stencil_metrics`]), for diagnosis.
//!
//! Two backends, one comparison: [`view_reference`] / [`verify_method`] run umbra-gl, the
//! [`mod@wgpu`] module runs umbra-wgpu; both end in [`reference_from_samples`] and
//! [`compare_decisions`].

use std::sync::Arc;
use std::time::Instant;

use umbra_geom::camera::Camera;
use umbra_geom::weld::WeldedMesh;
use umbra_geom::Light;
use umbra_gl::glow;
use umbra_gl::{
    create_method, CaptureFlags, Classification, FrameParams, LightCapture, LitMaskImage, Renderer, RgbaImage,
    SceneGpu, ShadowMethod, TriangleIdImage, WorldPosImage, NO_TRIANGLE,
};

pub mod wgpu;
use umbra_oracle::{
    compare_masked, reference_in_view, BandParts, Bvh, DepthFormat, Metrics, RasterView, Reference, Samples,
};

/// Why a verification could not run (not: a method that failed it).
#[derive(Debug, thiserror::Error)]
pub enum VerifyError {
    #[error("GL: {0}")]
    Gl(String),
    #[error("wgpu: {0}")]
    Wgpu(String),
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
/// (paper 002's single pass counts in front of the sample, z-pass style, so it is wrong with
/// the camera inside a shadow volume, and ties near interior edges break its INVERT parity;
/// overlapping volumes of different triangles are fine, since stencil updates apply in
/// primitive order).
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
    /// The rasterized samples (row-major, top row first; `u32::MAX` = background), the BVH and
    /// the view, kept for [`explain`].
    pub world_pos: Vec<[f32; 3]>,
    pub triangle: Vec<u32>,
    pub bvh: Bvh,
    pub raster: RasterView,
    pub eye: [f32; 3],
    pub light_positions: Vec<umbra_geom::Light>,
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
    /// `true` = the renderer did not light the pixel with this light (lit mask 0: the
    /// method's classification failed or the seen side faces away from the light; also on
    /// background); row-major, top row first.
    pub shadowed: Vec<bool>,
    pub metrics: Metrics,
    /// The same comparison with "shadowed" read from the stencil after the volume pass,
    /// interpreted with the method's classification (`None` for [`Classification::Shader`]).
    /// Diagnostic only: it also counts samples whose seen side faces away from the light,
    /// where the stencil does not matter.
    pub stencil_metrics: Option<Metrics>,
}

/// A method's verification over every light of a view.
pub struct MethodReport {
    pub method: String,
    /// The band parts the method is judged by ([`band_mask`]).
    pub band_mask: BandParts,
    pub must_be_exact: bool,
    /// Summed over lights; from the lit masks (the renderer's final decision).
    pub metrics: Metrics,
    /// Summed over lights; from the stencil (see [`LightResult::stencil_metrics`]).
    pub stencil_metrics: Option<Metrics>,
    pub per_light: Vec<LightResult>,
    /// The rendered image (all lights).
    pub image: RgbaImage,
    /// Wall time of the render (one frame with every light, plus the readbacks).
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
/// every light in `params`, with the band of this context's precision ([`raster_view`]).
pub fn view_reference(
    gl: &glow::Context,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    params: &FrameParams,
) -> Result<ViewReference, VerifyError> {
    view_reference_in(gl, renderer, scene, params, raster_view(gl, params))
}

/// [`view_reference`] with the band of `raster`'s precision: for samples judged against
/// another rasterizer's decisions (an external mask from a browser whose `GL_SUBPIXEL_BITS`
/// differs from this context's).
pub fn view_reference_in(
    gl: &glow::Context,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    params: &FrameParams,
    raster: RasterView,
) -> Result<ViewReference, VerifyError> {
    let p = FrameParams {
        capture: CaptureFlags { world_pos: true, triangle_id: true, ..CaptureFlags::default() },
        ..params.clone()
    };
    let mut none = create_method("none").map_err(gl_err)?;
    let images = renderer.render(gl, scene, none.as_mut(), &p, None).map_err(gl_err);
    none.destroy(gl);
    let images = images?;
    let (Some(world), Some(ids)) = (images.world_pos, images.triangle_id) else {
        return Err(VerifyError::Gl("the renderer returned no world-position / triangle-id images".into()));
    };
    reference_from_samples(scene.mesh(), &params.camera, raster, &params.lights, &world, &ids)
}

/// The backend-neutral half of [`view_reference`]: the reference for every light of a view
/// whose samples a backend's depth pass captured with `camera` (the world position and the
/// triangle id of every pixel, [`NO_TRIANGLE`] = background), rasterized with the precision
/// `raster` describes (the band's envelope, [`umbra_oracle::envelope`]).
pub fn reference_from_samples(
    mesh: &Arc<WeldedMesh>,
    camera: &Camera,
    raster: RasterView,
    lights: &[Light],
    world: &WorldPosImage,
    ids: &TriangleIdImage,
) -> Result<ViewReference, VerifyError> {
    let (width, height) = (world.width, world.height);
    let world_pos: Vec<[f32; 3]> = world.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
    // The oracle's background is u32::MAX.
    let triangle: Vec<u32> = ids.pixels.iter().map(|&t| if t == NO_TRIANGLE { u32::MAX } else { t }).collect();
    let start = Instant::now();
    let bvh = Bvh::build(&mesh.positions, &mesh.triangles)?;
    let bvh_ms = ms(start);
    let samples = Samples { width, height, world_pos: &world_pos, triangle: &triangle };
    let eye = camera.eye.map(|c| c as f32);
    let mut references = Vec::new();
    for (i, &light) in lights.iter().enumerate() {
        let start = Instant::now();
        let reference = reference_in_view(mesh, &bvh, &samples, light, eye, Some(&raster))?;
        references.push(LightReference { light: i, reference, reference_ms: ms(start) });
    }
    Ok(ViewReference {
        width,
        height,
        lights: references,
        bvh_ms,
        world_pos,
        triangle,
        bvh,
        raster,
        eye,
        light_positions: lights.to_vec(),
    })
}

/// The view and the precision the renderer rasterizes `params` with, for the band
/// ([`umbra_oracle::envelope`]): its projection in the frame's depth convention, the depth
/// format of the renderer's own target for that convention (DEPTH32F_STENCIL8 for
/// reversed-Z, DEPTH24_STENCIL8 for the standard convention) and the context's
/// `GL_SUBPIXEL_BITS`.
pub fn raster_view(gl: &glow::Context, params: &FrameParams) -> RasterView {
    use umbra_gl::camera::DepthConventionGl;
    use umbra_gl::glow::HasContext;
    let aspect = params.width as f64 / params.height.max(1) as f64;
    let clip_from_world = params.camera.clip_from_world_in(aspect, params.depth_convention).to_cols_array();
    let depth = if params.depth_convention.depth_format() == glow::DEPTH32F_STENCIL8 {
        DepthFormat::Float32
    } else {
        DepthFormat::Fixed(24)
    };
    // SAFETY: a plain integer query on the current context.
    let bits = unsafe { gl.get_parameter_i32(glow::SUBPIXEL_BITS) };
    let mut view = RasterView::new(clip_from_world);
    view.depth = depth;
    // The faces the depth pass shows: the reference judges the samples that pass drew.
    view.receivers = params.receivers;
    // Parallel pixel rays in an orthographic view.
    view.orthographic_forward = params.camera.is_orthographic().then(|| params.camera.forward());
    // The spec's minimum when the query returns less (it may not).
    view.subpixel_bits = u32::try_from(bits).unwrap_or(0).max(view.subpixel_bits);
    view
}

/// The band parts of `ray-bvh`, which decides the reference's own samples by an f32 ray test
/// (docs/exactness.md): `FACING` (the lighting pass), `SIDE_FACE` and `CANCELLING` (the segment
/// passes within the envelope of an occluder's edge, where its f32 edge functions may take the
/// other sign), `ORIENTATION` (an occluder nearly edge-on to the light: all three edge
/// functions small), `REFERENCE_EPS` (a hit between its eps / 2 and the reference's eps). Not
/// `SURFACE` or `NEAR_CUT`: no volume face is rasterized, depth-tested or clipped.
pub const RAY_BVH_BAND: BandParts = BandParts(
    BandParts::FACING.0
        | BandParts::SIDE_FACE.0
        | BandParts::CANCELLING.0
        | BandParts::ORIENTATION.0
        | BandParts::REFERENCE_EPS.0,
);

/// The band parts `method` is judged by ([`umbra_oracle::envelope`]): a silhouette method
/// ([`ShadowMethod::silhouette_sides`]) draws no faces on edges that cast nothing, so the
/// cancelling faces of per-triangle volumes are not its band; `ray-bvh` ([`RAY_BVH_BAND`])
/// depth-tests nothing.
pub fn band_mask(method: &dyn ShadowMethod) -> BandParts {
    if method.name() == umbra_gl::methods::ray_bvh::NAME {
        RAY_BVH_BAND
    } else if method.silhouette_sides() {
        BandParts::SILHOUETTE
    } else {
        BandParts::SAME_SAMPLES
    }
}

/// What is known about the sample at pixel `(x, y)` for light `light` (an index into
/// [`ViewReference::lights`]), for diagnosing a mismatch: its triangle, position, the distance
/// of the pixel centre to its triangle's edges, the reference's class and band, and the first
/// occluder along the segment to the light (if any), with its distance from the segment's
/// start. One line of text.
pub fn explain(mesh: &WeldedMesh, view: &ViewReference, light: usize, x: u32, y: u32) -> String {
    let i = y as usize * view.width as usize + x as usize;
    let (Some(&t), Some(lr), Some(&l)) =
        (view.triangle.get(i), view.lights.get(light), view.light_positions.get(light))
    else {
        return format!("({x}, {y}): no such sample");
    };
    if t == u32::MAX || t as usize >= mesh.triangles.len() {
        return format!("({x}, {y}): background");
    }
    let p = view.world_pos[i];
    let tri = mesh.triangles[t as usize].map(|k| mesh.positions[k as usize].map(f64::from));
    let edge_px = view.raster.edge_distance_px(tri, x, y, view.width, view.height);
    let s = p.map(f64::from);
    let (dir, t_max) = if l[3] != 0.0 {
        ([0, 1, 2].map(|k| f64::from(l[k]) / f64::from(l[3]) - s[k]), 1.0)
    } else {
        ([0, 1, 2].map(|k| f64::from(l[k])), f64::INFINITY)
    };
    let len = dir.iter().map(|c| c * c).sum::<f64>().sqrt();
    let hit = view.bvh.intersect(s, dir, 0.0, t_max);
    let hit = match hit {
        Some(h) if h.triangle == t => format!("own triangle at {:.3e}", h.t * len),
        Some(h) => format!("triangle {} at distance {:.3e}", h.triangle, h.t * len),
        None => "nothing".into(),
    };
    format!(
        "({x}, {y}): triangle {t} {:?} at {:?}, pixel centre {} px from its edges; reference {:?}{}; first hit towards the light: {hit}",
        mesh.triangles[t as usize],
        p,
        edge_px.map_or("?".into(), |d| format!("{d:.4}")),
        lr.reference.class[i],
        match lr.reference.parts.get(i) {
            Some(parts) if lr.reference.band[i] => format!(" (band: {})", parts.names().join(", ")),
            _ if lr.reference.band[i] => " (band)".into(),
            _ => String::new(),
        },
    )
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

/// Renders `method` once with every light of `params`, reads its per-sample decision for each
/// light (the lit mask) and compares it with `view` (from [`view_reference`] for the same
/// params).
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
    let band = band_mask(method);
    let mut p = params.clone();
    p.capture.lit_mask = LightCapture::AllLights;
    // The stencil costs one more readback per light; only meaningful for stencil methods.
    p.capture.stencil =
        if classification == Classification::Shader { LightCapture::None } else { LightCapture::AllLights };
    let start = Instant::now();
    let images = renderer.render(gl, scene, method, &p, None).map_err(gl_err)?;
    let render_ms = ms(start);
    let decisions = light_decisions(
        view,
        |light| images.lit_masks.iter().find(|m| m.light == light).map(|m| &m.image),
        |light| {
            let stencil = images.stencil.iter().find(|s| s.light == light)?;
            stencil_shadowed(classification, &stencil.image.pixels)
        },
    )
    .map_err(VerifyError::Gl)?;
    compare_decisions(name, band, view, &decisions, images.rgba, render_ms)
}

/// What a frame decided for each of `view`'s lights: its lit mask (`lit_mask(light)`; missing
/// is an error naming the light) and, for diagnosis, `stencil_shadowed(light)`.
fn light_decisions<'a>(
    view: &ViewReference,
    lit_mask: impl Fn(usize) -> Option<&'a LitMaskImage>,
    stencil_shadowed: impl Fn(usize) -> Option<Vec<bool>>,
) -> Result<Vec<LightDecision>, String> {
    let decide = |light| {
        let mask = lit_mask(light).ok_or_else(|| format!("no lit mask captured for light {light}"))?;
        Ok(LightDecision { light, lit_mask: mask.pixels.clone(), stencil_shadowed: stencil_shadowed(light) })
    };
    view.lights.iter().map(|lr| decide(lr.light)).collect()
}

/// What a backend's frame decided for one light: its lit mask (1 = the lighting pass shaded
/// the pixel, row-major, top row first) and, for diagnosis, "shadowed" read from the stencil
/// after the volume pass (`None` where the stencil is not the method's decision).
pub struct LightDecision {
    /// Index of the light in the view.
    pub light: usize,
    /// 1 lit, 0 not, per pixel.
    pub lit_mask: Vec<u8>,
    /// From the stencil, per pixel.
    pub stencil_shadowed: Option<Vec<bool>>,
}

/// The backend-neutral half of [`verify_method`]: a method's per-light decisions compared
/// with `view`, under the one set of band rules: the parts `band` names
/// ([`band_mask`] for a GL method).
pub fn compare_decisions(
    name: String,
    band: BandParts,
    view: &ViewReference,
    decisions: &[LightDecision],
    image: RgbaImage,
    render_ms: f64,
) -> Result<MethodReport, VerifyError> {
    let mut per_light = Vec::new();
    let mut metrics = Metrics::default();
    let mut stencil_sum: Option<Metrics> = None;
    for lr in &view.lights {
        let d = decisions.iter().find(|d| d.light == lr.light).ok_or_else(|| VerifyError::Method {
            method: name.clone(),
            message: format!("no decision for light {}", lr.light),
        })?;
        let shadowed: Vec<bool> = d.lit_mask.iter().map(|&lit| lit == 0).collect();
        let m = compare_masked(&lr.reference, &shadowed, band)?;
        metrics = add(metrics, m);
        let stencil_metrics =
            d.stencil_shadowed.as_ref().map(|sh| compare_masked(&lr.reference, sh, band)).transpose()?;
        if let Some(sm) = stencil_metrics {
            stencil_sum = Some(add(stencil_sum.unwrap_or_default(), sm));
        }
        per_light.push(LightResult { light: lr.light, shadowed, metrics: m, stencil_metrics });
    }
    Ok(MethodReport {
        must_be_exact: must_be_exact(&name),
        method: name,
        band_mask: band,
        metrics,
        stencil_metrics: stencil_sum,
        per_light,
        image,
        render_ms,
    })
}

/// The pixel colour an external shadow mask uses for "lit" (the WebGL2 viewer's `mask=1` view
/// draws lit samples white, every other pixel black or its background colour).
pub const EXTERNAL_LIT: [u8; 3] = [255, 255, 255];

/// Compares a shadow mask made outside umbra's renderer (the WebGL2 viewer's mask view, read
/// back) with `view`'s reference, as if it were method `name`: lit = the pixel is exactly
/// [`EXTERNAL_LIT`], shadowed = anything else, background included (the lit-mask convention of
/// [`verify_method`]). `mask` is RGBA8, top row first, of the view's size; the view must have
/// exactly one light (a mask holds one light's decision). Must be exact: the mask claims to
/// be a shadow-volume method's.
pub fn verify_external_mask(name: &str, mask: &RgbaImage, view: &ViewReference) -> Result<MethodReport, VerifyError> {
    let fail = |message: String| VerifyError::Method { method: name.to_string(), message };
    if (mask.width, mask.height) != (view.width, view.height) {
        return Err(fail(format!(
            "the mask is {}x{}, the view {}x{}",
            mask.width, mask.height, view.width, view.height
        )));
    }
    let [lr] = view.lights.as_slice() else {
        return Err(fail(format!("a mask holds one light's decision, the view has {} lights", view.lights.len())));
    };
    let shadowed: Vec<bool> = mask.pixels.iter().map(|p| p[..3] != EXTERNAL_LIT).collect();
    // The WebGL viewer draws paper 003's silhouette volumes: no faces on edges that cast
    // nothing, so no cancelling faces' band (as `band_mask` for a silhouette method). Its
    // decisions were made on its own depth pass: the surface that pass saw is band where it
    // may not be the sample's (`SEEN_SURFACE`, computed when the view's raster says
    // `other_depth_pass`).
    let band = BandParts::SILHOUETTE | BandParts::SEEN_SURFACE;
    let metrics = compare_masked(&lr.reference, &shadowed, band)?;
    Ok(MethodReport {
        method: name.to_string(),
        band_mask: band,
        must_be_exact: true,
        metrics,
        stencil_metrics: None,
        per_light: vec![LightResult { light: lr.light, shadowed, metrics, stencil_metrics: None }],
        image: mask.clone(),
        render_ms: 0.0,
    })
}

/// "Shadowed" per pixel read from the stencil after the volume pass, for the stencil
/// classifications; `None` for [`Classification::Shader`].
fn stencil_shadowed(classification: Classification, stencil: &[u8]) -> Option<Vec<bool>> {
    match classification {
        Classification::StencilZero => Some(stencil.iter().map(|&s| s != 0).collect()),
        Classification::StencilTest { func, reference, value_mask } => {
            Some(stencil.iter().map(|&s| !stencil_test_passes(func, reference, value_mask, s)).collect())
        }
        Classification::Shader => None,
    }
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
    fn stencil_shadowed_follows_the_classification() {
        let st = [0u8, 1, 0b1100, 0b1110];
        assert_eq!(stencil_shadowed(Classification::StencilZero, &st), Some(vec![false, true, true, true]));
        let paper002 = Classification::StencilTest { func: glow::NOTEQUAL, reference: 0b1100, value_mask: 0b1101 };
        assert_eq!(stencil_shadowed(paper002, &st), Some(vec![false, false, true, true]));
        assert_eq!(stencil_shadowed(Classification::Shader, &st), None);
    }

    /// A 4x1 view with one light: background, lit, shadowed (band), shadowed.
    fn four_pixel_view(lights: usize) -> ViewReference {
        use umbra_oracle::SampleClass::{Background, Lit, Shadowed};
        let reference = Reference {
            width: 4,
            height: 1,
            class: vec![Background, Lit, Shadowed, Shadowed],
            band: vec![false, false, true, false],
            parts: vec![BandParts::NONE, BandParts::NONE, BandParts::ORIENTATION, BandParts::NONE],
        };
        ViewReference {
            width: 4,
            height: 1,
            lights: (0..lights)
                .map(|light| LightReference { light, reference: reference.clone(), reference_ms: 0.0 })
                .collect(),
            bvh_ms: 0.0,
            world_pos: vec![[0.0; 3]; 4],
            triangle: vec![u32::MAX; 4],
            bvh: Bvh::build(&[], &[]).expect("empty BVH"),
            raster: RasterView::new([0.0; 16]),
            eye: [0.0; 3],
            light_positions: vec![[0.0, 1.0, 0.0, 1.0]; lights],
        }
    }

    #[test]
    fn external_mask_white_is_lit_everything_else_shadowed() {
        let view = four_pixel_view(1);
        let white = [255, 255, 255, 255];
        let black = [0, 0, 0, 255];
        let blue = [0, 0, 128, 255];
        // Background pixel: ignored whatever it holds; lit pixel white; band pixel wrong
        // (tolerated); last pixel black = shadowed, as the reference says.
        let mask = RgbaImage { width: 4, height: 1, pixels: vec![white, white, white, black] };
        let r = verify_external_mask("browser", &mask, &view).expect("same size, one light");
        assert_eq!(r.method, "browser");
        assert_eq!((r.metrics.samples, r.metrics.band_mismatches, r.metrics.mismatches_outside_band), (3, 1, 0));
        assert!(r.passed());
        // Almost white is not lit, and neither is the mask view's background colour: a
        // false shadow on the lit sample, outside the band.
        for not_lit in [[255, 255, 254, 255], blue] {
            let mask = RgbaImage { width: 4, height: 1, pixels: vec![blue, not_lit, black, black] };
            let r = verify_external_mask("browser", &mask, &view).expect("valid");
            assert_eq!(r.metrics.mismatches_outside_band, 1, "{not_lit:?} must read as shadowed");
            assert!(!r.passed());
        }
        // False light outside the band.
        let mask = RgbaImage { width: 4, height: 1, pixels: vec![black, white, black, white] };
        let r = verify_external_mask("browser", &mask, &view).expect("valid");
        assert_eq!(r.metrics.mismatches_outside_band, 1);
        assert_eq!(r.per_light[0].shadowed, vec![true, false, true, false]);
    }

    #[test]
    fn external_mask_of_the_wrong_size_or_several_lights_is_an_error() {
        let mask = RgbaImage::new(3, 1, [255u8; 4]);
        let e = verify_external_mask("m.png", &mask, &four_pixel_view(1)).err().expect("size mismatch");
        assert_eq!(e.to_string(), "method m.png: the mask is 3x1, the view 4x1");
        let mask = RgbaImage::new(4, 1, [255u8; 4]);
        let e = verify_external_mask("m.png", &mask, &four_pixel_view(2)).err().expect("two lights");
        assert_eq!(e.to_string(), "method m.png: a mask holds one light's decision, the view has 2 lights");
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
