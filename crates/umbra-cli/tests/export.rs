//! `umbra export`: paper 003's preprocessed scene for the WebGL 2 viewer. The
//! manifest's sizes are Eq. 8 / Eq. 9 and agree with `umbra info --json`; every file has
//! exactly the stated size; the buffers are what vs-silhouette builds; a truncated or
//! malformed export is refused by `umbra export --check` with an error naming the file and the
//! JSON path; Crytek Sponza exports in seconds (UMBRA_SCENES, skipped when absent).

use std::path::{Path, PathBuf};
use std::time::Instant;

mod common;
use common::*;

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("export").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn export(scene: &str, dir: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["export", scene, "--out", dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = umbra(&args);
    assert!(o.status.success(), "umbra export {scene}: {}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest.json");
    serde_json::from_str(&text).expect("manifest is JSON")
}

fn info(scene: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", scene, "--json"];
    args.extend_from_slice(extra);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("info JSON")
}

const BUFFERS: [&str; 6] = ["positions", "normals", "indices", "sides_data", "caps_data", "edge_triangles"];

/// Sizes: Eq. 8 / Eq. 9, `umbra info --json`, and the files on disk, exactly.
fn check_sizes(scene: &str, dir: &Path, m: &serde_json::Value, info: &serde_json::Value) {
    let u = |v: &serde_json::Value| v.as_u64().unwrap_or_else(|| panic!("{scene}: not a number: {v}"));
    let (max_mult, records, t) =
        (u(&m["max_mult"]), u(&m["counts"]["sides_data_records"]), u(&m["counts"]["triangles"]));
    assert_eq!(u(&m["sides_data_bytes"]), 16 * (2 + max_mult) * records, "{scene}: Eq. 8");
    assert_eq!(u(&m["caps_data_bytes"]), 48 * t, "{scene}: Eq. 9");
    assert_eq!(m["sides_data_bytes"], info["sides_data_bytes"], "{scene}: info --json sides_data_bytes");
    assert_eq!(m["caps_data_bytes"], info["caps_data_bytes"], "{scene}: info --json caps_data_bytes");
    assert_eq!(m["max_mult"], info["max_mult"], "{scene}");
    assert_eq!(m["counts"]["sides_data_records"], info["sides_data_records"], "{scene}");
    assert_eq!(m["counts"]["vertices"], info["vertices"], "{scene}");
    assert_eq!(m["counts"]["edges"], info["edges"], "{scene}");
    assert_eq!(m["buffers"]["sides_data"]["bytes"], m["sides_data_bytes"], "{scene}");
    assert_eq!(m["buffers"]["caps_data"]["bytes"], m["caps_data_bytes"], "{scene}");
    let v = u(&m["counts"]["vertices"]);
    for (name, bytes) in
        BUFFERS.iter().zip([12 * v, 12 * t, 12 * t, 16 * (2 + max_mult) * records, 48 * t, 4 * max_mult * records])
    {
        let b = &m["buffers"][name];
        assert_eq!(u(&b["bytes"]), bytes, "{scene}: {name}");
        assert_eq!(u(&b["offset"]), 0, "{scene}: {name}");
        let file = dir.join(b["file"].as_str().unwrap());
        assert_eq!(
            std::fs::metadata(&file).unwrap().len(),
            bytes,
            "{scene}: {} has exactly the stated size",
            file.display()
        );
    }
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

#[test]
fn box_export_sizes_contents_and_check() {
    let dir = tmp("box");
    let m = export("box", &dir, &[]);
    assert_eq!(m["format"], "umbra-export");
    assert_eq!(m["version"], 2);
    check_sizes("box", &dir, &m, &info("box", &[]));
    // The cube: 8 vertices, 12 triangles, 18 edges of 2 opposites each: maxMult 2, 18 records.
    assert_eq!(m["counts"]["vertices"], 8);
    assert_eq!(m["counts"]["triangles"], 12);
    assert_eq!(m["max_mult"], 2);
    // Contents: every edge record holds A, B (w = count 2, split 0) and two opposites (w = 1);
    // every caps record is three of the positions with w = 1; normals are unit.
    let pos = f32s(&std::fs::read(dir.join("positions.bin")).unwrap());
    let is_vertex = |p: &[f32]| pos.chunks_exact(3).any(|q| q == &p[..3]);
    let sides = f32s(&std::fs::read(dir.join("sides.bin")).unwrap());
    for rec in sides.chunks_exact(16) {
        assert_eq!((rec[3], rec[7], rec[11], rec[15]), (2.0, 0.0, 1.0, 1.0), "record {rec:?}");
        for k in 0..4 {
            assert!(is_vertex(&rec[4 * k..4 * k + 3]), "record vertex {k} is a mesh vertex");
        }
    }
    let caps = f32s(&std::fs::read(dir.join("caps.bin")).unwrap());
    let idx: Vec<u32> = std::fs::read(dir.join("indices.bin"))
        .unwrap()
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    for (t, tri) in idx.chunks_exact(3).enumerate() {
        for k in 0..3 {
            let p = &pos[3 * tri[k] as usize..3 * tri[k] as usize + 3];
            assert_eq!(&caps[12 * t + 4 * k..12 * t + 4 * k + 3], p, "caps-data = the triangle's vertices in order");
            assert_eq!(caps[12 * t + 4 * k + 3], 1.0);
        }
    }
    // Edge triangles: per record, for each opposite slot the triangle (+1) that has the
    // record's edge and that opposite vertex, signed by the direction it walks A -> B.
    let refs: Vec<i32> = std::fs::read(dir.join("edge_triangles.bin"))
        .unwrap()
        .chunks_exact(4)
        .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(m["buffers"]["edge_triangles"]["component_type"], "i32");
    let vertex = |p: &[f32]| pos.chunks_exact(3).position(|q| q == &p[..3]).unwrap() as u32;
    for (rec, r) in sides.chunks_exact(16).zip(refs.chunks_exact(2)) {
        let (a, b) = (vertex(&rec[0..3]), vertex(&rec[4..7]));
        for (slot, &v) in r.iter().enumerate() {
            let tri = &idx[3 * (v.unsigned_abs() as usize - 1)..][..3];
            let o = vertex(&rec[8 + 4 * slot..11 + 4 * slot]);
            let at = |x: u32| tri.iter().position(|&y| y == x).expect("the triangle has the vertex");
            let walks_a_to_b = (at(a) + 1) % 3 == at(b);
            assert_eq!(at(o), 3 - at(a) - at(b), "slot {slot}: the opposite vertex is the triangle's third");
            assert_eq!(v > 0, walks_a_to_b, "slot {slot}: the sign is the walking direction");
        }
    }
    for n in f32s(&std::fs::read(dir.join("normals.bin")).unwrap()).chunks_exact(3) {
        assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) - 1.0).abs() < 1e-5, "unit normal {n:?}");
    }
    let o = umbra(&["export", "--check", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn default_scene_with_ground_and_the_suggested_view_of_render() {
    let dir = tmp("default-ground");
    let m = export("default", &dir, &["--ground"]);
    check_sizes("default --ground", &dir, &m, &info("default", &["--ground"]));
    assert_eq!(m["ground"], true);
    // The light and camera are render's defaults for the scene (bounds without the ground):
    // the same as without --ground.
    let plain = export("default", &tmp("default"), &[]);
    assert_eq!(m["light"], plain["light"]);
    assert_eq!(m["camera"]["eye"], plain["camera"]["eye"]);
    assert_eq!(m["light"].as_array().unwrap().len(), 4);
    // Explicit light and eye reach the manifest.
    let e = export("box", &tmp("box-light"), &["--light", "1,5,2", "--eye", "3,3,3"]);
    assert_eq!(e["light"], serde_json::json!([1.0, 5.0, 2.0, 1.0]));
    assert_eq!(e["camera"]["eye"], serde_json::json!([3.0, 3.0, 3.0]));
}

#[test]
fn export_is_deterministic() {
    let (a, b) = (tmp("det-a"), tmp("det-b"));
    export("default", &a, &[]);
    export("default", &b, &[]);
    for f in
        ["manifest.json", "positions.bin", "normals.bin", "indices.bin", "sides.bin", "caps.bin", "edge_triangles.bin"]
    {
        assert!(std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(), "{f} differs between runs");
    }
}

#[test]
fn truncated_buffer_is_refused_naming_file_and_sizes() {
    let dir = tmp("truncated");
    let m = export("box", &dir, &[]);
    let sides = dir.join("sides.bin");
    let bytes = std::fs::read(&sides).unwrap();
    std::fs::write(&sides, &bytes[..bytes.len() - 1]).unwrap();
    let o = umbra(&["export", "--check", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("sides.bin") && e.contains("$.buffers.sides_data"), "{e}");
    assert!(
        e.contains(&format!("has {} bytes", bytes.len() - 1)) && e.contains(&m["sides_data_bytes"].to_string()),
        "{e}"
    );
}

#[test]
fn malformed_manifests_are_refused_naming_file_and_json_path() {
    let dir = tmp("malformed");
    export("box", &dir, &[]);
    let path = dir.join("manifest.json");
    let good = std::fs::read_to_string(&path).unwrap();
    let check = |text: &str| {
        std::fs::write(&path, text).unwrap();
        let o = umbra(&["export", "--check", dir.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "must fail: {text}");
        stderr(&o)
    };
    // Truncated: a syntax error with the file, line and column.
    let e = check(&good[..good.len() / 2]);
    assert!(e.contains("manifest.json:") && e.contains("not valid JSON"), "{e}");
    // Wrong type, missing field, other version, sizes that contradict Eq. 9.
    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["counts"]["triangles"] = "twelve".into();
    let e = check(&v.to_string());
    assert!(e.contains("manifest.json: $.counts.triangles: expected an unsigned integer"), "{e}");
    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["buffers"].as_object_mut().unwrap().remove("normals");
    let e = check(&v.to_string());
    assert!(e.contains("manifest.json: $.buffers.normals: missing"), "{e}");
    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["version"] = 7.into();
    let e = check(&v.to_string());
    assert!(e.contains("$.version") && e.contains("version 7"), "{e}");
    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["caps_data_bytes"] = 100.into();
    let e = check(&v.to_string());
    assert!(e.contains("$.caps_data_bytes: Eq. 9 gives 576"), "{e}");
    // Missing manifest: the file is named.
    std::fs::remove_file(&path).unwrap();
    let o = umbra(&["export", "--check", dir.to_str().unwrap()]);
    assert!(!o.status.success() && stderr(&o).contains("manifest.json"), "{}", stderr(&o));
}

#[test]
fn usage_errors() {
    let o = umbra(&["export", "box"]);
    assert_eq!(o.status.code(), Some(2), "no --out");
    assert!(stderr(&o).contains("--out"), "{}", stderr(&o));
    let o = umbra(&["export", "no-such-file.obj", "--out", tmp("nofile").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no-such-file.obj"), "{}", stderr(&o));
}

/// Crytek Sponza (UMBRA_SCENES, default ../shared/scenes beside the workspace): the export
/// takes seconds, and its sizes follow Eq. 8 / 9 and `umbra info`.
#[test]
fn crytek_sponza_exports() {
    let scenes = std::env::var("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|_| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"));
    let Some(sponza) = std::fs::read_dir(&scenes).ok().and_then(|d| {
        d.filter_map(|e| e.ok().map(|e| e.path())).find(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.to_lowercase().contains("sponza") && n.ends_with(".obj.gz"))
        })
    }) else {
        eprintln!("SKIP crytek_sponza_exports: no *sponza*.obj.gz in {}", scenes.display());
        return;
    };
    let dir = tmp("sponza");
    let scene = sponza.to_str().unwrap();
    let start = Instant::now();
    let m = export(scene, &dir, &[]);
    let secs = start.elapsed().as_secs_f64();
    let total: u64 = BUFFERS.iter().map(|b| m["buffers"][b]["bytes"].as_u64().unwrap()).sum();
    eprintln!(
        "Crytek Sponza export: {secs:.2} s, {} triangles, {} edge records, maxMult {}, sides-data {} B, caps-data {} B, {total} B in all",
        m["counts"]["triangles"], m["counts"]["sides_data_records"], m["max_mult"], m["sides_data_bytes"], m["caps_data_bytes"]
    );
    // The time is printed, never asserted: export speed is a benchmark.
    check_sizes("sponza", &dir, &m, &info(scene, &[]));
}
