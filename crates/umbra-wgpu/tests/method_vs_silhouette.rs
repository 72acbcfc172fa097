//! vs-silhouette on wgpu: paper 003's fixed-size records read the orientations of the
//! orientation pass; an edge with more opposite vertices than `maxMult` is split into records
//! whose opposite-signed sides must cancel exactly. Checked against cpu-silhouette's stencil,
//! value for value, for point and directional lights under z-fail and z-pass.

mod common;

use std::sync::Arc;

use common::*;
use umbra_geom::sides_data::{choose_max_mult, MAX_MULT_LIMIT};
use umbra_geom::{weld::weld, EdgeAdjacency, Mesh};
use umbra_wgpu::methods::vs_silhouette::records;
use umbra_wgpu::FrameParams;

/// A fan of `pages` triangles around one spine, alternately wound (multiplicities of both
/// signs within one edge), over a ground plane, next to a sphere.
fn book_scene(pages: usize) -> Mesh {
    let mut m = umbra_geom::scene::uv_sphere([-1.5, 2.0, 0.0], 0.8, 24, 12);
    let base = m.positions.len() as u32;
    m.positions.extend_from_slice(&[[1.0, 1.5, -0.8], [1.0, 1.5, 0.8]]);
    for k in 0..pages {
        let a = std::f32::consts::PI * (0.1 + 0.8 * k as f32 / pages as f32);
        m.positions.push([1.0 + 0.9 * a.cos(), 1.5 + 0.9 * a.sin(), 0.3 * (k % 3) as f32 - 0.3]);
        let o = base + 2 + k as u32;
        m.triangles.push(if k % 3 == 0 { [base + 1, base, o] } else { [base, base + 1, o] });
    }
    m.append(&umbra_geom::scene::ground_plane([0.0, 0.0, 0.0], 10.0));
    m
}

#[test]
fn split_records_cancel_and_stencil_equals_cpu_silhouette() {
    let Some(gpu) = gpu() else { return };
    let mesh = Arc::new(weld(&book_scene(40)));
    let adj = EdgeAdjacency::build(&mesh);
    let max_mult = choose_max_mult(&adj, MAX_MULT_LIMIT);
    let recs = records(&adj, max_mult);
    assert!(recs.iter().any(|r| r[3] >> 8 != 0), "the spine is split into several records");
    assert_eq!(recs.len(), umbra_geom::sides_data::record_count(&adj, max_mult), "the records of paper 003's layout");
    let lights = vec![[2.5, 5.0, 0.4, 1.0], [-0.6, 1.0, 0.2, 0.0], [1.0, 1.5, 5.0, 1.0]];
    for zpass in [false, true] {
        let p = FrameParams { zpass, auto_zpass: false, ..params(default_camera(), lights.clone(), 240, 180) };
        let cpu = render_once(&gpu, &mesh, "cpu-silhouette", &p);
        let vs = render_once(&gpu, &mesh, "vs-silhouette", &p);
        for (i, (e, a)) in cpu.stencil.iter().zip(&vs.stencil).enumerate() {
            assert!(e.image.pixels.iter().any(|&v| v != 0), "light {i} casts a visible shadow");
            let differing = e.image.pixels.iter().zip(&a.image.pixels).filter(|(x, y)| x != y).count();
            assert_eq!(differing, 0, "light {i}, zpass {zpass}: stencil values differ from cpu-silhouette's");
        }
    }
}
