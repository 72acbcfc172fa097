//! The ray-bvh hierarchy of a scene on the CPU: build time, size, depth, and the work of shadow
//! rays from random points of the scene's triangles to its default light (the GPU walk's
//! reference, `umbra_geom::ray_bvh::RayBvh::occluded`).
//!
//!     cargo run --release -p umbra-geom --example ray_bvh_walk -- SCENE [RAYS]

use std::time::Instant;

use umbra_geom::ray_bvh::{build, segment_epsilon};
use umbra_geom::scene::load_scene;
use umbra_geom::weld::weld;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(spec) = args.get(1) else {
        eprintln!("usage: ray_bvh_walk SCENE [RAYS]");
        std::process::exit(2);
    };
    let rays: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let soup = match load_scene(spec) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let Some(b) = soup.bounds() else { return };
    let mesh = weld(&soup);
    let started = Instant::now();
    let bvh = build(&mesh.positions, &mesh.triangles);
    let build_ms = started.elapsed().as_secs_f64() * 1e3;
    println!(
        "{} triangles ({} left out): {} nodes, depth {}, {:.1} MiB, built in {build_ms:.0} ms",
        mesh.triangles.len(),
        bvh.skipped,
        bvh.node_count(),
        bvh.depth,
        bvh.bytes() as f64 / (1024.0 * 1024.0)
    );
    // The CLI's default light of an interior (crates/umbra-cli/src/config.rs): 70 % of the
    // height, a little off the centre.
    let (c, e) = (b.center(), b.extent());
    let light = [c[0] + 0.11 * e[0], b.min[1] + 0.7 * e[1], c[2] + 0.07 * e[2]];
    let eps = segment_epsilon(&mesh.positions) as f32;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let (mut nodes, mut triangles, mut hits) = (0usize, 0usize, 0usize);
    let started = Instant::now();
    for _ in 0..rays {
        let t = (next() * mesh.triangles.len() as f32) as usize % mesh.triangles.len();
        let v = mesh.triangles[t].map(|k| mesh.positions[k as usize]);
        let (mut u, mut w) = (next(), next());
        if u + w > 1.0 {
            (u, w) = (1.0 - u, 1.0 - w);
        }
        let o = [0, 1, 2].map(|k| v[0][k] + u * (v[1][k] - v[0][k]) + w * (v[2][k] - v[0][k]));
        let d = [0, 1, 2].map(|k| light[k] - o[k]);
        let (hit, walk) = bvh.occluded(o, d, 1.0, 0.5 * eps, f32::INFINITY, t as u32);
        nodes += walk.nodes;
        triangles += walk.triangles;
        hits += usize::from(hit);
    }
    let ms = started.elapsed().as_secs_f64() * 1e3;
    let n = rays as f64;
    println!(
        "{rays} rays to {light:?}: {:.0} % occluded, {:.1} nodes and {:.1} triangles per ray, {:.2} M rays/s on one core",
        100.0 * hits as f64 / n,
        nodes as f64 / n,
        triangles as f64 / n,
        n / ms / 1e3
    );
}
