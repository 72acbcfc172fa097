//! Shared helpers of umbra-verify's integration tests: the GL context, one exactness case
//! (a method against the ray-traced reference: 0 samples outside the band, both classes
//! present), the cases every compute method must get right (a light inside a closed room,
//! samples exactly on face planes), and the shared scenes with the CLI's default interior view.

// Reason: each test crate uses a part of these helpers.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::Arc;

use umbra_geom::scene::{cuboid, ground_plane};
use umbra_geom::weld::weld;
use umbra_geom::{Light, Mesh};
use umbra_gl::{Camera, ContextOptions, FrameParams, GlApi, HeadlessContext, Renderer, SceneGpu, ShadowMethod};
use umbra_oracle::{Metrics, SampleClass};
use umbra_verify::{verify_method, view_reference, ViewReference};

/// A debug GL 4.5 core context; no context is a test failure.
/// A headless wgpu device, or `None` (with a SKIPPED message) where no adapter exists; any
/// other failure panics.
pub fn wgpu_gpu() -> Option<umbra_wgpu::HeadlessGpu> {
    match umbra_wgpu::HeadlessGpu::new() {
        Ok(g) => Some(g),
        Err(e @ umbra_wgpu::WgpuError::NoAdapter { .. }) => {
            eprintln!("SKIPPED: {e}");
            None
        }
        Err(e) => panic!("wgpu device: {e}"),
    }
}

pub fn context() -> HeadlessContext {
    HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"))
}

/// Prints a case's band metrics on one line.
pub fn print_metrics(name: &str, m: &Metrics) {
    println!(
        "{name}: samples {} shadowed {} band {} band mismatches {} outside the band {}",
        m.samples, m.shadowed_reference, m.band_samples, m.band_mismatches, m.mismatches_outside_band
    );
}

/// The reference's samples and shadowed samples over every light of `view`, asserting that both
/// classes hold 1 % at least (else the case tests nothing). Returns (samples, shadowed).
pub fn both_classes(name: &str, view: &ViewReference) -> (usize, usize) {
    let (samples, shadowed) = view.lights.iter().fold((0, 0), |(n, s), l| {
        let c = &l.reference.class;
        (
            n + c.iter().filter(|&&k| k != SampleClass::Background).count(),
            s + c.iter().filter(|&&k| k == SampleClass::Shadowed).count(),
        )
    });
    assert!(
        shadowed * 100 >= samples && (samples - shadowed) * 100 >= samples,
        "{name}: {shadowed} of {samples} samples shadowed: the case tests nothing"
    );
    (samples, shadowed)
}

/// Verifies `method` on `mesh` seen by `camera` with `lights` at `w x h`: 0 samples outside the
/// band, both classes present, no GL error. Destroys the method. Returns (samples, shadowed).
pub fn verify_exact(
    name: &str,
    mesh: &Mesh,
    camera: Camera,
    lights: Vec<Light>,
    (w, h): (u32, u32),
    method: &mut dyn ShadowMethod,
) -> (usize, usize) {
    let ctx = context();
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, Arc::new(weld(mesh))).expect("upload");
    let mut renderer = Renderer::new(gl).expect("renderer").with_error_log(ctx.error_log().cloned());
    let params = FrameParams { camera, width: w, height: h, lights, ..FrameParams::default() };
    let view = view_reference(gl, &mut renderer, &scene, &params).unwrap_or_else(|e| panic!("{name}: {e}"));
    let report =
        verify_method(gl, &mut renderer, &scene, method, &params, &view).unwrap_or_else(|e| panic!("{name}: {e}"));
    let m = report.metrics;
    print_metrics(name, &m);
    let counts = both_classes(name, &view);
    assert_eq!(m.mismatches_outside_band, 0, "{name}: samples outside the band");
    method.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    assert!(ctx.take_gl_errors().is_empty(), "{name}: GL errors");
    counts
}

/// Rotation by `angle` radians about the unit axis `k` (Rodrigues), in f64.
pub fn rotate(p: [f64; 3], k: [f64; 3], angle: f64) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let kxp = [k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2], k[0] * p[1] - k[1] * p[0]];
    let kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
    [0, 1, 2].map(|i| p[i] * c + kxp[i] * s + k[i] * kp * (1.0 - c))
}

/// The shared scenes' folder (`UMBRA_SCENES`, default ../shared/scenes beside the repository),
/// or `None` with a SKIPPED message when it is absent.
pub fn scenes_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("SKIPPED: shared scenes not found at {} (set UMBRA_SCENES)", dir.display());
        None
    }
}

/// Calls `case` with each shared scene found (file name, mesh) and its default view: the CLI's
/// default interior camera and light (crates/umbra-cli/src/config.rs, `default_camera` /
/// `default_light`, Framing::Interior). A missing scene is skipped with a message.
pub fn for_each_shared_scene_default_view(mut case: impl FnMut(&str, &Mesh, Camera, Light)) {
    let Some(dir) = scenes_dir() else { return };
    for file in ["crytek-sponza.obj.gz", "conference.obj.gz", "sibenik.obj.gz"] {
        let path = dir.join(file);
        if !path.is_file() {
            eprintln!("SKIPPED: {} not found", path.display());
            continue;
        }
        let mesh = umbra_geom::load::load_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let b = mesh.bounds().expect("non-empty scene");
        let (c, e) = (b.center().map(f64::from), b.extent().map(f64::from));
        let min_y = f64::from(b.min[1]);
        let (eye, target) = if e[0] >= e[2] {
            ([c[0] - 0.2 * e[0], min_y + 0.45 * e[1], c[2]], [c[0] + 0.2 * e[0], min_y + 0.3 * e[1], c[2]])
        } else {
            ([c[0], min_y + 0.45 * e[1], c[2] - 0.2 * e[2]], [c[0], min_y + 0.3 * e[1], c[2] + 0.2 * e[2]])
        };
        let light = [(c[0] + 0.11 * e[0]) as f32, (min_y + 0.7 * e[1]) as f32, (c[2] + 0.07 * e[2]) as f32, 1.0];
        let camera = Camera { eye, target, near: 1e-3 * f64::from(b.diagonal()), ..Camera::default() };
        case(file, &mesh, camera, light);
    }
}

/// A closed room (a cuboid seen from inside, the camera inside too) with the light and a box
/// inside: the box shadows the floor and walls, the walls shadow nothing they enclose.
pub fn closed_room() -> (Mesh, Camera, Light) {
    let mut m = cuboid([0.0, 2.5, 0.0], [4.0, 2.5, 4.0]);
    m.append(&cuboid([0.0, 0.75, 0.0], [0.5, 0.75, 0.5]));
    let camera = Camera { eye: [3.2, 4.2, 3.5], target: [0.0, 0.5, 0.0], near: 0.01, ..Camera::default() };
    (m, camera, [-1.0, 3.0, 0.7, 1.0])
}

/// Samples exactly on face planes, axis-aligned: the box's bottom lies in the floor's plane,
/// its side faces' planes cut the floor along its foot, a triangle and a second floor patch lie
/// in the floor's plane over parts of it, and the floor itself is split into coplanar triangles.
/// Its camera and lights are those of [`turned_face_planes`] before the turn.
pub fn face_planes() -> Mesh {
    let mut m = ground_plane([0.0, 0.0, 0.0], 6.0);
    m.append(&ground_plane([1.5, 0.0, 1.0], 2.0));
    m.append(&cuboid([-0.5, 0.5, -0.5], [0.5, 0.5, 0.5]));
    let base = m.positions.len() as u32;
    m.positions.extend_from_slice(&[[-3.0, 0.0, 2.0], [-1.0, 0.0, 3.5], [-2.0, 0.0, 0.5]]);
    m.triangles.push([base, base + 1, base + 2]);
    m
}

/// [`face_planes`] turned about an oblique axis, so that the rasterized positions scatter by
/// rounding on both sides of the planes, with its camera, a point light and a directional light
/// turned alike. Coplanar surfaces meet a sample's segment only at t ~ 0: they must not shadow
/// it (the reference's eps).
pub fn turned_face_planes() -> (Mesh, Camera, Light, Light) {
    let mut m = face_planes();
    let axis = [1.0 / 14f64.sqrt(), 2.0 / 14f64.sqrt(), 3.0 / 14f64.sqrt()];
    let turn = |p: [f64; 3]| rotate(p, axis, 0.7);
    for q in &mut m.positions {
        *q = turn(q.map(f64::from)).map(|c| c as f32);
    }
    let up = turn([0.0, 1.0, 0.0]);
    let camera =
        Camera { eye: turn([4.0, 5.0, 6.0]), target: turn([-0.5, 0.0, 0.0]), up, near: 0.01, ..Camera::default() };
    let point = turn([-3.0, 2.0, -2.0]).map(|c| c as f32);
    let dir = turn([-0.6, 0.8, -0.4]).map(|c| c as f32);
    (m, camera, [point[0], point[1], point[2], 1.0], [dir[0], dir[1], dir[2], 0.0])
}
