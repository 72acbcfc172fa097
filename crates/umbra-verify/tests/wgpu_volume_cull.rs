//! umbra-wgpu's culled volumes, judged by the ray-traced reference: `cpu-silhouette` culled and
//! clamped against the receivers on the CPU (docs/exactness.md, "Volumes clamped to their
//! receivers") and `cs-silhouette` culled on the GPU ("Volumes culled on the GPU"). Exact
//! culled and unculled, z-pass and z-fail, point and directional lights, and the cull really
//! drops the triangles no visible sample lies behind (a cull that silently kept everything
//! would pass every exactness check). The torture suite runs every case both ways too
//! (torture.rs, `run_wgpu`).

mod common;

use std::sync::Arc;

use common::{for_each_shared_scene_default_view, wgpu_gpu};
use umbra_geom::camera::Camera;
use umbra_geom::scene::{cuboid, ground_plane};
use umbra_geom::weld::weld;
use umbra_geom::{Light, Mesh};

/// What one run decided: samples outside the band, and per light the volume drawn.
struct Run {
    outside_band: u64,
    shadowed: u64,
    drawn: Vec<umbra_wgpu::methods::DrawnVolume>,
}

/// The methods that cull on wgpu.
const CULLING: [&str; 2] = ["cpu-silhouette", "cs-silhouette"];

/// `method` on `mesh` with `params`, culled or not, against the reference.
fn run(gpu: &umbra_wgpu::HeadlessGpu, method: &str, mesh: &Mesh, params: &umbra_wgpu::FrameParams) -> [Run; 2] {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let scene = umbra_wgpu::SceneGpu::upload(device, Arc::new(weld(mesh))).expect("upload");
    let mut renderer = umbra_wgpu::Renderer::new(device).expect("renderer");
    let view = umbra_verify::wgpu::view_reference(device, queue, &mut renderer, &scene, params).expect("reference");
    [true, false].map(|cull| {
        let mut volumes = renderer.volumes(device, method).expect("method");
        assert!(volumes.culls_volumes());
        let p = umbra_wgpu::FrameParams { volume_cull: cull, ..params.clone() };
        let report = umbra_verify::wgpu::verify_method(device, queue, &mut renderer, &scene, &mut volumes, &p, &view)
            .unwrap_or_else(|e| panic!("{method}, volume cull {cull}: {e}"));
        let drawn = (0..params.lights.len())
            .map(|i| volumes.read_drawn_volume(device, queue, i).expect("read back").expect("the method reports"))
            .collect();
        Run { outside_band: report.metrics.mismatches_outside_band, shadowed: report.metrics.shadowed_reference, drawn }
    })
}

/// A floor with a box in view and a second box far behind the camera, whose shadow falls where
/// the camera does not look: the cull must drop the second box and keep the first.
fn two_boxes() -> (Mesh, Camera) {
    let mut m = ground_plane([0.0, 0.0, 0.0], 40.0);
    m.append(&cuboid([0.0, 1.0, 0.0], [0.6, 1.0, 0.6]));
    m.append(&cuboid([20.0, 1.0, -30.0], [0.6, 1.0, 0.6]));
    let camera = Camera { eye: [4.0, 5.0, -6.0], target: [0.0, 0.0, 0.5], near: 0.05, ..Camera::default() };
    (m, camera)
}

#[test]
fn culled_volumes_are_exact_and_drop_what_no_visible_sample_lies_behind() {
    let Some(gpu) = wgpu_gpu() else { return };
    let (mesh, camera) = two_boxes();
    let triangles = weld(&mesh).triangles.len() as u64;
    let lights: [Light; 2] = [[1.5, 6.0, -1.0, 1.0], [0.4, 1.0, -0.3, 0.0]];
    for (method, light) in CULLING.iter().flat_map(|m| lights.map(|l| (*m, l))) {
        // Automatic z-pass (the eye is outside every volume: z-pass) and forced z-fail.
        for auto_zpass in [true, false] {
            let params = umbra_wgpu::FrameParams {
                camera,
                width: 240,
                height: 180,
                lights: vec![light],
                auto_zpass,
                ..umbra_wgpu::FrameParams::default()
            };
            let [culled, unculled] = run(&gpu, method, &mesh, &params);
            let what = format!("{method}, light {light:?}, auto z-pass {auto_zpass}");
            assert!(culled.shadowed > 0, "{what}: the reference has no shadow to test");
            assert_eq!(culled.outside_band, 0, "{what}: culled");
            assert_eq!(unculled.outside_band, 0, "{what}: unculled");
            let (c, u) = (culled.drawn[0], unculled.drawn[0]);
            assert!(c.culled && !u.culled, "{what}: {c:?} / {u:?}");
            assert_eq!(u.triangles, triangles, "{what}: unculled keeps every triangle");
            // The far box's 12 triangles at least, and the floor's which face away from nothing
            // in view, go; the near box stays (its shadow is in view).
            assert!(c.triangles + 12 <= triangles && c.triangles >= 12, "{what}: kept {} of {triangles}", c.triangles);
        }
    }
}

/// A device without `SHADER_EARLY_DEPTH_TEST` (as Metal and DX12 are): the scatter's own depth
/// test is then the only one, and the cull is as exact and drops the same far box.
#[test]
fn culled_without_early_depth_tests_is_exact() {
    let Some(gpu) = wgpu_gpu() else { return };
    let features = gpu.adapter.features()
        & (umbra_wgpu::device::frame_features() | umbra_wgpu::wgpu::Features::DEPTH32FLOAT_STENCIL8);
    let descriptor = umbra_wgpu::wgpu::DeviceDescriptor {
        required_features: features,
        required_limits: gpu.adapter.limits(),
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(gpu.adapter.request_device(&descriptor)).expect("device");
    assert!(!device.features().contains(umbra_wgpu::wgpu::Features::SHADER_EARLY_DEPTH_TEST));
    let gpu = umbra_wgpu::HeadlessGpu { device, queue, ..gpu };
    let (mesh, camera) = two_boxes();
    let triangles = weld(&mesh).triangles.len() as u64;
    for method in CULLING {
        for light in [[1.5, 6.0, -1.0, 1.0], [0.4, 1.0, -0.3, 0.0]] {
            let params = umbra_wgpu::FrameParams {
                camera,
                width: 240,
                height: 180,
                lights: vec![light],
                ..umbra_wgpu::FrameParams::default()
            };
            let [culled, unculled] = run(&gpu, method, &mesh, &params);
            assert_eq!((culled.outside_band, unculled.outside_band), (0, 0), "{method}, light {light:?}");
            let c = culled.drawn[0];
            assert!(c.culled && c.triangles + 12 <= triangles, "{method}, light {light:?}: {c:?}");
        }
    }
}

/// The eye inside the near box's shadow volume: z-fail, a clamped volume around the eye.
#[test]
fn eye_inside_a_culled_volume_is_exact() {
    let Some(gpu) = wgpu_gpu() else { return };
    let (mesh, _) = two_boxes();
    let camera = Camera { eye: [-0.3, 0.5, 1.2], target: [-1.5, 0.0, 4.0], near: 0.01, ..Camera::default() };
    let params = umbra_wgpu::FrameParams {
        camera,
        width: 240,
        height: 180,
        lights: vec![[0.5, 4.0, -1.5, 1.0]],
        ..umbra_wgpu::FrameParams::default()
    };
    for method in CULLING {
        let [culled, unculled] = run(&gpu, method, &mesh, &params);
        assert!(culled.shadowed > 0, "the reference has no shadow to test");
        assert_eq!(culled.outside_band, 0, "{method}: culled");
        assert_eq!(unculled.outside_band, 0, "{method}: unculled");
        assert!(culled.drawn[0].culled, "{method}");
    }
}

/// The shared scenes' default views at 320 x 180, point and directional light: exact culled,
/// and the cull keeps fewer triangles than the scene has.
#[test]
fn shared_scenes_culled_are_exact() {
    let Some(gpu) = wgpu_gpu() else { return };
    for_each_shared_scene_default_view(|file, mesh, camera, light| {
        let triangles = weld(mesh).triangles.len() as u64;
        for (method, light) in CULLING.iter().flat_map(|m| [(*m, light), (*m, [0.3, 1.0, 0.2, 0.0])]) {
            let params = umbra_wgpu::FrameParams {
                camera,
                width: 320,
                height: 180,
                lights: vec![light],
                ..umbra_wgpu::FrameParams::default()
            };
            let [culled, unculled] = run(&gpu, method, mesh, &params);
            let d = culled.drawn[0];
            println!(
                "{file} {method} light {light:?}: kept {} of {triangles} triangles, {} edges (unculled {}), clamped {}",
                d.triangles, d.edges, unculled.drawn[0].edges, d.clamped
            );
            assert_eq!(culled.outside_band, 0, "{file}, {method}, light {light:?}: culled");
            assert_eq!(unculled.outside_band, 0, "{file}, {method}, light {light:?}: unculled");
            assert!(d.culled && d.triangles < triangles, "{file}, {method}, light {light:?}: {d:?} of {triangles}");
        }
    });
}
