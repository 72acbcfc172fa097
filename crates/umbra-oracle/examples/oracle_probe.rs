//! Profiling driver: loads Sponza, builds the BVH a few times, runs the reference once per
//! light, printing wall and process CPU times. `cargo run --release --example oracle_probe [SCENE]`
use std::time::Instant;
use umbra_oracle::synthetic::{primary_samples, PinholeCamera};
use umbra_oracle::{reference, Bvh, Samples};

/// Process CPU time (user + system) in seconds from /proc/self/stat (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

fn timed<T>(what: &str, f: impl FnOnce() -> T) -> T {
    let (w, c) = (Instant::now(), cpu_seconds());
    let r = f();
    println!("{what}: wall {:.3?}, cpu {:.2}s", w.elapsed(), cpu_seconds() - c);
    r
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| "/work/shared/scenes/crytek-sponza.obj.gz".into());
    let mesh = umbra_geom::load::load_path(std::path::Path::new(&path))?;
    let w = umbra_geom::weld::weld(&mesh);
    let mut bvh = None;
    for _ in 0..3 {
        bvh = Some(timed("bvh build", || Bvh::build(&w.positions, &w.triangles))?);
    }
    let bvh = bvh.ok_or("no bvh")?;
    let cam = PinholeCamera {
        eye: [-8.2, 1.5, -0.1],
        target: [5.0, 2.5, 0.3],
        up: [0.0, 1.0, 0.0],
        fov_y: 60f32.to_radians(),
        width: 1280,
        height: 720,
    };
    let (pos, tri) = timed("primary rays", || primary_samples(&bvh, &cam));
    let samples = Samples { width: 1280, height: 720, world_pos: &pos, triangle: &tri };
    for light in [[0.0f32, 6.0, 0.0, 1.0], [0.3, 1.0, 0.2, 0.0]] {
        timed(&format!("reference {light:?}"), || reference(&w, &bvh, &samples, light, cam.eye))?;
    }
    Ok(())
}
