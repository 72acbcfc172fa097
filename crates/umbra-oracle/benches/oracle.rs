//! Oracle benchmarks on Crytek Sponza (skipped with a message when the scene is absent):
//! BVH build, and the full reference (one shadow ray per pixel, 1280x720) for a point and a
//! directional light. The samples are synthetic: primary rays cast with `Bvh::intersect` from
//! a camera in the atrium (bench only; `umbra verify` uses the GPU's rasterized samples).

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use umbra_oracle::synthetic::{primary_samples, PinholeCamera};
use umbra_oracle::{reference, Bvh, Samples};

fn scene_path(name: &str) -> PathBuf {
    let dir = std::env::var_os("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    dir.join(name)
}

fn sponza(c: &mut Criterion) {
    let path = scene_path("crytek-sponza.obj.gz");
    if !path.exists() {
        println!("SKIP: {} not found (set UMBRA_SCENES)", path.display());
        return;
    }
    let mesh = match umbra_geom::load::load_path(&path) {
        Ok(m) => m,
        Err(e) => {
            println!("SKIP: {e}");
            return;
        }
    };
    let welded = umbra_geom::weld::weld(&mesh);
    let mut group = c.benchmark_group("sponza");
    group.sample_size(10);
    group.bench_function("bvh_build", |b| b.iter(|| Bvh::build(&welded.positions, &welded.triangles).unwrap()));
    let bvh = Bvh::build(&welded.positions, &welded.triangles).unwrap();
    let camera = PinholeCamera {
        eye: [-8.2, 1.5, -0.1],
        target: [5.0, 2.5, 0.3],
        up: [0.0, 1.0, 0.0],
        fov_y: 60f32.to_radians(),
        width: 1280,
        height: 720,
    };
    let (pos, tri) = primary_samples(&bvh, &camera);
    let samples = Samples { width: 1280, height: 720, world_pos: &pos, triangle: &tri };
    for (name, light) in [
        ("reference_point_1280x720", [0.0f32, 6.0, 0.0, 1.0]),
        ("reference_directional_1280x720", [0.3, 1.0, 0.2, 0.0]),
    ] {
        group.bench_function(name, |b| b.iter(|| reference(&welded, &bvh, &samples, light, camera.eye).unwrap()));
    }
    group.bench_function("primary_rays_1280x720", |b| b.iter(|| primary_samples(&bvh, &camera)));
    group.finish();
}

criterion_group!(benches, sponza);
criterion_main!(benches);
