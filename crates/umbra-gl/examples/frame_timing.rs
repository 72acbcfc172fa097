//! Renders a scene headlessly with every shadow method, prints per-stage timings
//! (glQueryCounter(GL_TIMESTAMP) pairs + CPU wall time) and writes one PNG per method.
//!
//! `cargo run --release -p umbra-gl --example frame_timing -- [SCENE] [WIDTHxHEIGHT] [FRAMES] [OUT_DIR] [METHODS]`
//! SCENE is an umbra_geom scene spec (default `spheres:10:100k`, which has a ground plane);
//! METHODS a comma-separated list of method names (default: every registered method).

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use umbra_gl::{create_method, method_names, Camera, FrameParams, HeadlessContext, Renderer, SceneGpu, TimestampHook};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec = args.first().map_or("spheres:10:100k", String::as_str);
    let (width, height) = match args.get(1) {
        Some(s) => {
            let (w, h) = s.split_once('x').ok_or("size must be WIDTHxHEIGHT")?;
            (w.parse()?, h.parse()?)
        }
        None => (1280, 720),
    };
    let frames: usize = args.get(2).map_or(Ok(5), |s| s.parse())?;
    let out_dir = std::path::PathBuf::from(args.get(3).map_or("target/frame_timing", String::as_str));
    let names: Vec<String> = match args.get(4) {
        Some(list) => list.split(',').map(str::to_string).collect(),
        None => method_names().iter().map(|n| n.to_string()).collect(),
    };

    let mesh = umbra_geom::scene::load_scene(spec)?;
    let t = Instant::now();
    let welded = Arc::new(umbra_geom::weld::weld(&mesh));
    println!("scene {spec}: {} triangles, weld {:.1} ms", welded.triangles.len(), t.elapsed().as_secs_f64() * 1e3);
    let b = mesh.bounds().ok_or("empty scene")?;
    let (c, d) = (b.center().map(f64::from), f64::from(b.diagonal()));

    let ctx = HeadlessContext::new()?;
    println!("GL: {} / {} ({})", ctx.renderer_string(), ctx.version_string(), ctx.platform());
    let gl = ctx.gl();
    let scene = SceneGpu::upload(gl, welded)?;
    let t = Instant::now();
    scene.adjacency();
    println!("adjacency {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let mut renderer = Renderer::new(gl)?.with_error_log(ctx.error_log().cloned());
    let params = FrameParams {
        camera: Camera {
            eye: [c[0] + 0.45 * d, c[1] + 0.35 * d, c[2] + 0.55 * d],
            target: c,
            near: d * 1e-3,
            ..Camera::default()
        },
        width,
        height,
        lights: vec![[(c[0] - 0.2 * d) as f32, (c[1] + 0.6 * d) as f32, (c[2] + 0.1 * d) as f32, 1.0]],
        ..FrameParams::default()
    };
    // UMBRA_SYNC_STAGES=1: glFinish at every stage boundary (exact attribution on llvmpipe).
    let mut hook = if std::env::var_os("UMBRA_SYNC_STAGES").is_some() {
        TimestampHook::synchronous()
    } else {
        TimestampHook::new()
    };
    for name in &names {
        let mut method = create_method(name)?;
        let mut totals: BTreeMap<String, (u64, u64)> = BTreeMap::new();
        let mut wall = Vec::new();
        for frame in 0..=frames {
            let t = Instant::now();
            let images = renderer.render(gl, &scene, method.as_mut(), &params, Some(&mut hook))?;
            wall.push(t.elapsed().as_secs_f64() * 1e3);
            let timings = hook.finish(gl);
            if frame == 0 {
                // First frame pays shader compiles and preparation: not averaged.
                images.rgba.save_png(&out_dir.join(format!("{name}.png")))?;
                wall.clear();
                continue;
            }
            for s in timings {
                let key = format!("{}:{}", s.mark.source, s.mark.label);
                let e = totals.entry(key).or_default();
                e.0 += s.gpu_ns;
                e.1 += s.cpu_ns;
            }
        }
        let n = frames as f64;
        wall.sort_by(f64::total_cmp);
        println!(
            "{name}: median frame incl. readback {:.2} ms, gpu bytes {}",
            wall[wall.len() / 2],
            method.gpu_bytes()
        );
        for (k, (g, c)) in totals {
            println!("  {k:<28} gpu {:8.3} ms   cpu {:8.3} ms", g as f64 / n / 1e6, c as f64 / n / 1e6);
        }
        method.destroy(gl);
    }
    hook.destroy(gl);
    renderer.destroy(gl);
    scene.destroy(gl);
    Ok(())
}
