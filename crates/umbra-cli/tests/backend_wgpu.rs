//! `--backend wgpu` as users run it: render, verify, bench and info on umbra-wgpu, the flag's
//! errors, and the GL default unchanged. Skipped with a message when no Vulkan/Metal/DX12
//! adapter exists (CI installs Mesa's lavapipe, so they run there).

use std::path::PathBuf;

mod common;
use common::*;

fn tmp(name: &str) -> PathBuf {
    tmp_dir("cli-wgpu").join(name)
}

/// Whether a wgpu adapter exists (else the test prints why it is skipped).
fn adapter() -> bool {
    let o = umbra(&["info", "--backend", "wgpu"]);
    if o.status.success() {
        return true;
    }
    let e = stderr(&o);
    assert!(e.contains("adapter found"), "info --backend wgpu failed for another reason: {e}");
    eprintln!("SKIPPED: {e}");
    false
}

#[test]
fn info_prints_the_adapter_and_needs_a_scene_or_a_backend() {
    let o = umbra(&["info"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("SCENE, or --backend"), "{}", stderr(&o));
    let o = umbra(&["info", "box", "--backend", "vulkan"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--backend: expected gl or wgpu"), "{}", stderr(&o));
    if !adapter() {
        return;
    }
    let o = umbra(&["info", "--backend", "wgpu"]);
    let text = stdout(&o);
    assert!(text.starts_with("adapter ") && text.contains("depth clamp           yes"), "{text}");
    let o = umbra(&["info", "box", "--backend", "wgpu", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["triangles"], 12, "the statistics keys are unchanged");
    assert!(v["device"]["adapter"].as_str().is_some_and(|s| !s.is_empty()), "{v}");
    assert!(v["device"]["methods"].as_str().unwrap().contains("cs-silhouette"));
}

#[test]
fn verify_every_wgpu_method_is_exact() {
    if !adapter() {
        return;
    }
    let o = umbra(&["verify", "--backend", "wgpu", "--size", "160x120", "--light", "0.6,3,0.4", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = json(&o);
    let names: Vec<&str> = rows.as_array().unwrap().iter().map(|r| r["method"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "none",
            "cpu-silhouette",
            "vs-silhouette",
            "cs-silhouette",
            "shadow-map-cube:1024",
            "shadow-map-cube:2048",
            "ray-bvh"
        ]
    );
    for r in rows.as_array().unwrap() {
        assert_eq!(r["backend"], "wgpu");
        let name = r["method"].as_str().unwrap();
        if name.ends_with("silhouette") {
            assert_eq!(r["mismatches_outside_band"], 0, "{name}: {r}");
            assert_eq!(r["counter"], "stencil8");
        }
        if name == "ray-bvh" {
            assert_eq!(r["mismatches_outside_band"], 0, "{name}: {r}");
        }
        assert!(r["samples"].as_u64().unwrap() > 1000, "{r}");
    }
    // `none` is measured, not failed, and does miss the shadow.
    assert!(rows[0]["mismatches"].as_u64().unwrap() > 0);
}

#[test]
fn render_matches_the_gl_backend() {
    if !adapter() {
        return;
    }
    let (gl, wgpu) = (tmp("gl.png"), tmp("wgpu.png"));
    for (backend, out) in [("gl", &gl), ("wgpu", &wgpu)] {
        let o = umbra(&[
            "render",
            "--backend",
            backend,
            "--method",
            "cs-silhouette",
            "--size",
            "200x150",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{backend}: {}", stderr(&o));
    }
    let read = |p: &PathBuf| {
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        (info.width, info.height, buf)
    };
    let (a, b) = (read(&gl), read(&wgpu));
    assert_eq!((a.0, a.1), (b.0, b.1));
    // The same samples, shadows and shading arithmetic: equal up to the rounding of the
    // lighting shader's arithmetic (GLSL and WGSL compile it separately), one step at most.
    let worst = a.2.iter().zip(&b.2).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    assert!(worst <= 1, "largest channel difference {worst}");
}

#[test]
fn backend_errors_say_what_to_do() {
    let o = umbra(&["render", "--backend", "metal", "--out", tmp("x.png").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--backend: expected gl or wgpu, got \"metal\""), "{}", stderr(&o));
    if !adapter() {
        return;
    }
    // A method wgpu cannot express.
    let o = umbra(&["verify", "--backend", "wgpu", "--method", "ts-silhouette", "--size", "32x24"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("geometry or tessellation shaders: --backend gl"), "{}", stderr(&o));
    // The wide counter is GL's.
    let o = umbra(&["render", "--backend", "wgpu", "--counter", "float32", "--size", "32x24"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("8-bit stencil only") && stderr(&o).contains("--backend gl"), "{}", stderr(&o));
    // `--method help` lists the wgpu methods.
    let o = umbra(&["render", "--backend", "wgpu", "--method", "help"]);
    assert!(stdout(&o).lines().any(|l| l == "vs-silhouette") && !stdout(&o).contains("gs-silhouette"));
}

#[test]
fn bench_runs_a_short_wgpu_measurement() {
    if !adapter() {
        return;
    }
    let o = umbra(&[
        "bench",
        "--backend",
        "wgpu",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--size",
        "96x64",
        "--methods",
        "cs-silhouette,shadow-map-cube:256",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = json(&o);
    for r in rows.as_array().unwrap() {
        assert_eq!(r["backend"], "wgpu");
        assert_eq!(r["frames"], 2);
        assert!(r["mean_ms"].as_f64().unwrap() > 0.0);
        assert!(r["error"].is_null(), "{r}");
    }
    assert_eq!(rows[1]["counter"], "none", "a shadow map does not count");
    let o = umbra(&["bench", "--backend", "wgpu", "--suite", "001-spheres"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("gl backend only"));
}

#[test]
fn bench_interleaves_gl_and_wgpu_in_one_run() {
    if !adapter() {
        return;
    }
    let o = umbra(&[
        "bench",
        "--backend",
        "gl,wgpu",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--size",
        "64x48",
        "--methods",
        "cs-silhouette",
        "--trace-order",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = json(&o);
    let got: Vec<(&str, &str)> = rows
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["method"].as_str().unwrap(), r["backend"].as_str().unwrap()))
        .collect();
    assert_eq!(got, [("cs-silhouette", "gl"), ("cs-silhouette", "wgpu")]);
    // Both have stages: GL's timestamp marks, wgpu's timestamps at its passes' boundaries
    // (lavapipe has timestamp queries inside encoders); culled by default, so wgpu's frame
    // submits its depth first (`receivers`) and culls in `prepare`.
    assert!(!rows[0]["stages"].as_object().unwrap().is_empty());
    let stages: Vec<&String> = rows[1]["stages"].as_object().unwrap().keys().collect();
    assert_eq!(stages, ["depth+ambient", "lighting", "prepare", "receivers", "volumes"], "{}", rows[1]);
    let order: Vec<String> = stderr(&o).lines().filter(|l| l.starts_with("bench-order")).map(str::to_string).collect();
    assert_eq!(
        order,
        [
            "bench-order warmup 0 cs-silhouette@gl",
            "bench-order warmup 0 cs-silhouette@wgpu",
            "bench-order frame 0 cs-silhouette@gl",
            "bench-order frame 0 cs-silhouette@wgpu",
            "bench-order frame 1 cs-silhouette@gl",
            "bench-order frame 1 cs-silhouette@wgpu",
        ],
        "frame by frame, one backend after the other"
    );
    let o = umbra(&["bench", "--backend", "wgpu,wgpu", "--frames", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("expected gl, wgpu or gl,wgpu"), "{}", stderr(&o));
}

/// `bench --backend wgpu --volume-cull both`: cpu-silhouette and cs-silhouette run culled and
/// as `NAME@cull-off` in one schedule; every row reports `volume_triangles` and
/// `volume_edges` (cs-silhouette's read back from the GPU), and `volume_fragments` where the
/// adapter has pipeline statistics (lavapipe does): the culled row's include its receiver
/// map's scatter, the unculled rows' are equal (the same volume). The culled rows have the
/// `receivers` stage.
/// `verify --backend wgpu` is exact both ways.
#[test]
fn volume_cull_on_wgpu_both_ways() {
    if !adapter() {
        return;
    }
    let mut args =
        vec!["bench", "--backend", "wgpu", "--json", "--methods", "cpu-silhouette,cs-silhouette", "--frames", "1"];
    args.extend(["--warmup", "0", "--stage-every", "1", "--volume-cull", "both", "--size", "96x64"]);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = json(&o);
    let rows = rows.as_array().expect("array");
    assert_eq!(rows.len(), 4, "{rows:?}");
    let (on, off, cs_on, cs) = (&rows[0], &rows[1], &rows[2], &rows[3]);
    for (row, method, cull) in [
        (on, "cpu-silhouette", true),
        (off, "cpu-silhouette", false),
        (cs_on, "cs-silhouette", true),
        (cs, "cs-silhouette", false),
    ] {
        assert_eq!(row["method"], method, "{row}");
        assert_eq!(row["volume_cull"].as_bool(), Some(cull), "{row}");
        assert!(row["volume_triangles"].as_f64().unwrap_or(0.0) > 0.0, "{row}");
        assert!(row["volume_edges"].as_f64().unwrap_or(0.0) > 0.0, "{row}");
        assert_eq!(row["stages"].get("receivers").is_some(), cull, "{row}");
    }
    if let Some(unculled) = off["volume_fragments"].as_f64() {
        assert_eq!(off["volume_fragments_query"], "fragment_shader_invocations", "{off}");
        assert_eq!(cs["volume_fragments"].as_f64(), Some(unculled), "the same volume: {cs}");
        // Nothing of the default scene is dropped: culled, the scatter comes on top.
        let culled = on["volume_fragments"].as_f64().expect("counted both ways");
        assert!(culled > unculled, "culled {culled} against {unculled}");
    } else {
        eprintln!("no pipeline statistics on this adapter: volume_fragments absent");
    }
    for (method, cull) in ["cpu-silhouette", "cs-silhouette"].iter().flat_map(|m| [(*m, "on"), (*m, "off")]) {
        let mut args = vec!["verify", "--backend", "wgpu", "--method", method, "--json", "--volume-cull", cull];
        args.extend(["--size", "96x64"]);
        let o = umbra(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(json(&o)[0]["mismatches_outside_band"], 0, "{method} --volume-cull {cull}");
    }
}
