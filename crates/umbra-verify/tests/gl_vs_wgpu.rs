//! The same frame on both backends: for every method the wgpu backend shares with umbra-gl
//! (`umbra_wgpu::method_names()`), the stencil after each light's volume pass and the lit mask
//! are read back from umbra-gl (OpenGL 4.5 through EGL, Mesa llvmpipe here) and from
//! umbra-wgpu (Vulkan, Mesa lavapipe here) and compared pixel for pixel.
//!
//! What is asserted:
//! * both backends rasterize the same samples (triangle id per pixel);
//! * wherever the two stencils disagree on "lit" (0 or not), or the lit masks disagree, the
//!   sample lies in the reference's boundary band (umbra-oracle, computed from the wgpu
//!   frame's samples): outside the band both are exact, so both must agree.
//!
//! What is reported (stdout, and `target/test-output/gl-vs-wgpu/<frame>.tsv`): per method and
//! light, the pixels whose stencil values differ, those that differ in "lit", and the lit-mask
//! differences. Shadow maps are compared the same way (their "stencil" is the resolve of their
//! depth test, 0 = lit).
//!
//! Skipped with a message when no Vulkan/Metal/DX12 adapter exists (CI installs lavapipe).

mod common;

use std::path::PathBuf;
use std::sync::Arc;

use common::wgpu_gpu;
use umbra_geom::scene::{cuboid, ground_plane, uv_sphere};
use umbra_geom::weld::weld;
use umbra_geom::{Light, Mesh, WeldedMesh};
use umbra_gl::{
    create_method, Camera, CaptureFlags, ContextOptions, GlApi, HeadlessContext, LightCapture, Renderer, SceneGpu,
};

const W: u32 = 200;
const H: u32 = 150;

fn output_dir() -> PathBuf {
    std::env::var_os("UMBRA_TEST_OUTPUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output"))
        .join("gl-vs-wgpu")
}

/// `pages` triangles hinged on one spine: an edge of multiplicity far above 1.
fn book(pages: usize) -> Mesh {
    let mut m = Mesh { positions: vec![[2.0, 1.0, -0.5], [2.0, 1.0, 0.5]], ..Default::default() };
    for k in 0..pages {
        let a = std::f32::consts::PI * (0.1 + 0.8 * k as f32 / pages as f32);
        m.positions.push([2.0 + 0.8 * a.cos(), 1.0 + 0.8 * a.sin(), 0.0]);
        let o = 2 + k as u32;
        m.triangles.push(if k % 2 == 0 { [0, 1, o] } else { [1, 0, o] });
    }
    m
}

fn scene() -> Arc<WeldedMesh> {
    let mut m = uv_sphere([0.0, 2.0, 0.0], 1.0, 32, 16);
    m.append(&book(12));
    m.append(&cuboid([-2.5, 0.5, 1.0], [0.5, 0.5, 0.5]));
    m.append(&ground_plane([0.0, 0.0, 0.0], 10.0));
    Arc::new(weld(&m))
}

struct Frame {
    name: &'static str,
    camera: Camera,
    lights: Vec<Light>,
    zpass: bool,
    auto_zpass: bool,
}

fn compare(frame: Frame) {
    let Some(gpu) = wgpu_gpu() else { return };
    let mesh = scene();
    let ctx = HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
        .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"));
    let gl = ctx.gl();
    let gl_scene = SceneGpu::upload(gl, mesh.clone()).expect("GL upload");
    let mut gl_renderer = Renderer::new(gl).expect("GL renderer").with_error_log(ctx.error_log().cloned());
    let capture = |world| CaptureFlags {
        world_pos: world,
        triangle_id: true,
        stencil: LightCapture::AllLights,
        lit_mask: LightCapture::AllLights,
    };
    let gl_params = umbra_gl::FrameParams {
        camera: frame.camera,
        width: W,
        height: H,
        lights: frame.lights.clone(),
        zpass: frame.zpass,
        auto_zpass: frame.auto_zpass,
        capture: capture(false),
        ..umbra_gl::FrameParams::default()
    };
    let (device, queue) = (&gpu.device, &gpu.queue);
    let wgpu_scene = umbra_wgpu::SceneGpu::upload(device, mesh.clone()).expect("wgpu upload");
    let mut wgpu_renderer = umbra_wgpu::Renderer::new(device).expect("wgpu renderer");
    let wgpu_params = umbra_wgpu::FrameParams {
        camera: frame.camera,
        width: W,
        height: H,
        lights: frame.lights.clone(),
        zpass: frame.zpass,
        auto_zpass: frame.auto_zpass,
        capture: umbra_wgpu::CaptureFlags {
            world_pos: false,
            triangle_id: true,
            stencil: umbra_wgpu::LightCapture::AllLights,
            lit_mask: umbra_wgpu::LightCapture::AllLights,
        },
        ..umbra_wgpu::FrameParams::default()
    };
    // The band of the wgpu frame's own samples (both backends' samples are asserted equal).
    let view = umbra_verify::wgpu::view_reference(device, queue, &mut wgpu_renderer, &wgpu_scene, &wgpu_params)
        .unwrap_or_else(|e| panic!("{}: reference: {e}", frame.name));

    let mut tsv =
        String::from("method\tlight\tstencil_differs\tlit_differs\tlit_differs_outside_band\tlit_mask_differs\n");
    let mut failures = Vec::new();
    for &name in umbra_wgpu::method_names() {
        let mut gl_method = create_method(name).unwrap_or_else(|e| panic!("GL has no {name}: {e}"));
        let gl_images = gl_renderer.render(gl, &gl_scene, gl_method.as_mut(), &gl_params, None);
        gl_method.destroy(gl);
        let gl_images = gl_images.unwrap_or_else(|e| panic!("{} / GL {name}: {e}", frame.name));
        let mut volumes = wgpu_renderer.volumes(device, name).expect("wgpu method");
        let wgpu_images = wgpu_renderer
            .render(device, queue, &wgpu_scene, &mut volumes, &wgpu_params)
            .unwrap_or_else(|e| panic!("{} / wgpu {name}: {e}", frame.name));
        let (gl_ids, wgpu_ids) = (gl_images.triangle_id.expect("GL ids"), wgpu_images.triangle_id.expect("wgpu ids"));
        let id_differs = gl_ids.pixels.iter().zip(&wgpu_ids.pixels).filter(|(a, b)| a != b).count();
        assert_eq!(id_differs, 0, "{} / {name}: the backends rasterized different samples", frame.name);
        // Shadow maps classify in the lighting shader on GL (the stencil read back there is
        // not their decision); on wgpu they resolve into the stencil. Lit masks only for them.
        let gl_has_stencil = !name.starts_with(umbra_geom::shadow_map::PREFIX);
        for (i, lr) in view.lights.iter().enumerate() {
            let (gl_lit, wgpu_lit) = (&gl_images.lit_masks[i].image.pixels, &wgpu_images.lit_masks[i].image.pixels);
            let lit_mask_differs = gl_lit.iter().zip(wgpu_lit).filter(|(a, b)| a != b).count();
            let mut outside = 0;
            let (mut stencil_differs, mut lit_differs) = (0, 0);
            for k in 0..(W * H) as usize {
                let mut differs = gl_lit[k] != wgpu_lit[k];
                if gl_has_stencil {
                    let (g, w) = (gl_images.stencil[i].image.pixels[k], wgpu_images.stencil[i].image.pixels[k]);
                    stencil_differs += (g != w) as usize;
                    // "Lit" only matters on geometry.
                    let geometry = wgpu_ids.pixels[k] != umbra_wgpu::NO_TRIANGLE;
                    if geometry && (g == 0) != (w == 0) {
                        lit_differs += 1;
                        differs = true;
                    }
                }
                if differs && !lr.reference.band[k] {
                    outside += 1;
                }
            }
            let stencil = if gl_has_stencil {
                format!("stencil values differ on {stencil_differs:>5} of {} pixels, lit on {lit_differs:>4}", W * H)
            } else {
                "stencil not compared (GL classifies in its lighting shader)".to_string()
            };
            println!(
                "{:<22} {:<24} light {i}: {stencil}; lit masks differ on {lit_mask_differs} ({outside} decisions outside the band)",
                frame.name, name
            );
            tsv += &format!("{name}\t{i}\t{stencil_differs}\t{lit_differs}\t{outside}\t{lit_mask_differs}\n");
            if outside > 0 {
                failures.push(format!("{name} light {i}: {outside} decisions differ outside the band"));
            }
        }
    }
    let dir = output_dir();
    let _ = std::fs::create_dir_all(&dir);
    let _ = std::fs::write(dir.join(format!("{}.tsv", frame.name)), tsv);
    gl_renderer.destroy(gl);
    gl_scene.destroy(gl);
    assert!(failures.is_empty(), "{}: {}", frame.name, failures.join("; "));
}

const EYE: [f64; 3] = [5.0, 4.0, 6.0];

fn camera(eye: [f64; 3]) -> Camera {
    Camera { near: 0.01, ..Camera::look_at(eye, [0.0, 0.5, 0.0]) }
}

#[test]
fn zfail_point_and_directional_lights() {
    compare(Frame {
        name: "zfail-two-lights",
        camera: camera(EYE),
        lights: vec![[0.3, 6.0, 0.2, 1.0], [-0.5, 1.0, 0.3, 0.0]],
        zpass: false,
        auto_zpass: false,
    });
}

#[test]
fn auto_zpass_and_camera_in_shadow() {
    // Light 0 leaves the eye clear (z-pass), the eye under the sphere is in light 1's shadow
    // (z-fail, or z-pass from W0).
    compare(Frame {
        name: "auto-camera-in-shadow",
        camera: Camera { near: 0.01, ..Camera::look_at([0.1, 0.3, 0.1], [4.0, 0.0, 3.0]) },
        lights: vec![[0.3, 6.0, 0.2, 1.0], [6.0, 3.0, -4.0, 1.0]],
        zpass: false,
        auto_zpass: true,
    });
}
