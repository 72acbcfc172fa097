//! The torture suite: every case runs through every shadow method the renderer knows (a new
//! method joins every case automatically, through `umbra_gl::method_names()`), and each
//! method that must be exact ([`umbra_verify::must_be_exact`]) must have 0 mismatches outside
//! the one-pixel shadow-boundary band against the CPU ray-traced reference.
//!
//! `UMBRA_TORTURE_METHODS=a,b` runs only those methods (while working on one); unset, every
//! registered method runs.
//!
//! On failure the diff image (false shadow red, false light blue, band grey) and the method's
//! shadow mask are written to target/test-output/torture/ (or $UMBRA_TEST_OUTPUT/torture),
//! labelled with the GL renderer string.
//!
//! Every case also runs on umbra-wgpu (its own depth pass's samples, its own reference, every
//! method of `umbra_wgpu::method_names()`), with the same rule; its numbers go to
//! `results/<case>.wgpu.tsv`. Without a Vulkan/Metal/DX12 adapter that half is skipped with a
//! message (CI installs Mesa's lavapipe, so it runs there).

mod common;

use std::path::PathBuf;
use std::sync::Arc;

use common::scenes_dir;
use umbra_geom::scene::{cuboid, ground_plane, load_scene, tetrahedron, uv_sphere};
use umbra_geom::weld::weld;
use umbra_geom::{Light, Mesh};
use umbra_gl::{
    create_method, method_names, Camera, ContextOptions, FrameParams, GlApi, HeadlessContext, Renderer, RgbaImage,
    SceneGpu,
};
use umbra_oracle::diff_image;
use umbra_verify::{verify_method, view_reference, MethodReport};

/// Small images keep the suite fast on a software rasterizer; every pixel is still a sample.
const W: u32 = 240;
const H: u32 = 180;

struct Case {
    name: &'static str,
    mesh: Mesh,
    camera: Camera,
    lights: Vec<Light>,
    /// Methods excused from exactness in this case, with the reason (documented in
    /// docs/exactness.md). Empty for almost every case.
    excused: &'static [(&'static str, &'static str)],
}

fn case(name: &'static str, mesh: Mesh, eye: [f64; 3], target: [f64; 3], lights: Vec<Light>) -> Case {
    let camera = Camera { eye, target, near: 0.01, ..Camera::default() };
    Case { name, mesh, camera, lights, excused: &[] }
}

fn output_dir() -> PathBuf {
    std::env::var_os("UMBRA_TEST_OUTPUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output"))
        .join("torture")
}

fn slug(s: &str) -> String {
    let s: String = s.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
    s.split('-').filter(|p| !p.is_empty()).collect::<Vec<_>>().join("-")
}

fn write_failure(
    ctx: &HeadlessContext,
    case: &str,
    report: &MethodReport,
    view: &umbra_verify::ViewReference,
) -> PathBuf {
    write_failure_images(case, &slug(&ctx.renderer_string()), report, view)
}

/// Writes the diff image, the method's shadow mask and its image, named
/// `<case>-<method>-<backend>`.
fn write_failure_images(
    case: &str,
    backend: &str,
    report: &MethodReport,
    view: &umbra_verify::ViewReference,
) -> PathBuf {
    let dir = output_dir();
    let _ = std::fs::create_dir_all(&dir);
    let label = format!("{}-{}-{}", case, slug(&report.method), backend);
    let base: Vec<u8> = report.image.pixels.iter().flatten().copied().collect();
    for (lr, res) in view.lights.iter().zip(&report.per_light) {
        if let Ok(rgba) = diff_image(&lr.reference, &res.shadowed, &base) {
            let img = RgbaImage {
                width: view.width,
                height: view.height,
                pixels: rgba.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect(),
            };
            let _ = img.save_png(&dir.join(format!("{label}-light{}-difference.png", lr.light)));
        }
        let mask = RgbaImage {
            width: view.width,
            height: view.height,
            pixels: res.shadowed.iter().map(|&s| if s { [0, 0, 0, 255] } else { [255, 255, 255, 255] }).collect(),
        };
        let _ = mask.save_png(&dir.join(format!("{label}-light{}-actual-mask.png", lr.light)));
    }
    let _ = report.image.save_png(&dir.join(format!("{label}-actual.png")));
    dir
}

/// Runs `case` through every registered method (both z-fail and, where it is meant to work,
/// nothing else: z-pass is a documented failure mode, tested in umbra-gl).
fn run(case: Case) {
    let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"));
    let gl = ctx.gl();
    let welded = Arc::new(weld(&case.mesh));
    assert!(!welded.triangles.is_empty(), "case {} has no triangles", case.name);
    let scene = SceneGpu::upload(gl, welded.clone()).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let params =
        FrameParams { camera: case.camera, width: W, height: H, lights: case.lights.clone(), ..FrameParams::default() };
    let view = view_reference(gl, &mut renderer, &scene, &params).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let mut failures = Vec::new();
    // Every method's numbers, one TSV per case, for scripts/exactness.py's torture table.
    let mut tsv = String::from(
        "method\tsamples\tshadowed_reference\tmismatches\tband_samples\tband_mismatches\tmismatches_outside_band\n",
    );
    let only = std::env::var("UMBRA_TORTURE_METHODS").ok();
    let selected = |name: &str| only.as_deref().is_none_or(|list| list.split(',').any(|m| m.trim() == name));
    // A method that culls its volumes against the receivers runs both ways (docs/exactness.md,
    // "Volumes clamped to their receivers"): culled (the default), then unculled.
    let mut runs: Vec<(&str, bool)> = Vec::new();
    for &name in method_names().iter().filter(|n| selected(n)) {
        runs.push((name, true));
        if create_method(name).expect("registered").culls_volumes() {
            runs.push((name, false));
        }
    }
    for (name, cull) in runs {
        let mut method = create_method(name).expect("registered");
        let params = FrameParams { volume_cull: cull, ..params.clone() };
        let report = verify_method(gl, &mut renderer, &scene, method.as_mut(), &params, &view);
        method.destroy(gl);
        let report = report.unwrap_or_else(|e| panic!("{} / {name} (volume cull {cull}): {e}", case.name));
        let label = if cull { name.to_string() } else { format!("{name}:volume-cull-off") };
        let name = label.as_str();
        let m = report.metrics;
        println!(
            "{:<28} {:<24} samples {:>6} shadowed {:>6} band {:>5} band-mis {:>4} outside-band {:>4}",
            case.name,
            name,
            m.samples,
            m.shadowed_reference,
            m.band_samples,
            m.band_mismatches,
            m.mismatches_outside_band
        );
        tsv += &format!(
            "{name}\t{}\t{}\t{}\t{}\t{}\t{}\n",
            m.samples, m.shadowed_reference, m.mismatches, m.band_samples, m.band_mismatches, m.mismatches_outside_band
        );
        let excused = case.excused.iter().any(|(n, _)| *n == name);
        if !report.passed() && !excused {
            let dir = write_failure(&ctx, case.name, &report, &view);
            failures.push(format!(
                "{name}: {} mismatches outside the band (images in {})",
                m.mismatches_outside_band,
                dir.display()
            ));
        }
    }
    // A case whose reference is (almost) all lit or all shadowed tests nothing: every method,
    // even `none` or "all shadow", would pass it. Demand both classes, 1 % at least.
    let (samples, shadowed) = view.lights.iter().fold((0usize, 0usize), |(n, s), l| {
        let c = &l.reference.class;
        (
            n + c.iter().filter(|&&k| k != umbra_oracle::SampleClass::Background).count(),
            s + c.iter().filter(|&&k| k == umbra_oracle::SampleClass::Shadowed).count(),
        )
    });
    assert!(
        shadowed * 100 >= samples && (samples - shadowed) * 100 >= samples,
        "{}: the reference has {shadowed} shadowed of {samples} samples: a case needs both lit and shadowed samples",
        case.name
    );
    let results = output_dir().join("results");
    let _ = std::fs::create_dir_all(&results);
    let _ = std::fs::write(results.join(format!("{}.tsv", case.name)), tsv);
    run_wgpu(&case, &welded, &mut failures);
    let errors = ctx.take_gl_errors();
    assert!(errors.is_empty(), "{}: GL errors: {errors:?}", case.name);
    assert!(view.lights.iter().all(|l| l.reference.class.len() == (W * H) as usize));
    assert!(failures.is_empty(), "{} ({}): {}", case.name, ctx.renderer_string(), failures.join("; "));
}

/// The case on umbra-wgpu: every wgpu method against the reference of the wgpu frame's own
/// samples; failures are added to `failures`, the numbers written to `<case>.wgpu.tsv`.
fn run_wgpu(case: &Case, welded: &Arc<umbra_geom::WeldedMesh>, failures: &mut Vec<String>) {
    let gpu = match umbra_wgpu::HeadlessGpu::new() {
        Ok(gpu) => gpu,
        Err(e @ umbra_wgpu::WgpuError::NoAdapter { .. }) => {
            eprintln!("SKIPPED (wgpu half of {}): {e}", case.name);
            return;
        }
        Err(e) => panic!("{}: wgpu device: {e}", case.name),
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let scene = umbra_wgpu::SceneGpu::upload(device, welded.clone()).expect("wgpu upload");
    let mut renderer = umbra_wgpu::Renderer::new(device).expect("wgpu renderer");
    let params = umbra_wgpu::FrameParams {
        camera: case.camera,
        width: W,
        height: H,
        lights: case.lights.clone(),
        ..umbra_wgpu::FrameParams::default()
    };
    let view = umbra_verify::wgpu::view_reference(device, queue, &mut renderer, &scene, &params)
        .unwrap_or_else(|e| panic!("{} (wgpu): {e}", case.name));
    let mut tsv = String::from(
        "method\tsamples\tshadowed_reference\tmismatches\tband_samples\tband_mismatches\tmismatches_outside_band\n",
    );
    // As on GL: a method that culls its volumes runs culled (the default), then unculled.
    let mut runs: Vec<(&str, bool)> = Vec::new();
    for &name in umbra_wgpu::method_names() {
        runs.push((name, true));
        if renderer.volumes(device, name).is_ok_and(|v| v.culls_volumes()) {
            runs.push((name, false));
        }
    }
    for (name, cull) in runs {
        let mut volumes = renderer.volumes(device, name).unwrap_or_else(|e| panic!("{} / wgpu {name}: {e}", case.name));
        let params = umbra_wgpu::FrameParams { volume_cull: cull, ..params.clone() };
        let report =
            umbra_verify::wgpu::verify_method(device, queue, &mut renderer, &scene, &mut volumes, &params, &view)
                .unwrap_or_else(|e| panic!("{} / wgpu {name} (volume cull {cull}): {e}", case.name));
        let label = if cull { name.to_string() } else { format!("{name}:volume-cull-off") };
        let name = label.as_str();
        let m = report.metrics;
        println!(
            "{:<28} wgpu {:<19} samples {:>6} shadowed {:>6} band {:>5} band-mis {:>4} outside-band {:>4}",
            case.name,
            name,
            m.samples,
            m.shadowed_reference,
            m.band_samples,
            m.band_mismatches,
            m.mismatches_outside_band
        );
        tsv += &format!(
            "{name}\t{}\t{}\t{}\t{}\t{}\t{}\n",
            m.samples, m.shadowed_reference, m.mismatches, m.band_samples, m.band_mismatches, m.mismatches_outside_band
        );
        let excused = case.excused.iter().any(|(n, _)| *n == name);
        if !report.passed() && !excused {
            let dir = write_failure_images(case.name, &format!("wgpu-{}", slug(&gpu.adapter_line())), &report, &view);
            failures.push(format!(
                "wgpu {name}: {} mismatches outside the band (images in {})",
                m.mismatches_outside_band,
                dir.display()
            ));
        }
    }
    let results = output_dir().join("results");
    let _ = std::fs::write(results.join(format!("{}.wgpu.tsv", case.name)), tsv);
}

// ---------------------------------------------------------------------------------------
// Scenes

fn sphere_over_ground() -> Mesh {
    let mut m = uv_sphere([0.0, 2.0, 0.0], 1.0, 32, 16);
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    m
}

fn soup(tris: &[[[f32; 3]; 3]]) -> Mesh {
    let mut m = Mesh::default();
    for t in tris {
        let b = m.positions.len() as u32;
        m.positions.extend_from_slice(t);
        m.triangles.push([b, b + 1, b + 2]);
    }
    m
}

fn with_ground(mut m: Mesh) -> Mesh {
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    m
}

/// Every triangle with its own three vertices (nothing shared until welding... or ever, for
/// the renderer's input: the caller hands us the soup).
fn unwelded(m: &Mesh) -> Mesh {
    let tris: Vec<[[f32; 3]; 3]> = m.triangles.iter().map(|t| t.map(|i| m.positions[i as usize])).collect();
    soup(&tris)
}

fn scale(mut m: Mesh, s: f32) -> Mesh {
    for p in &mut m.positions {
        *p = p.map(|c| c * s);
    }
    m
}

/// `pages` triangles sharing the spine (−1, 1.5, 0)–(1, 1.5, 0), fanned around it.
fn book(pages: usize) -> Mesh {
    let mut m = Mesh { positions: vec![[-1.0, 1.5, 0.0], [1.0, 1.5, 0.0]], ..Default::default() };
    for k in 0..pages {
        let a = std::f32::consts::PI * (0.1 + 0.8 * k as f32 / pages.max(2) as f32 - 0.5) + std::f32::consts::PI;
        m.positions.push([0.3 * (k as f32 / pages as f32 - 0.5), 1.5 + a.sin(), a.cos()]);
        let o = 2 + k as u32;
        m.triangles.push(if k % 2 == 0 { [0, 1, o] } else { [1, 0, o] });
    }
    m
}

const ABOVE: Light = [0.3, 6.0, 0.2, 1.0];
const EYE: [f64; 3] = [5.0, 4.0, 6.0];
const ORIGIN: [f64; 3] = [0.0, 0.5, 0.0];

// ---------------------------------------------------------------------------------------
// Camera and light placement

#[test]
fn torture_camera_inside_shadow_volume() {
    // Eye on the ground under the sphere (in its umbra), looking along the ground.
    run(case("camera-inside-volume", sphere_over_ground(), [0.1, 0.3, 0.1], [4.0, 0.0, 3.0], vec![ABOVE]));
}

#[test]
fn torture_near_plane_cuts_volume() {
    // Eye on the side boundary of the sphere's shadow volume: the near plane straddles it.
    let mut c = case(
        "near-plane-cuts-volume",
        sphere_over_ground(),
        [1.07, 1.0, 0.0],
        [-2.0, 0.0, 0.5],
        vec![[0.0, 6.0, 0.0, 1.0]],
    );
    c.camera.near = 0.2;
    run(c);
}

#[test]
fn torture_near_plane_cuts_caster() {
    // The eye 0.005 outside a wall (near plane 0.01: the scene pass cuts the wall away), looking
    // through it at a room lit from inside with a square occluder. Light caps are pushed to the
    // far plane (003 Eq. 6) on the assumption that their caster hides what lies behind it; here
    // it does not, so the wall's cap must be clipped at the near plane too
    // (methods/shared/depth.glsl). Found on Crytek Sponza (torture pose 2, eye 0.0099 from a
    // wall): every sample seen through the wall was shadowed by every method.
    let mut m = soup(&[
        [[5.0, 0.0, -10.0], [5.0, 6.0, -10.0], [5.0, 6.0, 10.0]],
        [[5.0, 0.0, -10.0], [5.0, 6.0, 10.0], [5.0, 0.0, 10.0]],
        [[-1.0, 2.0, -1.0], [1.0, 2.0, -1.0], [1.0, 2.0, 1.0]],
        [[-1.0, 2.0, -1.0], [1.0, 2.0, 1.0], [-1.0, 2.0, 1.0]],
    ]);
    m = with_ground(m);
    run(case("near-plane-cuts-caster", m, [5.005, 2.0, 0.3], [-5.0, 0.0, 0.0], vec![[0.0, 3.0, 0.0, 1.0]]));
}

#[test]
fn torture_light_close_to_surface() {
    let mut m = with_ground(cuboid([0.0, 0.3, 0.0], [0.3, 0.3, 0.3]));
    m.append(&tetrahedron([1.5, 0.5, 1.0], 0.4));
    run(case("light-close-to-surface", m, EYE, ORIGIN, vec![[0.9, 1e-3, 0.7, 1.0]]));
}

#[test]
fn torture_light_inside_closed_mesh() {
    // A closed room (box seen from inside) with an occluder; light and camera inside.
    let mut m = cuboid([0.0, 2.0, 0.0], [4.0, 2.0, 4.0]);
    m.append(&tetrahedron([0.5, 1.0, 0.3], 0.6));
    run(case("light-inside-closed-mesh", m, [-3.0, 3.0, 3.2], [0.5, 0.5, 0.0], vec![[1.0, 3.0, -0.5, 1.0]]));
}

#[test]
fn torture_directional_light() {
    let mut m = sphere_over_ground();
    m.append(&cuboid([2.5, 0.5, -1.0], [0.5, 0.5, 0.5]));
    run(case("directional-light", m, EYE, ORIGIN, vec![[0.4, 1.0, 0.3, 0.0]]));
}

#[test]
fn torture_two_lights_point_and_directional() {
    run(case("two-lights", sphere_over_ground(), EYE, ORIGIN, vec![ABOVE, [-0.5, 1.0, 0.2, 0.0]]));
}

// ---------------------------------------------------------------------------------------
// Volumes clamped to their receivers (cpu-silhouette's receiver map; docs/exactness.md,
// "Volumes clamped to their receivers")

#[test]
fn torture_clamp_receiver_at_the_clamp_distance_and_one_an_ulp_beyond() {
    // Two floor tiles under one caster: the left one at y = 1, the right one an ulp lower,
    // so the farthest receiver of the caster's cone (the one its clamp is made from) and a
    // receiver an ulp beyond it both lie in its shadow, side by side.
    let below = f32::from_bits(1.0f32.to_bits() - 1);
    let tile = |x0: f32, x1: f32, y: f32| {
        [[[x0, y, -3.0], [x1, y, -3.0], [x1, y, 3.0]], [[x0, y, -3.0], [x1, y, 3.0], [x0, y, 3.0]]]
    };
    let mut tris: Vec<[[f32; 3]; 3]> = tile(-3.0, 0.0, 1.0).into_iter().chain(tile(0.0, 3.0, below)).collect();
    tris.push([[-1.0, 2.5, -1.0], [1.0, 2.5, -0.8], [0.0, 2.5, 1.2]]);
    run(case(
        "clamp-receiver-an-ulp-beyond",
        soup(&tris),
        [2.0, 5.0, 4.0],
        [0.0, 1.0, 0.0],
        vec![[0.1, 6.0, 0.2, 1.0]],
    ));
}

#[test]
fn torture_clamp_light_inside_with_receivers_on_every_side() {
    // A closed room lit from its middle, with casters on all six sides of the light: every
    // cube face of the receiver map holds receivers, and cones cross faces.
    let mut m = cuboid([0.0, 0.0, 0.0], [4.0, 4.0, 4.0]);
    for c in [[1.5, 0.0, 0.0], [-1.5, 0.2, 0.0], [0.0, 1.5, 0.3], [0.2, -1.5, 0.0], [0.0, 0.0, 1.5], [0.3, 0.0, -1.5]] {
        m.append(&tetrahedron(c, 0.5));
    }
    m.append(&cuboid([0.6, 0.6, 0.6], [0.3, 0.1, 0.3]));
    run(case("clamp-light-inside", m, [-3.5, 3.0, 3.4], [0.5, -1.0, -1.0], vec![[0.05, 0.1, -0.05, 1.0]]));
}

#[test]
fn torture_clamp_receiver_seen_through_a_narrow_gap() {
    // A wall with a slit 0.05 wide between the eye and the floor behind it: the only visible
    // receivers of the caster's shadow are the few seen through the slit.
    // The wall is lower than the light, so the floor behind it is lit but for the caster's
    // shadow, and the floor in front of it gives the case lit samples.
    let mut m = with_ground(cuboid([0.0, 0.8, 3.0], [0.3, 0.1, 0.3]));
    m.append(&cuboid([-2.525, 0.75, 0.0], [2.5, 0.75, 0.05]));
    m.append(&cuboid([2.525, 0.75, 0.0], [2.5, 0.75, 0.05]));
    run(case("clamp-narrow-gap", m, [0.0, 1.0, -4.0], [0.0, 0.3, 3.0], vec![[0.2, 6.0, 3.1, 1.0]]));
}

#[test]
fn torture_clamp_eye_inside_a_clamped_volume() {
    // The eye under a plate, between it and the floor its shadow is clamped to, looking out
    // of the shadow along the floor.
    let mut m = with_ground(cuboid([0.0, 1.2, 0.0], [1.5, 0.05, 1.5]));
    m.append(&tetrahedron([3.0, 0.5, 1.0], 0.5));
    run(case("clamp-eye-inside-volume", m, [0.1, 0.4, -0.2], [4.0, 0.0, 2.0], vec![[0.2, 6.0, 0.1, 1.0]]));
}

#[test]
fn torture_clamp_directional_light_over_a_very_deep_scene() {
    // A corridor 2,000 units deep, posts along it, a low directional light along its length:
    // the depths along the light span the whole corridor.
    let mut m = Mesh::default();
    m.append(&soup(&[
        [[-5.0, 0.0, 0.0], [5.0, 0.0, 0.0], [5.0, 0.0, -2000.0]],
        [[-5.0, 0.0, 0.0], [5.0, 0.0, -2000.0], [-5.0, 0.0, -2000.0]],
    ]));
    for k in 0..20 {
        let z = -5.0 - 15.0 * k as f32 * (1.0 + k as f32);
        m.append(&cuboid([if k % 2 == 0 { -2.0 } else { 2.0 }, 1.5, z], [0.8, 1.5, 0.8]));
    }
    run(case("clamp-deep-directional", m, [0.0, 6.0, 6.0], [0.0, 0.0, -30.0], vec![[0.4, 0.3, 1.0, 0.0]]));
}

/// Every method (each object reused across frames, as an application does) stays exact when
/// the caster moves between frames and then the light does: nothing of the previous frame's
/// receiver map or clamp survives into the next.
#[test]
fn torture_clamp_caster_moves_between_frames() {
    let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"));
    let gl = ctx.gl();
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let frames: Vec<(Mesh, Light)> = vec![
        (with_ground(cuboid([0.0, 1.5, 0.0], [0.5, 0.5, 0.5])), ABOVE),
        (with_ground(cuboid([1.5, 1.0, 0.5], [0.5, 0.5, 0.5])), ABOVE),
        (with_ground(cuboid([1.5, 1.0, 0.5], [0.5, 0.5, 0.5])), [-2.0, 5.0, 1.0, 1.0]),
    ];
    let scenes: Vec<SceneGpu> =
        frames.iter().map(|(m, _)| SceneGpu::upload(gl, Arc::new(weld(m))).expect("upload")).collect();
    let mut failures = Vec::new();
    let only = std::env::var("UMBRA_TORTURE_METHODS").ok();
    let selected = |name: &str| only.as_deref().is_none_or(|list| list.split(',').any(|m| m.trim() == name));
    for &name in method_names().iter().filter(|n| selected(n)) {
        let mut method = create_method(name).expect("registered");
        for (k, ((_, light), scene)) in frames.iter().zip(&scenes).enumerate() {
            let camera = Camera { eye: EYE, target: ORIGIN, near: 0.01, ..Camera::default() };
            let params = FrameParams { camera, width: W, height: H, lights: vec![*light], ..FrameParams::default() };
            let view = view_reference(gl, &mut renderer, scene, &params).expect("reference");
            let report = verify_method(gl, &mut renderer, scene, method.as_mut(), &params, &view)
                .unwrap_or_else(|e| panic!("{name}, frame {k}: {e}"));
            if !report.passed() {
                failures
                    .push(format!("{name}, frame {k}: {} outside the band", report.metrics.mismatches_outside_band));
            }
        }
        method.destroy(gl);
    }
    let errors = ctx.take_gl_errors();
    assert!(errors.is_empty(), "GL errors: {errors:?}");
    assert!(failures.is_empty(), "{}", failures.join("; "));
}

// ---------------------------------------------------------------------------------------
// Open geometry

#[test]
fn torture_single_triangle() {
    let m = with_ground(soup(&[[[-1.0, 1.5, -1.0], [1.0, 1.5, -0.5], [0.0, 1.5, 1.2]]]));
    run(case("single-triangle", m, EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_single_quad() {
    let m = with_ground(soup(&[
        [[-1.0, 1.5, -1.0], [1.0, 1.5, -1.0], [1.0, 1.7, 1.0]],
        [[-1.0, 1.5, -1.0], [1.0, 1.7, 1.0], [-1.0, 1.7, 1.0]],
    ]));
    run(case("single-quad", m, EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_open_box() {
    // A cube with its top face removed, light shining in from above.
    let mut b = cuboid([0.0, 1.0, 0.0], [1.0, 1.0, 1.0]);
    let w = weld(&b);
    let top: Vec<usize> =
        (0..w.triangles.len()).filter(|&t| w.triangles[t].iter().all(|&v| w.positions[v as usize][1] > 1.5)).collect();
    assert_eq!(top.len(), 2, "the cube's top face is two triangles");
    b = Mesh {
        positions: w.positions.clone(),
        triangles: w.triangles.iter().enumerate().filter(|(i, _)| !top.contains(i)).map(|(_, t)| *t).collect(),
        normals: None,
    };
    run(case("open-box", with_ground(b), [4.0, 5.0, 3.0], [0.0, 0.5, 0.0], vec![[0.6, 5.0, 0.4, 1.0]]));
}

// ---------------------------------------------------------------------------------------
// Non-manifold edges

#[test]
fn torture_three_and_four_fins() {
    let mut m = Mesh::default();
    for (fins, x) in [(3usize, -1.5f32), (4, 1.5)] {
        let base = m.positions.len() as u32;
        m.positions.push([x, 1.0, -1.0]);
        m.positions.push([x, 1.0, 1.0]);
        for k in 0..fins {
            let a = k as f32 * std::f32::consts::TAU / fins as f32 + 0.3;
            m.positions.push([x + 0.8 * a.cos(), 1.0 + 0.8 * a.sin(), 0.0]);
            m.triangles.push([base, base + 1, base + 2 + k as u32]);
        }
    }
    run(case("three-and-four-fins", with_ground(m), EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_book_of_40_pages() {
    // Multiplicity far beyond 32 (the paper's tessellation limit) on one spine edge.
    run(case("book-40-pages", with_ground(book(40)), [3.0, 4.0, 5.0], [0.0, 1.0, 0.0], vec![[0.2, 6.0, 0.3, 1.0]]));
}

// ---------------------------------------------------------------------------------------
// Degenerate and duplicated input

#[test]
fn torture_same_triangle_twice_opposite_windings() {
    let t = [[-1.0, 1.5, -1.0], [1.0, 1.5, -0.5], [0.0, 1.5, 1.2]];
    let m = with_ground(soup(&[t, [t[0], t[2], t[1]]]));
    run(case("same-triangle-twice", m, EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_unwelded_mesh() {
    let mut m = unwelded(&uv_sphere([0.0, 2.0, 0.0], 1.0, 24, 12));
    m.append(&unwelded(&ground_plane([0.0, 0.0, 0.0], 10.0)));
    run(case("unwelded-mesh", m, EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_zero_area_triangles() {
    // A quad with zero-area slivers along its edges and diagonal (collinear distinct vertices).
    let a = [-1.0, 1.5, -1.0];
    let b = [1.0, 1.5, -1.0];
    let c = [1.0, 1.5, 1.0];
    let d = [-1.0, 1.5, 1.0];
    let mid = |p: [f32; 3], q: [f32; 3]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])];
    let m = with_ground(soup(&[[a, b, c], [a, c, d], [a, mid(a, c), c], [a, mid(a, b), b], [b, mid(b, c), c]]));
    run(case("zero-area-triangles", m, EYE, ORIGIN, vec![ABOVE]));
}

#[test]
fn torture_triangles_edge_on_to_light() {
    // Vertical walls whose planes contain the point light.
    let l = [0.0f32, 5.0, 0.0];
    let wall = |x: f32| [[x, 0.5, -1.0], [x, 2.5, -1.0], [x, 0.5, 1.0]];
    let mut tris = vec![wall(0.0)];
    tris.push([[l[0], 1.0, 0.5], [1.0, 1.0, 0.5], [l[0], 3.0, 0.5]]);
    tris.push([[-1.0, 1.5, -1.5], [1.0, 1.5, -1.5], [0.0, 1.5, -0.5]]);
    run(case("edge-on-to-light", with_ground(soup(&tris)), EYE, ORIGIN, vec![[l[0], l[1], l[2], 1.0]]));
}

// ---------------------------------------------------------------------------------------
// Extreme coordinates

#[test]
fn torture_huge_coordinates() {
    let s = 1e5f32;
    let m = scale(sphere_over_ground(), s);
    let e = EYE.map(|c| c * s as f64);
    let t = ORIGIN.map(|c| c * s as f64);
    let mut c = case("huge-coordinates", m, e, t, vec![[ABOVE[0] * s, ABOVE[1] * s, ABOVE[2] * s, 1.0]]);
    c.camera.near = 0.01 * s as f64;
    run(c);
}

#[test]
fn torture_tiny_coordinates() {
    let s = 1e-3f32;
    let m = scale(sphere_over_ground(), s);
    let e = EYE.map(|c| c * s as f64);
    let t = ORIGIN.map(|c| c * s as f64);
    let mut c = case("tiny-coordinates", m, e, t, vec![[ABOVE[0] * s, ABOVE[1] * s, ABOVE[2] * s, 1.0]]);
    c.camera.near = 0.01 * s as f64;
    run(c);
}

// ---------------------------------------------------------------------------------------
// Real and procedural scenes

#[test]
fn torture_spheres_10_100k() {
    let m = load_scene("spheres:10:100000").expect("procedural scene");
    run(case("spheres-10-100k", m, [-20.0, 14.0, 22.0], [0.0, 1.0, 0.0], vec![[3.0, 12.0, 2.0, 1.0]]));
}

/// Three camera and light poses inside the scene's bounds, as fractions of the box.
fn shared_scene(file: &str) {
    let Some(dir) = scenes_dir() else { return };
    let path = dir.join(file);
    if !path.is_file() {
        eprintln!("SKIPPED: {} not found", path.display());
        return;
    }
    let mesh = umbra_geom::load::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
    let b = mesh.bounds().expect("non-empty scene");
    let at = |f: [f64; 3]| [0, 1, 2].map(|k| b.min[k] as f64 + f[k] * (b.max[k] - b.min[k]) as f64);
    let poses = [
        // (eye, target, light) as fractions of the bounding box
        ([0.3, 0.45, 0.5], [0.7, 0.3, 0.5], [0.61, 0.7, 0.57]),
        // (The light of pose 1 stays below 0.8: there Sibenik's light sits in the vault and
        // every sample is shadowed, a case that tests nothing; the check in `run` fails such
        // a pose.)
        ([0.5, 0.3, 0.3], [0.5, 0.1, 0.7], [0.35, 0.6, 0.45]),
        ([0.75, 0.55, 0.5], [0.3, 0.2, 0.4], [0.5, 0.5, 0.5]),
    ];
    for (i, (e, t, l)) in poses.into_iter().enumerate() {
        // Pose 2's eye at z 0.5 (at z 0.6 it would be inside a wall on Crytek Sponza: every
        // sample a back face, all shadowed) is 0.0099 outside a wall the near plane cuts (the
        // near-plane cut of light caps, also pinned by torture_near_plane_cuts_caster), and on
        // Conference it sees a floor sample touching a
        // table's side-face edge within a depth step (the *touching* band class).
        let light = at(l);
        let name: &'static str = Box::leak(format!("{}-pose{i}", file.trim_end_matches(".obj.gz")).into_boxed_str());
        let mut c =
            case(name, mesh.clone(), at(e), at(t), vec![[light[0] as f32, light[1] as f32, light[2] as f32, 1.0]]);
        c.camera.near = 1e-3 * b.diagonal() as f64;
        run(c);
    }
}

#[test]
fn torture_crytek_sponza() {
    shared_scene("crytek-sponza.obj.gz");
}

#[test]
fn torture_conference() {
    shared_scene("conference.obj.gz");
}

#[test]
fn torture_sibenik() {
    shared_scene("sibenik.obj.gz");
}
