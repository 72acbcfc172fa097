//! The soak's plan: the scene, the fly-through's frame parameters per frame and phase, the
//! methods at their soak resolutions, and the fixed frame every method renders at the start
//! and at the end.

use crate::common::*;
use std::sync::Arc;
use umbra_geom::{scene, weld::weld, WeldedMesh};
use umbra_gl::counter::Counter;
use umbra_gl::{
    create_method, Camera, CaptureFlags, FrameParams, HeadlessContext, LightCapture, Renderer, SceneGpu, ShadowMethod,
};

/// `spheres:2` over a ground plane.
pub(crate) fn soak_scene() -> Arc<WeldedMesh> {
    let mut mesh = scene::load_scene("spheres:2").expect("procedural scene");
    scene::add_ground(&mut mesh);
    Arc::new(weld(&mesh))
}

/// Centre and radius of the mesh's bounding box.
pub(crate) fn frame_of(mesh: &WeldedMesh) -> ([f64; 3], f64) {
    let (lo, hi) = mesh.positions.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
        ([0, 1, 2].map(|k| lo[k].min(f64::from(p[k]))), [0, 1, 2].map(|k| hi[k].max(f64::from(p[k]))))
    });
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let r = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max) * 0.5;
    (c, r)
}

/// Cycles per block: the configurations of a frame depend only on its cycle's phase
/// (`cycle % PHASES`), and every combination of the features below occurs once per block.
pub(crate) const PHASES: usize = 12;

/// The frame parameters of frame `f` (cycle `f / methods`, see [`PHASES`]).
pub(crate) fn fly_through(f: usize, methods: usize, centre: [f64; 3], radius: f64) -> FrameParams {
    let phase = (f / methods) % PHASES;
    let angle = std::f64::consts::TAU * f as f64 / 360.0; // one orbit per 360 frames
    let camera = Camera {
        eye: [centre[0] + 1.6 * radius * angle.cos(), centre[1] + 0.9 * radius, centre[2] + 1.6 * radius * angle.sin()],
        target: centre,
        up: [0.0, 1.0, 0.0],
        fov_y_degrees: 55.0,
        near: 0.01 * radius,
        ..Camera::default()
    };
    let light_angle = -std::f64::consts::TAU * f as f64 / 97.0;
    let point = [
        (centre[0] + 0.5 * radius * light_angle.cos()) as f32,
        (centre[1] + 1.2 * radius) as f32,
        (centre[2] + 0.5 * radius * light_angle.sin()) as f32,
        1.0,
    ];
    let mut lights = vec![point];
    if phase % 2 == 1 {
        lights.push([0.3, 1.0, 0.2, 0.0]);
    }
    let (width, height) = if (phase / 2).is_multiple_of(2) { (160, 120) } else { (120, 160) };
    let capture = if phase % 3 == 2 {
        CaptureFlags {
            world_pos: true,
            triangle_id: true,
            stencil: LightCapture::AllLights,
            lit_mask: LightCapture::AllLights,
        }
    } else {
        CaptureFlags::default()
    };
    let counter = if phase == 6 { Counter::Float32 } else { Counter::Stencil8 };
    FrameParams {
        camera,
        width,
        height,
        lights,
        capture,
        zpass: phase % 4 == 3,
        auto_zpass: phase != 1,
        counter,
        ..FrameParams::default()
    }
}

/// Makes the soak's methods, in a fixed order (one cycle = one frame of each).
pub(crate) type MethodFactory = fn() -> Vec<Box<dyn ShadowMethod>>;

/// The soak's name for a registered method: the shadow maps at an eighth of their registered
/// resolution (`shadow-map-cube:1024` -> `:128`, `:2048` -> `:256`). The code is the same for
/// every resolution; the memory is not: a destroyed 2048 map is 96 MiB that Mesa may keep alive
/// for several blocks (see the module doc), which at 256 is 1.5 MiB, below the memory check's
/// noise.
pub(crate) fn soak_name(registered: &str) -> String {
    match registered.strip_prefix("shadow-map-cube:").and_then(|r| r.parse::<u32>().ok()) {
        Some(resolution) => format!("shadow-map-cube:{}", resolution / 8),
        None => registered.to_string(),
    }
}

/// One method instance per registered name ([`soak_name`]).
pub(crate) fn create_all() -> Vec<Box<dyn ShadowMethod>> {
    umbra_gl::method_names().iter().map(|n| create_method(&soak_name(n)).expect("registered method")).collect()
}

/// Every method renders the fixed frame (with captures); PNG bytes per method.
pub(crate) fn fixed_frames(
    ctx: &HeadlessContext,
    renderer: &mut Renderer,
    scene: &SceneGpu,
    methods: &mut [Box<dyn ShadowMethod>],
    p: &FrameParams,
    tag: &str,
) -> Vec<Vec<u8>> {
    let dir = output_dir().join("soak");
    std::fs::create_dir_all(&dir).expect("create the soak output directory");
    methods
        .iter_mut()
        .map(|m| {
            let images = renderer
                .render(ctx.gl(), scene, m.as_mut(), p, None)
                .unwrap_or_else(|e| panic!("{tag}: {}: {e}", m.name()));
            let path = dir.join(format!("{tag}-{}.png", m.name().replace(':', "-")));
            images.rgba.save_png(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        })
        .collect()
}
