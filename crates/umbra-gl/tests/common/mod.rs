//! Shared helpers of the GL integration tests: contexts, the sphere-over-ground scene, pixel
//! checks that write `actual` and `difference` PNGs (labelled with the GL renderer string)
//! under target/test-output/ (or $UMBRA_TEST_OUTPUT) when they fail.

#![allow(dead_code)]

pub mod child;

use std::path::PathBuf;
use std::sync::Arc;

use umbra_geom::scene::{ground_plane, uv_sphere};
use umbra_geom::{weld::weld, Light, Mesh, WeldedMesh};
use umbra_gl::{
    create_method, Camera, CaptureFlags, ContextOptions, FrameImages, FrameParams, GlApi, HeadlessContext,
    LightCapture, Renderer, RgbaImage, SceneGpu, ShadowMethod, StencilImage,
};

pub const SPHERE_CENTER: [f64; 3] = [0.0, 2.0, 0.0];
pub const SPHERE_RADIUS: f64 = 1.0;
pub const POINT_LIGHT: [f32; 4] = [0.0, 6.0, 0.0, 1.0];

/// A debug GL 4.5 core context (errors recorded) — the tests need a GL; failing to get one
/// is a test failure with the context error's install hint.
pub fn context() -> HeadlessContext {
    match HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true }) {
        Ok(c) => c,
        Err(e) => panic!("no headless GL 4.5 context: {e}"),
    }
}

/// UV sphere (radius 1 at (0, 2, 0), 48 x 24) above a 20 x 20 ground plane at y = 0.
/// The ground's two triangles come last in the welded mesh.
pub fn sphere_over_ground() -> Arc<WeldedMesh> {
    let c = SPHERE_CENTER.map(|v| v as f32);
    let mut mesh: Mesh = uv_sphere(c, SPHERE_RADIUS as f32, 48, 24);
    mesh.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&mesh))
}

pub fn params(camera: Camera, lights: Vec<[f32; 4]>, width: u32, height: u32) -> FrameParams {
    FrameParams {
        camera,
        width,
        height,
        lights,
        capture: CaptureFlags {
            world_pos: true,
            triangle_id: true,
            stencil: LightCapture::AllLights,
            lit_mask: LightCapture::AllLights,
        },
        ..FrameParams::default()
    }
}

/// Renders one frame with the named method on a fresh renderer.
pub fn render_once(ctx: &HeadlessContext, mesh: &Arc<WeldedMesh>, method: &str, p: &FrameParams) -> FrameImages {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut m = create_method(method).expect("registered method");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let out = r.render(gl, &scene, m.as_mut(), p, None).unwrap_or_else(|e| panic!("render with {method}: {e}"));
    m.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    out
}

pub fn output_dir() -> PathBuf {
    std::env::var_os("UMBRA_TEST_OUTPUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output"))
}

/// File-name-safe GL renderer string, e.g. "llvmpipe-llvm-15-0-6-256-bits".
pub fn renderer_slug(ctx: &HeadlessContext) -> String {
    let s: String = ctx
        .renderer_string()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' })
        .collect();
    s.split('-').filter(|p| !p.is_empty()).collect::<Vec<_>>().join("-")
}

/// Writes `<test>-<renderer>-actual.png` and `<test>-<renderer>-difference.png`, returns
/// the directory for the panic message.
pub fn write_failure_images(ctx: &HeadlessContext, test: &str, actual: &RgbaImage, difference: &RgbaImage) -> String {
    let dir = output_dir();
    let slug = renderer_slug(ctx);
    let a = dir.join(format!("{test}-{slug}-actual.png"));
    let d = dir.join(format!("{test}-{slug}-difference.png"));
    let mut note = format!("images: {} and {}", a.display(), d.display());
    if let Err(e) = actual.save_png(&a).and_then(|()| difference.save_png(&d)) {
        note = format!("(could not write failure images: {e})");
    }
    note
}

/// Compares two images; on any difference writes actual (= `b`) and difference and panics.
pub fn assert_same_image(ctx: &HeadlessContext, test: &str, a: &RgbaImage, b: &RgbaImage) {
    let (diff, n) = a.difference(b).unwrap_or_else(|| panic!("{test}: image sizes differ"));
    if n != 0 {
        let note = write_failure_images(ctx, test, b, &diff);
        panic!("{test}: {n} pixels differ on {}; {note}", ctx.renderer_string());
    }
}

/// Collects pixel expectations; `finish` writes the failure images (difference: the checked
/// pixels, green if right, red if wrong, over a dimmed copy) and panics if any failed.
pub struct PixelChecks<'a> {
    pub ctx: &'a HeadlessContext,
    pub test: &'static str,
    pub image: &'a RgbaImage,
    failures: Vec<String>,
    marks: Vec<(u32, u32, bool)>,
}

impl<'a> PixelChecks<'a> {
    pub fn new(ctx: &'a HeadlessContext, test: &'static str, image: &'a RgbaImage) -> Self {
        Self { ctx, test, image, failures: Vec::new(), marks: Vec::new() }
    }

    pub fn check(&mut self, x: u32, y: u32, ok: bool, what: impl FnOnce() -> String) {
        self.marks.push((x, y, ok));
        if !ok {
            self.failures.push(format!("pixel ({x}, {y}): {}", what()));
        }
    }

    /// Number of failed checks so far.
    pub fn failures(&self) -> usize {
        self.failures.len()
    }

    pub fn finish(self) {
        if self.failures.is_empty() {
            return;
        }
        let mut diff = self.image.clone();
        for p in &mut diff.pixels {
            *p = [p[0] / 3, p[1] / 3, p[2] / 3, 255];
        }
        // Passed checks: one green pixel; failed ones: a red 5x5 square drawn on top.
        let mut put = |x: i64, y: i64, c: [u8; 4]| {
            if x >= 0 && y >= 0 && (x as u32) < diff.width && (y as u32) < diff.height {
                diff.pixels[y as usize * diff.width as usize + x as usize] = c;
            }
        };
        for &(x, y, ok) in &self.marks {
            if ok {
                put(x as i64, y as i64, [0, 160, 0, 255]);
            }
        }
        for &(x, y, ok) in &self.marks {
            if !ok {
                for dy in -2i64..=2 {
                    for dx in -2i64..=2 {
                        put(x as i64 + dx, y as i64 + dy, [255, 0, 0, 255]);
                    }
                }
            }
        }
        let note = write_failure_images(self.ctx, self.test, self.image, &diff);
        panic!(
            "{}: {} check(s) failed on {}:\n  {}\n{note}",
            self.test,
            self.failures.len(),
            self.ctx.renderer_string(),
            self.failures.join("\n  ")
        );
    }
}

/// Integer pixel containing the projection of `world`.
pub fn pixel_of(camera: &Camera, world: [f64; 3], w: u32, h: u32) -> (u32, u32) {
    let p = camera.project(world, w, h).expect("point in front of the camera");
    assert!(p[0] >= 0.0 && p[1] >= 0.0 && p[0] < w as f64 && p[1] < h as f64, "{world:?} projects outside: {p:?}");
    (p[0] as u32, p[1] as u32)
}

/// Expected colour channel (0..1) of a lit two-sided Blinn-Phong surface point, mirroring
/// lighting.frag.glsl in f64 (ambient + one light).
pub fn expected_lit(p: &FrameParams, world: [f64; 3], normal: [f64; 3], light: [f32; 4]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let norm = |a: [f64; 3]| {
        let l = dot(a, a).sqrt();
        a.map(|x| x / l)
    };
    let l4 = light.map(f64::from);
    let v = norm(sub(p.camera.eye, world));
    let mut n = normal;
    if dot(n, v) < 0.0 {
        n = n.map(|x| -x);
    }
    let l = norm(sub([l4[0], l4[1], l4[2]], world.map(|x| x * l4[3])));
    let ambient = f64::from(p.albedo[0] * p.ambient);
    let ndl = dot(n, l);
    if ndl <= 0.0 {
        return ambient;
    }
    let h = norm([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let spec = dot(n, h).max(0.0).powf(f64::from(p.shininess));
    ambient + f64::from(p.light_color[0]) * (f64::from(p.albedo[0]) * ndl + f64::from(p.specular) * spec)
}

/// Whether the side of triangle `id` that the camera at `eye` sees faces `light`, decided in
/// f64 from the f32 vertices; `None` when the camera or the light is within `1e-3` (cosine)
/// of the triangle's plane, where the GPU's gl_FrontFacing / f32 shading may decide either
/// way.
pub fn seen_side_faces_light(
    mesh: &WeldedMesh,
    id: u32,
    world: [f64; 3],
    eye: [f64; 3],
    light: [f32; 4],
) -> Option<bool> {
    let t = mesh.triangles[id as usize];
    let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
    let sub = |p: [f64; 3], q: [f64; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let (u, v) = (sub(b, a), sub(c, a));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let l4 = light.map(f64::from);
    let to_light = [l4[0] - world[0] * l4[3], l4[1] - world[1] * l4[3], l4[2] - world[2] * l4[3]];
    let to_eye = sub(eye, a);
    let cos = |d: [f64; 3]| dot(n, d) / (dot(n, n) * dot(d, d)).sqrt();
    let (ce, cl) = (cos(to_eye), cos(to_light));
    if !(ce.abs() >= 1e-3 && cl.abs() >= 1e-3) {
        return None;
    }
    Some((ce > 0.0) == (cl > 0.0))
}

/// Expected 8-bit value of an unshadowed-by-light (ambient only) surface.
pub fn expected_ambient_u8(p: &FrameParams) -> u8 {
    (f64::from(p.albedo[0] * p.ambient) * 255.0).round() as u8
}

pub fn to_u8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The method names every generic test iterates over (all registered ones).
pub fn shadow_methods() -> Vec<&'static str> {
    umbra_gl::method_names().iter().copied().filter(|&m| m != "none").collect()
}

/// The shadow methods whose shadows are right where the volumes of several triangles overlap
/// (under the sphere, two of its triangles shadow the ground): all but paper 002's
/// `all-edges-invert`, whose INVERT parity cancels there by design (documented; see
/// umbra_verify::must_be_exact).
pub fn overlap_exact_methods() -> Vec<&'static str> {
    shadow_methods().into_iter().filter(|&m| m != "all-edges-invert").collect()
}

/// The shadow methods that count in the stencil (Classification::StencilZero, and volumes
/// filled: not hier-triangle, which writes a 0/1 decision): the ones whose stencil values (2
/// under the sphere, z-pass wrap-around, ...) tests may check.
pub fn counting_methods() -> Vec<&'static str> {
    shadow_methods()
        .into_iter()
        .filter(|m| {
            create_method(m)
                .is_ok_and(|c| c.classification() == umbra_gl::Classification::StencilZero && c.fills_volumes())
        })
        .collect()
}

pub fn default_camera() -> Camera {
    Camera {
        eye: [0.0, 5.0, 8.0],
        target: [0.0, 0.5, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 0.1,
        ..Camera::default()
    }
}

/// The stencil counts one light leaves after `method`'s volume pass (sample for sample).
pub fn stencil_of(
    ctx: &HeadlessContext,
    scene: &SceneGpu,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
) -> StencilImage {
    let gl = ctx.gl();
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let s = r.render_stencil(gl, scene, method, p, 0).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
    r.destroy(gl);
    s
}

/// A 200x150 frame with one light, counted with z-fail or z-pass as asked (not auto z-pass:
/// auto_zpass.rs tests that choice).
pub fn volume_params(eye: [f64; 3], target: [f64; 3], light: Light, zpass: bool) -> FrameParams {
    FrameParams {
        camera: Camera { eye, target, near: 0.01, ..Camera::default() },
        width: 200,
        height: 150,
        lights: vec![light],
        zpass,
        auto_zpass: false,
        ..FrameParams::default()
    }
}

// The compute methods' tests (hier-triangle, hier-silhouette, ray-bvh): one small frame of the
// sphere over the ground, and each light's stencil after the method's volume pass.

/// Width and height of the compute methods' test frame.
pub const METHOD_W: u32 = 160;
pub const METHOD_H: u32 = 120;

/// The compute methods' test camera: the sphere over the ground from above and aside.
pub fn method_camera() -> Camera {
    Camera { eye: [5.0, 6.0, 7.0], target: [0.0, 0.5, 0.0], near: 0.05, ..Camera::default() }
}

/// The compute methods' test frame with `lights`.
pub fn method_frame(lights: Vec<[f32; 4]>) -> FrameParams {
    FrameParams { camera: method_camera(), width: METHOD_W, height: METHOD_H, lights, ..FrameParams::default() }
}

/// Per light, the stencil of `method` (0 = lit) after its volume pass; the method is destroyed
/// and no GL error may be left.
pub fn volume_stencils(
    ctx: &HeadlessContext,
    mesh: &Arc<WeldedMesh>,
    method: &mut dyn ShadowMethod,
    p: &FrameParams,
) -> Vec<StencilImage> {
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, mesh.clone()).expect("upload");
    let mut r = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let mut p = p.clone();
    p.capture.stencil = LightCapture::AllLights;
    let out = r.render(gl, &scene, method, &p, None).unwrap_or_else(|e| panic!("{}: {e}", method.name()));
    method.destroy(gl);
    r.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "{}: GL errors", method.name());
    out.stencil.into_iter().map(|s| s.image).collect()
}

/// A stencil image as "shadowed" per pixel (nonzero).
pub fn stencil_shadowed(s: &StencilImage) -> Vec<bool> {
    s.pixels.iter().map(|&v| v != 0).collect()
}
