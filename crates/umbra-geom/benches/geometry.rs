//! `cargo bench -p umbra-geom`: the CPU geometry path of umbra on a real scene (Crytek
//! Sponza) and on the synthetic sphere scene of paper 001 Table 5 (`spheres:10:1000000`).
//!
//! * preprocessing, once per mesh: exact-position [`weld`] and [`EdgeAdjacency::build`]
//!   (throughput in triangles), next to meshoptimizer's adjacency index buffer
//!   (`meshopt::generate_adjacency_indices`, the peer a user would otherwise pick; it assumes
//!   manifold meshes and keeps one neighbour per edge, so it is a speed reference only);
//! * per frame: [`extract`], i.e. every edge's multiplicity (paper 001 Alg. 3-4) plus the
//!   side quads and caps (throughput in edges), for a point light inside the scene and for
//!   a directional light, with the output buffers reused across frames as a renderer would;
//!   the caps both as vertex copies ([`extract`]) and as oriented index triples from one
//!   orientation per triangle ([`extract_indexed`] with its per-mesh [`TriangleSlots`], what
//!   the cpu-silhouette renderer uses), in the same run.
//!
//! Scenes come from `UMBRA_SCENES` (default `<workspace>/../shared/scenes`); Sponza is
//! skipped with a message when absent. Before criterion measures, each scene's counts and
//! the rows of the tables in `docs/benchmarks.md` are printed: the best of several runs of
//! every stage, ours and meshopt's in the same process (on a shared machine the best run is
//! the least disturbed one; criterion's mean includes every disturbance), the load average,
//! the volume sizes and the heap allocations of warmed-up frames. With
//! `UMBRA_BENCH_FINGERPRINTS=1` also a hash of every result, to check that an optimisation
//! left the output unchanged.

use std::alloc::System;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, SamplingMode, Throughput};
use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};
use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::silhouette::{extract, extract_indexed, has_dark_caps, IndexedVolume, TriangleSlots, VolumeGeometry};
use umbra_geom::weld::{weld, WeldedMesh};
use umbra_geom::{load, scene, Light, Mesh};

/// Counts heap allocations, to check that a warmed-up frame allocates nothing.
#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Frames over which the heap allocations of a warmed-up extraction are counted.
const FRAMES_COUNTED: usize = 10;

fn scenes_dir() -> PathBuf {
    match std::env::var_os("UMBRA_SCENES") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    }
}

/// The benchmark scenes that are available: (name, mesh).
fn scenes() -> Vec<(&'static str, Mesh)> {
    let mut out = Vec::new();
    let sponza = scenes_dir().join("crytek-sponza.obj.gz");
    if sponza.is_file() {
        match load::load_path(&sponza) {
            Ok(m) => out.push(("sponza", m)),
            Err(e) => eprintln!("SKIPPED: sponza: {e}"),
        }
    } else {
        eprintln!("SKIPPED: sponza: {} not found (set UMBRA_SCENES)", sponza.display());
    }
    match scene::load_scene("spheres:10:1000000") {
        Ok(m) => out.push(("spheres-10-1M", m)),
        Err(e) => eprintln!("SKIPPED: spheres:10:1000000: {e}"),
    }
    out
}

/// A point light inside the bounds, at 70% of the height, slightly off the vertical axis;
/// and a directional light from above at an angle.
fn lights(mesh: &WeldedMesh) -> [(&'static str, Light); 2] {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let e = [0, 1, 2].map(|k| hi[k] - lo[k]);
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let point = [c[0] + 0.0731 * e[0], lo[1] + 0.7 * e[1], c[2] + 0.0417 * e[2], 1.0];
    [("point", point), ("directional", [0.31, 1.0, 0.17, 0.0])]
}

fn configure(group: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_millis(1500));
}

fn bench_geometry(c: &mut Criterion) {
    for (name, mesh) in scenes() {
        let welded = weld(&mesh);
        let adj = EdgeAdjacency::build(&welded);
        println!(
            "{name}: {} input triangles, {} input vertices; welded: {} triangles ({} degenerate dropped), \
             {} vertices; {} edges ({} open, {} non-manifold, at most {} opposites)",
            mesh.triangles.len(),
            mesh.positions.len(),
            welded.triangles.len(),
            welded.degenerate_triangles,
            welded.positions.len(),
            adj.len(),
            adj.open_edges(),
            adj.nonmanifold_edges(),
            adj.max_opposites()
        );

        if fingerprints() {
            println!("{name}: fingerprint weld {:016x} adjacency {:016x}", fingerprint(&welded), fingerprint(&adj));
        }

        best_of_tables(name, &mesh, &welded, &adj);

        let mut pre = c.benchmark_group(format!("{name}/preprocess"));
        configure(&mut pre);
        pre.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        pre.bench_function("weld", |b| b.iter(|| weld(black_box(&mesh))));
        pre.bench_function("meshopt_adjacency(input)", |b| {
            let adapter = vertex_adapter(&mesh.positions);
            let indices = mesh.triangles.as_flattened();
            b.iter(|| meshopt::generate_adjacency_indices(black_box(indices), &adapter))
        });
        pre.throughput(Throughput::Elements(welded.triangles.len() as u64));
        pre.bench_function("adjacency", |b| b.iter(|| EdgeAdjacency::build(black_box(&welded))));
        pre.finish();

        let slots = TriangleSlots::build(&welded, &adj).expect("the adjacency of the mesh");
        let mut frame = c.benchmark_group(format!("{name}/extract"));
        configure(&mut frame);
        frame.throughput(Throughput::Elements(adj.len() as u64));
        for (light_name, light) in lights(&welded) {
            for caps in [true, false] {
                let mut out = VolumeGeometry::default();
                extract(&welded, &adj, light, caps, &mut out);
                extract(&welded, &adj, light, caps, &mut out);
                let allocations = count_allocations(|| extract(&welded, &adj, light, caps, &mut out));
                let label = format!("{light_name}{}", if caps { "+caps" } else { "" });
                println!(
                    "{name}/{label}: {} side, {} light-cap, {} dark-cap vertices; \
                     {allocations} heap allocations in {FRAMES_COUNTED} warmed-up frames",
                    out.sides.len(),
                    out.light_caps.len(),
                    out.dark_caps.len(),
                );
                if fingerprints() {
                    println!("{name}/{label}: fingerprint {:016x}", fingerprint(&out));
                }
                frame.bench_function(label, |b| {
                    b.iter(|| extract(black_box(&welded), &adj, black_box(light), caps, &mut out))
                });
            }
            // The renderer's variant: one orientation per triangle, caps as oriented index
            // triples.
            let mut out = IndexedVolume::default();
            extract_indexed(&welded, &adj, &slots, light, true, &mut out);
            extract_indexed(&welded, &adj, &slots, light, true, &mut out);
            let allocations = count_allocations(|| extract_indexed(&welded, &adj, &slots, light, true, &mut out));
            let label = format!("{light_name}+indexed-caps");
            println!(
                "{name}/{label}: {} side vertices, {} caps ({} index bytes); \
                 {allocations} heap allocations in {FRAMES_COUNTED} warmed-up frames",
                out.sides.len(),
                out.caps.len(),
                std::mem::size_of_val(&out.caps[..]),
            );
            if fingerprints() {
                // Expanded: equal to the fingerprint of `+caps` above when the volumes agree.
                println!("{name}/{label}: fingerprint {:016x}", fingerprint(&out.expand(&welded.positions, light)));
            }
            frame.bench_function(label, |b| {
                b.iter(|| extract_indexed(black_box(&welded), &adj, &slots, black_box(light), true, &mut out))
            });
        }
        frame.finish();
    }
}

/// Heap allocations (and reallocations) of [`FRAMES_COUNTED`] calls of `frame`.
fn count_allocations(mut frame: impl FnMut()) -> usize {
    let region = Region::new(GLOBAL);
    for _ in 0..FRAMES_COUNTED {
        frame();
    }
    let change = region.change();
    change.allocations + change.reallocations
}

/// `UMBRA_BENCH_FINGERPRINTS=1` prints [`fingerprint`]s of every result (slow: seconds).
fn fingerprints() -> bool {
    std::env::var_os("UMBRA_BENCH_FINGERPRINTS").is_some_and(|v| v == "1")
}

/// A hash of a result's `Debug` form (which prints every float exactly): equal fingerprints
/// before and after an optimisation mean the same output, bit for bit in practice.
fn fingerprint<T: std::fmt::Debug>(value: &T) -> u64 {
    use std::hash::{DefaultHasher, Hasher};
    use std::io::Write;
    struct HashWriter(DefaultHasher);
    impl Write for HashWriter {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.write(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut w = HashWriter(DefaultHasher::new());
    write!(w, "{value:?}").expect("hashing never fails");
    w.0.finish()
}

/// CPU time used so far by all threads of this process, in nanoseconds (Linux: the first
/// field of `/proc/self/task/*/schedstat`); `None` elsewhere.
fn process_cpu_ns() -> Option<u64> {
    let mut total = 0;
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let stat = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        total += stat.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total)
}

/// Best (minimum) wall time and best CPU time (all threads) of `runs` calls, in
/// milliseconds. On a shared machine the minimum is the run least disturbed by other
/// processes (criterion's mean includes every disturbance), and the CPU time does not count
/// the time a thread waited for a core.
fn best_ms<R>(runs: usize, mut f: impl FnMut() -> R) -> (f64, f64) {
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..runs {
        let cpu_start = process_cpu_ns();
        let start = Instant::now();
        black_box(f());
        wall = wall.min(start.elapsed().as_secs_f64() * 1e3);
        if let (Some(a), Some(b)) = (cpu_start, process_cpu_ns()) {
            cpu = cpu.min(b.saturating_sub(a) as f64 / 1e6);
        }
    }
    (wall, cpu)
}

/// [`best_ms`] of several functions, run in turn `runs` times (one run of each per round).
fn best_ms_interleaved<const N: usize>(runs: usize, mut fs: [&mut dyn FnMut(); N]) -> [(f64, f64); N] {
    let mut best = [(f64::INFINITY, f64::INFINITY); N];
    for _ in 0..runs {
        for (f, best) in fs.iter_mut().zip(&mut best) {
            let (wall, cpu) = best_ms(1, &mut **f);
            *best = (best.0.min(wall), best.1.min(cpu));
        }
    }
    best
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map_or_else(|_| "unknown".into(), |s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// Prints the rows of the tables of `docs/benchmarks.md` (best of several runs, all in this
/// process, ours and meshopt alike).
fn best_of_tables(name: &str, mesh: &Mesh, welded: &WeldedMesh, adj: &EdgeAdjacency) {
    const PRE_RUNS: usize = 3;
    const FRAME_RUNS: usize = 10;
    println!(
        "{name}: best of {PRE_RUNS} (preprocessing) / {FRAME_RUNS} (frames) runs: best wall ms (least CPU ms, all threads); \
         load average before: {}",
        load_average()
    );
    let weld_ms = best_ms(PRE_RUNS, || weld(mesh));
    let adj_ms = best_ms(PRE_RUNS, || EdgeAdjacency::build(welded));
    let both_ms = best_ms(PRE_RUNS, || EdgeAdjacency::build(&weld(mesh)));
    let input = (mesh.triangles.as_flattened(), vertex_adapter(&mesh.positions));
    let meshopt_input_ms = best_ms(PRE_RUNS, || meshopt::generate_adjacency_indices(input.0, &input.1));
    let welded_input = (welded.triangles.as_flattened(), vertex_adapter(&welded.positions));
    let meshopt_welded_ms = best_ms(PRE_RUNS, || meshopt::generate_adjacency_indices(welded_input.0, &welded_input.1));
    let ms = |(wall, cpu): (f64, f64)| format!("{wall:.1} ({cpu:.1})");
    let mt = |tris: usize, (wall, _): (f64, f64)| tris as f64 / wall / 1e3;
    println!(
        "| {name} | {} | {} | {} | {} | {} | {:.1} | {} | {:.1} | {} | {:.2} | {} | {:.2} |",
        mesh.triangles.len(),
        welded.triangles.len(),
        adj.len(),
        ms(weld_ms),
        ms(adj_ms),
        mt(welded.triangles.len(), adj_ms),
        ms(both_ms),
        mt(mesh.triangles.len(), both_ms),
        ms(meshopt_input_ms),
        both_ms.0 / meshopt_input_ms.0,
        ms(meshopt_welded_ms),
        adj_ms.0 / meshopt_welded_ms.0,
    );
    let slots_ms = best_ms(PRE_RUNS, || TriangleSlots::build(welded, adj));
    println!("{name}: triangle slots (per-mesh preprocessing of the indexed variant): {}", ms(slots_ms));
    let slots = TriangleSlots::build(welded, adj).expect("the adjacency of the mesh");
    let (mut vertices, mut indexed, mut sides) =
        (VolumeGeometry::default(), IndexedVolume::default(), VolumeGeometry::default());
    for (light_name, light) in lights(welded) {
        // The three outputs interleaved run by run, so that a change of load hits them alike.
        let [vertex_ms, indexed_ms, sides_ms] = best_ms_interleaved(
            FRAME_RUNS,
            [
                &mut || extract(welded, adj, light, true, &mut vertices),
                &mut || extract_indexed(welded, adj, &slots, light, true, &mut indexed),
                &mut || extract(welded, adj, light, false, &mut sides),
            ],
        );
        let dark = if has_dark_caps(light) { 2 } else { 1 };
        let rows = [
            (
                "sides + caps (vertex copies)",
                vertex_ms,
                vertices.sides.len(),
                (vertices.light_caps.len() + vertices.dark_caps.len()) / 3,
            ),
            ("sides + caps (indexed)", indexed_ms, indexed.sides.len(), dark * indexed.caps.len()),
            ("sides", sides_ms, sides.sides.len(), 0),
        ];
        for (output, frame_ms, side_vertices, cap_tris) in rows {
            println!(
                "| {name} | {light_name} | {output} | {} | {} | {cap_tris} | {} | {:.1} | {:.1} | {:.2} |",
                adj.len(),
                side_vertices / 3,
                ms(frame_ms),
                adj.len() as f64 / frame_ms.0 / 1e3,
                adj.len() as f64 / (frame_ms.1 / 2.0) / 1e3,
                frame_ms.0 / vertex_ms.0,
            );
        }
    }
    println!("{name}: load average after: {}", load_average());
}

fn vertex_adapter(positions: &[[f32; 3]]) -> meshopt::VertexDataAdapter<'_> {
    meshopt::VertexDataAdapter::new(meshopt::typed_to_bytes(positions), std::mem::size_of::<[f32; 3]>(), 0)
        .expect("[f32; 3] positions are a whole number of 12-byte vertices")
}

criterion_group!(benches, bench_geometry);
criterion_main!(benches);
