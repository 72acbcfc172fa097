//! Float inputs pinned on the wgpu backend, each a case the backend must decide exactly (run
//! against the ray-traced reference with the verifier's band rules).

use std::sync::Arc;

use umbra_geom::camera::Camera;
use umbra_geom::weld::weld;
use umbra_geom::Mesh;

/// Crytek Conference's default view under z-fail (`umbra verify --backend wgpu --zmode zfail
/// --scene conference.obj.gz`) had one false shadow at pixel (142, 536): a lit floor sample
/// with a stencil of -3. Behind it ran the sides of three short silhouette edges (0.01 units
/// long, 640 units from the light) of a chair: each side's triangle (Y, X_inf, Y_inf) is a
/// needle whose two vertices at infinity lie 0.005 px apart, and lavapipe gave the needle's
/// fragment at that pixel a NaN depth, which passed the depth test: three back faces behind
/// the sample went uncounted. Now the volume fragment shader writes the depth, NaN made far
/// (shaders/volume.wgsl). The floor triangle, the chair's triangles on those edges, the light
/// and the camera, exactly (1280x720, so the needles snap to the same subpixels).
#[test]
fn needle_side_with_nan_depth_on_conference() {
    let gpu = match umbra_wgpu::HeadlessGpu::new() {
        Ok(g) => g,
        Err(e @ umbra_wgpu::WgpuError::NoAdapter { .. }) => {
            eprintln!("SKIPPED: {e}");
            return;
        }
        Err(e) => panic!("wgpu device: {e}"),
    };
    let floor = [[-946.888, -1.57216, -1016.1], [-946.888, -1.57216, 668.489], [1653.25, -1.57216, -1016.1]];
    let y = [1635.48, -0.064194, -1014.72];
    let chair = [
        [y, [1635.49, -0.063187, -1014.72], [1635.32, 0.036545, -1013.44]],
        [[1635.48, -0.064133, -1014.72], [1635.49, -0.063126, -1014.72], [1635.48, -0.064133, -1014.71]],
        [[1635.48, -0.064133, -1014.72], [1635.49, -0.063126, -1014.72], [1635.49, -0.064133, -1014.72]],
    ];
    let mut mesh = Mesh::default();
    for t in std::iter::once(floor).chain(chair) {
        let b = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&t);
        mesh.triangles.push([b, b + 1, b + 2]);
    }
    let welded = Arc::new(weld(&mesh));
    let camera = Camera {
        eye: [-208.34796142578125, 291.09605226516726, -193.58551025390625],
        target: [874.0280151367188, 193.13323488235474, -193.58551025390625],
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 60.0,
        near: 3.274343017578125,
        ..Camera::default()
    };
    let params = umbra_wgpu::FrameParams {
        camera,
        width: 1280,
        height: 720,
        lights: vec![[630.4934, 454.36743, -72.89507, 1.0]],
        auto_zpass: false,
        ..umbra_wgpu::FrameParams::default()
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let scene = umbra_wgpu::SceneGpu::upload(device, welded).expect("upload");
    let mut renderer = umbra_wgpu::Renderer::new(device).expect("renderer");
    let view = umbra_verify::wgpu::view_reference(device, queue, &mut renderer, &scene, &params).expect("reference");
    for method in ["cpu-silhouette", "vs-silhouette", "cs-silhouette"] {
        let mut volumes = renderer.volumes(device, method).expect("method");
        let report =
            umbra_verify::wgpu::verify_method(device, queue, &mut renderer, &scene, &mut volumes, &params, &view)
                .expect("verify");
        let pixel = 536 * 1280 + 142;
        assert!(!report.per_light[0].shadowed[pixel], "{method}: the floor sample at (142, 536) is lit");
        assert_eq!(report.metrics.mismatches_outside_band, 0, "{method}");
    }
}
