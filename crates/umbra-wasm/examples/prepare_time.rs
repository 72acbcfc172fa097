//! Native timing of what the WebAssembly module does, loading apart: loads a scene (any
//! `umbra` scene spec, e.g. a path to an OBJ), flattens it into a three.js-style geometry
//! (positions and a u32 index), then times [`umbra_wasm::prepare`] (check, weld, adjacency,
//! sides-data, caps-data, edge triangles, normals) over several runs: once on the mesh as
//! loaded, once on its welded mesh (the positions.bin and indices.bin of `umbra export`, the
//! input `web/bench-wasm.mjs` gives the module).
//!
//! `cargo run --release -p umbra-wasm --example prepare_time -- SCENE [RUNS]`
//! (`RAYON_NUM_THREADS=1` for one thread, as in the browser).

use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let spec = args.next().ok_or("usage: prepare_time SCENE [RUNS]")?;
    let runs: usize = args.next().map(|r| r.parse()).transpose()?.unwrap_or(5);
    let start = Instant::now();
    let mesh = umbra_geom::scene::load_scene(&spec)?;
    let load = start.elapsed();
    println!("{spec}: load {:.0} ms", load.as_secs_f64() * 1e3);
    time(&spec, "as loaded", &mesh, runs)?;
    let welded = umbra_geom::weld::weld(&mesh);
    let welded = umbra_geom::Mesh { positions: welded.positions, triangles: welded.triangles, normals: None };
    time(&spec, "welded (umbra export's positions.bin, indices.bin)", &welded, runs)?;
    Ok(())
}

/// Times `prepare` on `mesh` as a geometry with a u32 index.
fn time(spec: &str, what: &str, mesh: &umbra_geom::Mesh, runs: usize) -> Result<(), Box<dyn std::error::Error>> {
    let positions: Vec<f32> = mesh.positions.iter().flatten().copied().collect();
    let index: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        last = Some(umbra_wasm::prepare(spec, &positions, Some(&index))?);
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let p = last.ok_or("RUNS must be at least 1")?;
    times.sort_by(f64::total_cmp);
    println!(
        "  prepare {what}: {} vertices, {} triangles -> {} triangles, {} edge records, maxMult {}: median {:.0} ms, min {:.0} ms over {runs} runs, {} threads",
        mesh.positions.len(),
        p.input_triangles,
        p.buffers.triangles,
        p.buffers.records,
        p.buffers.max_mult,
        times[times.len() / 2],
        times[0],
        umbra_geom_threads(),
    );
    Ok(())
}

/// Threads the parallel parts of umbra-geom use (rayon's global pool).
fn umbra_geom_threads() -> usize {
    std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
