//! `umbra bench` as users run it: JSON keys, interleaving order (the hidden `--trace-order`
//! hook), fly-through errors naming file and line, CSV and SVG outputs, shadow-map options and
//! errors, suites.

use std::path::PathBuf;

mod common;
use common::*;

fn tmp(name: &str) -> PathBuf {
    tmp_dir("bench").join(name)
}

const SMALL: [&str; 6] = ["--scene", "default", "--size", "64x48", "--warmup", "1"];

#[test]
fn json_has_one_object_per_method_with_the_contract_keys() {
    let mut args = vec!["bench", "--json", "--methods", "none,cpu-silhouette", "--frames", "3"];
    args.extend(SMALL);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let rows = v.as_array().expect("array");
    assert_eq!(rows.len(), 2);
    for (row, name) in rows.iter().zip(["none", "cpu-silhouette"]) {
        assert_eq!(row["method"], name);
        assert_eq!(row["frames"], 3);
        for key in ["mean_ms", "median_ms", "p95_ms"] {
            let x = row[key].as_f64().unwrap_or_else(|| panic!("{key} is a number: {row}"));
            assert!(x > 0.0 && x.is_finite(), "{key} = {x}");
        }
        let (mean, p95) = (row["mean_ms"].as_f64().unwrap_or(0.0), row["p95_ms"].as_f64().unwrap_or(0.0));
        assert!(p95 >= mean * 0.999 || row["frames"] == 1, "p95 {p95} below mean {mean}?");
        let stages = row["stages"].as_object().expect("stages object");
        for s in ["depth+ambient", "lighting"] {
            assert!(
                stages.get(s).and_then(|x| x.as_f64()).is_some_and(|x| x >= 0.0),
                "{name}: stage {s} in {stages:?}"
            );
        }
        assert!(row["gpu_bytes"].is_u64(), "{row}");
        assert!(row.get("error").is_none(), "{row}");
    }
    // cpu-silhouette reports its own stages and holds a vertex buffer.
    let cpu = &rows[1];
    for s in ["silhouette", "sides", "caps"] {
        assert!(cpu["stages"].get(s).is_some(), "{s} missing: {}", cpu["stages"]);
    }
    assert!(cpu["gpu_bytes"].as_u64().unwrap_or(0) > 0);
    assert!(rows[0]["stages"].get("silhouette").is_none(), "none has no silhouette stage");
}

/// The volume passes' work: `volume_cull`, `volume_fragments` (fragment-shader invocations,
/// counted in the stage-timed rounds), `volume_triangles` and `volume_edges`, for
/// cpu-silhouette (culled on the CPU) and cs-silhouette (culled on the GPU, its counts read
/// back) both ways; on the shared Sponza view the cull draws fewer triangles, edges and
/// fragments (a count of the algorithm's work, not a timing). `none` draws no volume
/// fragments and reports no triangles.
#[test]
fn volume_counts_are_reported_both_ways() {
    let rows = |scene: &[&str], cull: &str| {
        let methods = "cpu-silhouette,none,cs-silhouette";
        let mut args = vec!["bench", "--json", "--methods", methods, "--frames", "1", "--warmup", "0"];
        args.extend(["--stage-every", "1", "--size", "160x90", "--volume-cull", cull]);
        args.extend(scene);
        let o = umbra(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&o).as_array().expect("array").clone()
    };
    let on = rows(&["--scene", "default"], "on");
    let off = rows(&["--scene", "default"], "off");
    for m in [0, 2] {
        assert_eq!(on[m]["volume_cull"], true, "{}", on[m]);
        assert_eq!(off[m]["volume_cull"], false, "{}", off[m]);
    }
    for row in [&on[0], &off[0], &on[2], &off[2]] {
        for key in ["volume_fragments", "volume_triangles", "volume_edges"] {
            let x = row[key].as_f64().unwrap_or_else(|| panic!("{key} in {row}"));
            assert!(x > 0.0, "{key} = {x}");
        }
    }
    assert_eq!(on[1]["volume_fragments"].as_f64(), Some(0.0), "none: {}", on[1]);
    assert!(on[1].get("volume_triangles").is_none(), "none: {}", on[1]);
    assert_eq!(on[1]["volume_cull"], false);
    let dir = std::env::var("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    let sponza = dir.join("crytek-sponza.obj.gz");
    if !sponza.is_file() {
        eprintln!("SKIPPED: {} not found", sponza.display());
        return;
    }
    let sponza = sponza.to_string_lossy().to_string();
    let scene = ["--scene", sponza.as_str()];
    let (on, off) = (rows(&scene, "on"), rows(&scene, "off"));
    for m in [0, 2] {
        let f = |rows: &[serde_json::Value], key: &str| rows[m][key].as_f64().unwrap_or(f64::NAN);
        for key in ["volume_fragments", "volume_triangles", "volume_edges"] {
            assert!(
                f(&on, key) < f(&off, key),
                "{}: {key}: culled {} against {}",
                on[m]["method"],
                f(&on, key),
                f(&off, key)
            );
        }
    }
}

/// `volume_fragments` names the query that counted it (`volume_fragments_query`), and is
/// counted only in extra frames of the stage-timed rounds: absent with `--stage-every 0` (no
/// stall in any run without them) and for a method without a volume pass (hier-triangle).
#[test]
fn volume_fragments_name_their_query() {
    let rows = |every: &str| {
        let mut args = vec!["bench", "--json", "--methods", "cpu-silhouette,hier-triangle", "--frames", "2"];
        args.extend(["--stage-every", every]);
        args.extend(SMALL);
        let o = umbra(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&o).as_array().expect("array").clone()
    };
    let counted = rows("1");
    let cpu = &counted[0];
    assert_eq!(cpu["volume_cull"], true, "{cpu}");
    assert!(cpu["volume_fragments"].as_f64().is_some_and(|f| f > 0.0), "{cpu}");
    let query = cpu["volume_fragments_query"].as_str();
    assert!(matches!(query, Some("fragment_shader_invocations" | "samples_passed")), "{cpu}");
    assert_eq!(counted[1]["volume_cull"], false, "{}", counted[1]);
    let uncounted = rows("0");
    for key in ["volume_fragments", "volume_fragments_query"] {
        assert!(counted[1].get(key).is_none(), "hier-triangle has no volume pass: {}", counted[1]);
        assert!(uncounted[0].get(key).is_none(), "{key} counted without stage-timed rounds: {}", uncounted[0]);
    }
}

/// The hier methods' work counts: a "work" object with the four counts (mean per counted
/// frame) in their JSON rows and columns of the table; no "work" for a method without counts.
#[test]
fn work_counts_are_reported_for_the_hier_methods_only() {
    let mut args = vec!["bench", "--json", "--methods", "none,hier-triangle", "--frames", "2", "--stage-every", "1"];
    args.extend(SMALL);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let rows = v.as_array().expect("array");
    assert!(rows[0].get("work").is_none(), "none counts no work: {}", rows[0]);
    let work = rows[1]["work"].as_object().expect("hier-triangle's work object");
    for key in ["dispatches", "nodes_tested", "leaves_tested", "nodes_pruned"] {
        let x = work.get(key).and_then(|x| x.as_f64()).unwrap_or_else(|| panic!("{key} in {work:?}"));
        assert!(x >= 0.0 && x.is_finite(), "{key} = {x}");
    }
    let count = |k: &str| work[k].as_f64().unwrap_or(0.0);
    assert!(count("dispatches") > 0.0 && count("nodes_tested") > 0.0, "{work:?}");
    assert!(count("nodes_pruned") <= count("nodes_tested"), "{work:?}");
    let mut table = vec!["bench", "--methods", "none,hier-triangle", "--frames", "1", "--stage-every", "1"];
    table.extend(SMALL);
    let o = umbra(&table);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("| nodes_tested |") && out.contains("| dispatches |"), "{out}");
}

#[test]
fn methods_are_interleaved_frame_by_frame_after_the_warmup() {
    let o = umbra(&[
        "bench",
        "--scene",
        "box",
        "--size",
        "32x24",
        "--methods",
        "none,cpu-silhouette,shadow-map-cube:64",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--stage-every",
        "0",
        "--json",
        "--trace-order",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let order: Vec<String> =
        stderr(&o).lines().filter_map(|l| l.strip_prefix("bench-order ")).map(str::to_string).collect();
    let expected: Vec<String> = [
        "warmup 0 none",
        "warmup 0 cpu-silhouette",
        "warmup 0 shadow-map-cube:64",
        "frame 0 none",
        "frame 0 cpu-silhouette",
        "frame 0 shadow-map-cube:64",
        "frame 1 none",
        "frame 1 cpu-silhouette",
        "frame 1 shadow-map-cube:64",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    assert_eq!(order, expected);
    // --stage-every 0: no stage timing at all.
    let v = json(&o);
    assert!(v.as_array().expect("array").iter().all(|r| r["stages"].as_object().is_some_and(|s| s.is_empty())), "{v}");
}

#[test]
fn flythrough_errors_name_the_file_and_line() {
    let bad = tmp("bad.flythrough");
    std::fs::write(&bad, "# path\n0 5 10  0 0 0\n1 5 10  0 0\n").expect("write");
    let o = umbra(&[
        "bench",
        "--scene",
        "box",
        "--size",
        "32x24",
        "--frames",
        "2",
        "--flythrough",
        bad.to_str().expect("utf8"),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains(&format!("{}:3:", bad.display())) && e.contains("expected 6 numbers"), "{e}");

    let nan = tmp("nan.flythrough");
    std::fs::write(&nan, "0 5 10 0 0 0\n\n0 5 ten 0 0 0\n").expect("write");
    let o = umbra(&[
        "bench",
        "--scene",
        "box",
        "--size",
        "32x24",
        "--frames",
        "2",
        "--flythrough",
        nan.to_str().expect("utf8"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(&format!("{}:3:", nan.display())), "{}", stderr(&o));

    let o = umbra(&["bench", "--scene", "box", "--flythrough", "/nonexistent/path.flythrough"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/path.flythrough"), "{}", stderr(&o));
}

#[test]
fn a_flythrough_file_drives_the_camera_and_outputs_are_written() {
    let fly = tmp("good.flythrough");
    std::fs::write(&fly, "# eye target\n-4 3 6  0 0.5 0\n4, 3, 6, 0, 0.5, 0\n4 3 -6 0 0.5 0\n").expect("write");
    let csv = tmp("out.csv");
    let svg = tmp("out.svg");
    let stages_svg = tmp("out-stages.svg");
    for p in [&csv, &svg, &stages_svg] {
        let _ = std::fs::remove_file(p);
    }
    let mut args = vec![
        "bench",
        "--methods",
        "none,cpu-silhouette",
        "--frames",
        "4",
        "--flythrough",
        fly.to_str().expect("utf8"),
        "--csv",
        csv.to_str().expect("utf8"),
        "--plot",
        svg.to_str().expect("utf8"),
    ];
    args.extend(SMALL);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("| none |") && text.contains("| cpu-silhouette |"), "{text}");
    let csv_text = std::fs::read_to_string(&csv).expect("csv written");
    let mut lines = csv_text.lines();
    assert_eq!(lines.next(), Some("scene,width,height,method,frame,kind,name,ms"));
    let frames = csv_text.lines().filter(|l| l.contains(",frame,total,")).count();
    assert_eq!(frames, 8, "4 frames x 2 methods:\n{csv_text}");
    assert!(csv_text.lines().any(|l| l.starts_with("default,64,48,cpu-silhouette,") && l.contains(",stage,sides,")));
    for p in [&svg, &stages_svg] {
        let s = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert!(s.starts_with("<svg") && s.contains("cpu-silhouette"), "{}", p.display());
    }
}

#[test]
fn shadow_map_options_and_errors() {
    let mut args = vec![
        "bench",
        "--json",
        "--methods",
        "none,shadow-map-cube:128,shadow-map-cube:99999999",
        "--frames",
        "1",
        "--sm-bias",
        "2,1",
        "--sm-pcf",
    ];
    args.extend(SMALL);
    let o = umbra(&args);
    assert!(o.status.success(), "a failing method is reported, not fatal: {}", stderr(&o));
    let v = json(&o);
    let rows = v.as_array().expect("array");
    assert_eq!(rows[1]["method"], "shadow-map-cube:128");
    assert_eq!(rows[1]["gpu_bytes"], 6 * 128 * 128 * 4);
    assert!(rows[1]["stages"].get("shadow-map").is_some(), "{}", rows[1]);
    let err = rows[2]["error"].as_str().expect("error recorded");
    assert!(err.contains("GL_MAX_CUBE_MAP_TEXTURE_SIZE"), "{err}");
    assert_eq!(rows[2]["frames"], 0);
    assert!(rows[2]["mean_ms"].is_null());
    assert_eq!(rows[0]["frames"], 1, "the other methods still ran");

    for bad in ["x", "1,2,3", "-1"] {
        let o = umbra(&["bench", "--scene", "box", "--sm-bias", bad]);
        assert_eq!(o.status.code(), Some(2), "--sm-bias {bad}");
        assert!(stderr(&o).contains("--sm-bias"), "{}", stderr(&o));
    }
    let o = umbra(&["bench", "--scene", "box", "--methods", "shadow-map-cube:zero"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("shadow-map-cube:zero"), "{}", stderr(&o));
}

#[test]
fn suites_are_listed_and_unknown_ones_rejected() {
    let o = umbra(&["bench", "--suite", "list"]);
    assert!(o.status.success());
    for s in ["001-spheres", "001-objects", "001-vs-sm", "001-overall", "003-scenes", "003-stages"] {
        assert!(stdout(&o).contains(s), "{s}");
    }
    let o = umbra(&["bench", "--suite", "999-nothing"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("001-spheres"), "{}", stderr(&o));
}

/// A reduced suite run end to end: the first sphere count of Table 3 with one method.
#[test]
fn a_reduced_suite_run_prints_its_table() {
    let o = umbra(&[
        "bench",
        "--suite",
        "001-spheres",
        "--runs",
        "1",
        "--methods",
        "cpu-silhouette",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--size",
        "64x48",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("## 001-spheres") && s.contains("| 32400 |") && s.contains("cpu-silhouette"), "{s}");
}

/// ray-bvh's rows carry its BVH's figures (its own keys, within `gpu_bytes`) and its stages;
/// other methods' rows carry none of them.
#[test]
fn ray_bvh_rows_report_the_bvh() {
    let mut args = vec!["bench", "--json", "--methods", "cpu-silhouette,ray-bvh", "--frames", "1"];
    args.extend(SMALL);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    let rows = v.as_array().expect("array");
    let (cpu, ray) = (&rows[0], &rows[1]);
    assert_eq!(ray["method"], "ray-bvh");
    for key in ["bvh_build_ms", "bvh_bytes", "bvh_nodes", "bvh_depth"] {
        assert!(ray[key].as_f64().is_some_and(|x| x >= 0.0), "{key} in {ray}");
        assert!(cpu.get(key).is_none(), "{key} in cpu-silhouette's row");
    }
    let bvh = ray["bvh_bytes"].as_f64().unwrap_or(0.0);
    assert!(bvh > 0.0 && bvh <= ray["gpu_bytes"].as_f64().unwrap_or(0.0), "{ray}");
    for s in ["samples", "rays", "resume", "stencil"] {
        assert!(ray["stages"].get(s).is_some(), "{s} missing: {}", ray["stages"]);
    }
}
