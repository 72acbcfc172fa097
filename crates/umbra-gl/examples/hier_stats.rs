//! hier-triangle's and hier-silhouette's traversal statistics for one view: work counts
//! (dispatches, nodes and leaves tested, nodes pruned), hier-silhouette's pairs queued per level
//! (against the queues' capacity), per-stage times (glFinish at every stage), and the frame time
//! of `none` and `cpu-silhouette` in the same run for comparison.
//!
//! `cargo run --release -p umbra-gl --example hier_stats -- SCENE [WIDTHxHEIGHT] [EYE_X,Y,Z TARGET_X,Y,Z]`
//! The light is the CLI's default interior light (70 % of the height, slightly off-centre);
//! the camera defaults to the CLI's default interior camera.

use std::sync::Arc;
use std::time::Instant;

use umbra_gl::methods::hier_silhouette::HierSilhouette;
use umbra_gl::methods::hier_triangle::HierTriangle;
use umbra_gl::{create_method, Camera, FrameParams, HeadlessContext, Renderer, SceneGpu, ShadowMethod, TimestampHook};

fn parse3(s: &str) -> Result<[f64; 3], Box<dyn std::error::Error>> {
    let v: Vec<f64> = s.split(',').map(str::parse).collect::<Result<_, _>>()?;
    Ok([v[0], v[1], v[2]])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec = args.first().ok_or("usage: hier_stats SCENE [WxH] [EYE TARGET]")?;
    let (width, height) = match args.get(1) {
        Some(s) => {
            let (w, h) = s.split_once('x').ok_or("size must be WIDTHxHEIGHT")?;
            (w.parse()?, h.parse()?)
        }
        None => (640, 360),
    };
    let mesh = umbra_geom::scene::load_scene(spec)?;
    let welded = Arc::new(umbra_geom::weld::weld(&mesh));
    let b = mesh.bounds().ok_or("empty scene")?;
    let (c, e) = (b.center().map(f64::from), b.extent().map(f64::from));
    let min_y = f64::from(b.min[1]);
    let (eye, target) = match (args.get(2), args.get(3)) {
        (Some(a), Some(t)) => (parse3(a)?, parse3(t)?),
        _ => ([c[0] - 0.2 * e[0], min_y + 0.45 * e[1], c[2]], [c[0] + 0.2 * e[0], min_y + 0.3 * e[1], c[2]]),
    };
    let light = [(c[0] + 0.11 * e[0]) as f32, (min_y + 0.7 * e[1]) as f32, (c[2] + 0.07 * e[2]) as f32, 1.0];
    let ctx = HeadlessContext::new()?;
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, welded)?;
    let mut renderer = Renderer::new(gl)?.with_error_log(ctx.error_log().cloned());
    let params = FrameParams {
        camera: Camera { eye, target, near: 1e-3 * f64::from(b.diagonal()), ..Camera::default() },
        width,
        height,
        lights: vec![light],
        ..FrameParams::default()
    };
    println!("{spec}: {} triangles, {width}x{height}", scene.triangle_count());
    let mut hook = TimestampHook::synchronous();
    let scale: f64 = std::env::var("HIER_QUEUE_SCALE").ok().and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let mut hier = HierTriangle::new();
    for frame in 0..3 {
        let t = Instant::now();
        renderer.render(gl, &scene, &mut hier, &params, Some(&mut hook))?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let stages: Vec<String> = hook
            .finish(gl)
            .iter()
            .map(|s| format!("{} {:.1}/{:.1}", s.mark.label, s.gpu_ns as f64 / 1e6, s.cpu_ns as f64 / 1e6))
            .collect();
        println!("hier-triangle frame {frame}: {ms:.1} ms; {}", stages.join(", "));
    }
    hier.set_count_work(true);
    renderer.render(gl, &scene, &mut hier, &params, None)?;
    println!("  work {:?}; {} traversal dispatch(es)", hier.work_counts(gl), hier.last_rounds());
    hier.set_count_work(false);
    if let Some(layout) = hier.layout() {
        let dims: Vec<String> = layout.levels.iter().map(|l| format!("{}x{}", l.width, l.height)).collect();
        println!("  levels {}; {} MiB", dims.join(" "), hier.gpu_bytes() >> 20);
    }
    let mut sil = HierSilhouette::with_queue_scale(scale);
    for frame in 0..3 {
        let t = Instant::now();
        renderer.render(gl, &scene, &mut sil, &params, Some(&mut hook))?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let stages: Vec<String> = hook
            .finish(gl)
            .iter()
            .map(|s| format!("{} {:.1}/{:.1}", s.mark.label, s.gpu_ns as f64 / 1e6, s.cpu_ns as f64 / 1e6))
            .collect();
        println!("hier-silhouette frame {frame}: {ms:.1} ms; {}", stages.join(", "));
    }
    println!("  redo list: {} faces; unsure decisions {:?}", sil.redo_faces(gl), sil.unsure_counts(gl));
    sil.set_count_work(true);
    renderer.render(gl, &scene, &mut sil, &params, None)?;
    println!("  work {:?}", sil.work_counts(gl));
    sil.set_count_work(false);
    for (l, (pairs, capacity)) in sil.queue_counts(gl).iter().enumerate() {
        println!("  level {l}: {pairs} pairs queued, capacity {capacity}");
    }
    if let Some(faces) = sil.faces() {
        println!(
            "  {} faces ({} caps, {} edge records); {} MiB",
            faces.count(),
            faces.triangles,
            faces.records,
            sil.gpu_bytes() >> 20
        );
    }
    sil.destroy(gl);
    for name in ["none", "cpu-silhouette"] {
        let mut m = create_method(name)?;
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let t = Instant::now();
            renderer.render(gl, &scene, m.as_mut(), &params, None)?;
            best = best.min(t.elapsed().as_secs_f64() * 1e3);
        }
        println!("{name}: best of 3 frames {best:.1} ms");
        m.destroy(gl);
    }
    hier.destroy(gl);
    hook.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    Ok(())
}
