//! The `umbra` binary as users run it: flags, JSON contracts, exit statuses, error messages.

use std::path::PathBuf;

mod common;
use common::*;

fn tmp(name: &str) -> PathBuf {
    tmp_dir("cli").join(name)
}

#[test]
fn info_json_box_counts() {
    // A closed cube: 12 triangles, 8 welded vertices, 18 edges, all manifold.
    let o = umbra(&["info", "box", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["triangles"], 12);
    assert_eq!(v["vertices"], 8);
    assert_eq!(v["degenerate_triangles"], 0);
    assert_eq!(v["edges"], 18);
    assert_eq!(v["open_edges"], 0);
    assert_eq!(v["nonmanifold_edges"], 0);
    assert_eq!(v["max_opposites"], 2);
    assert!(v.get("silhouette_edges").is_none(), "no light, no silhouette keys");
    // Paper 003 Eq. 8 and 9 with maxMult = 2 (every edge has 2 opposite vertices) and one
    // record per edge: 16 (2 + 2) 18 and 48 x 12.
    assert_eq!(v["max_mult"], 2);
    assert_eq!(v["sides_data_records"], 18);
    assert_eq!(v["sides_data_bytes"], 16 * (2 + 2) * 18);
    assert_eq!(v["caps_data_bytes"], 48 * 12);
    // ts-silhouette patches (001 Fig. 4-5): 12 (V + K) + 4 (3 + K) P with V = 8 vertices,
    // K = 2 opposite slots (the most any edge has), P = 18 patches (one per edge).
    assert_eq!(v["patch_bytes"], 12 * (8 + 2) + 4 * (3 + 2) * 18);
}

/// `info --scene SCENE` is `info SCENE` (every other subcommand spells it `--scene`); two
/// different scenes are a usage error naming the flag.
#[test]
fn info_takes_the_scene_positionally_or_as_a_flag() {
    let positional = umbra(&["info", "box", "--json"]);
    let flag = umbra(&["info", "--scene", "box", "--json"]);
    assert!(flag.status.success(), "{}", stderr(&flag));
    assert_eq!(json(&flag), json(&positional));
    let both = umbra(&["info", "box", "--scene", "box", "--json"]);
    assert_eq!(json(&both)["triangles"], 12);
    let clash = umbra(&["info", "box", "--scene", "default"]);
    assert_eq!(clash.status.code(), Some(2), "{}", stderr(&clash));
    assert!(stderr(&clash).contains("--scene") && stderr(&clash).contains("two scenes"), "{}", stderr(&clash));
}

#[test]
fn info_json_sides_data_splits_the_book_spine() {
    // 40 pages on one spine: one edge with 40 opposite vertices; the other 80 edges (2 open
    // edges per page) have 1. maxMult stays the common case and the spine is split into
    // ceil(40 / maxMult) records; the sizes still follow Eq. 8 and 9 exactly. ts-silhouette's
    // patches hold K = 29 opposites at most (GL 4.0 minimums), so the spine takes 2 patches.
    let dir = tmp("book");
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("book.obj");
    let mut obj = String::from("v 0 0 0\nv 0 1 0\n");
    for k in 0..40 {
        let a = k as f64 * std::f64::consts::PI / 40.0;
        obj += &format!("v {} 0.5 {}\n", a.cos(), a.sin());
    }
    for k in 0..40 {
        obj += &format!("f 1 2 {}\n", k + 3);
    }
    std::fs::write(&f, obj).unwrap();
    let o = umbra(&["info", f.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["max_opposites"], 40);
    let (m, e) = (v["max_mult"].as_u64().unwrap(), v["sides_data_records"].as_u64().unwrap());
    let edges = v["edges"].as_u64().unwrap();
    assert!(m < 40, "the rare spine must not set maxMult: {m}");
    assert_eq!(e, edges - 1 + 40u64.div_ceil(m), "spine split into ceil(40 / maxMult) records");
    assert_eq!(v["sides_data_bytes"].as_u64().unwrap(), 16 * (2 + m) * e);
    assert_eq!(v["caps_data_bytes"], 48 * 40);
    assert_eq!(edges, 81);
    assert_eq!(v["patch_bytes"], 12 * (42 + 29) + 4 * (3 + 29) * (80 + 2));
}

#[test]
fn info_json_silhouette_of_box_from_above() {
    // Light far above the unit cube's centre: the silhouette is the 4 edges around the top
    // face, each with multiplicity 2 (a lit and an unlit face, Kim 2008), so the sum is 8.
    // The top face's diagonal and the side faces' diagonals are not silhouettes.
    let o = umbra(&["info", "box", "--json", "--light", "0,100,0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["silhouette_edges"], 4);
    assert_eq!(v["multiplicity_sum"], 8);
}

#[test]
fn info_text_names_every_count() {
    let o = umbra(&["info", "default"]);
    assert!(o.status.success());
    let s = stdout(&o);
    for key in ["triangles", "vertices", "degenerate", "edges", "open", "non-manifold", "max opposite"] {
        assert!(s.contains(key), "missing {key:?} in:\n{s}");
    }
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let out = tmp("render.png");
    let _ = std::fs::remove_file(&out);
    let o = umbra(&["render", "--size", "64x48", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&out).expect("png written");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR width and height, big-endian at bytes 16..24.
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 64);
    assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 48);
}

#[test]
fn render_is_deterministic() {
    let a = tmp("det-a.png");
    let b = tmp("det-b.png");
    for p in [&a, &b] {
        let o = umbra(&["render", "--size", "96x64", "--out", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "same input, same PNG bytes");
}

#[test]
fn bad_flags_are_errors_with_nonzero_status() {
    for (args, needle) in [
        (vec!["render", "--size", "0x10"], "--size"),
        (vec!["render", "--light", "1,2"], "--light"),
        (vec!["render", "--light", "0,0,0,0"], "directional"),
        (vec!["render", "--method", "no-such-method"], "unknown shadow method"),
        (vec!["render", "--scene", "spheres:0"], "spheres:0"),
        (vec!["info", "/nonexistent/file.obj"], "/nonexistent/file.obj"),
        (vec!["info", "scene.xyz"], "scene.xyz"),
    ] {
        let o = umbra(&args);
        assert!(!o.status.success(), "{args:?} should fail");
        let e = stderr(&o);
        assert!(e.contains("umbra: error:") && e.contains(needle), "{args:?}: {e}");
        assert!(!e.contains("panicked"), "{args:?} panicked: {e}");
    }
}

#[test]
fn bad_file_error_names_file_and_line() {
    let f = tmp("bad.obj");
    std::fs::write(&f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let o = umbra(&["info", f.to_str().unwrap()]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("bad.obj") && e.contains("line 4"), "{e}");
}

#[test]
fn empty_scene_render_explains() {
    let f = tmp("empty.obj");
    std::fs::write(&f, "# nothing here\n").unwrap();
    let o = umbra(&["render", "--scene", f.to_str().unwrap(), "--out", tmp("empty.png").to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no triangles"), "{}", stderr(&o));
}

/// `verify` with several methods: one that cannot be drawn here (a cube map larger than any
/// GL's GL_MAX_CUBE_MAP_TEXTURE_SIZE) is an error row, the others are still verified, and the
/// exit status is 2 (an error), not 0 or 1. With that method alone, its error is the command's.
#[test]
fn verify_goes_on_past_a_method_that_cannot_be_drawn_and_reports_it() {
    let o = umbra(&["verify", "--size", "160x90", "--method", "cpu-silhouette,shadow-map-cube:1048576", "--json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("1 of 2 methods could not be verified here: shadow-map-cube:1048576"),
        "{}",
        stderr(&o)
    );
    let v = json(&o);
    let rows = v.as_array().expect("array");
    assert_eq!(rows.len(), 2, "{v}");
    assert_eq!(rows[0]["method"], "cpu-silhouette");
    assert_eq!(rows[0]["mismatches_outside_band"], 0, "{}", rows[0]);
    assert!(rows[0].get("error").is_none(), "{}", rows[0]);
    assert_eq!(rows[1]["method"], "shadow-map-cube:1048576");
    assert!(rows[1]["error"].as_str().is_some_and(|e| e.contains("GL_MAX_CUBE_MAP_TEXTURE_SIZE")), "{}", rows[1]);
    assert!(rows[1].get("mismatches").is_none(), "an error row has no counts: {}", rows[1]);
    // The table says it too.
    let o = umbra(&["verify", "--size", "160x90", "--method", "shadow-map-cube:1048576,cpu-silhouette"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("shadow-map-cube:1048576") && out.contains("ERROR:"), "{out}");
    assert!(out.contains("EXACT"), "cpu-silhouette still verified: {out}");
    // Alone, the method's error is the command's (no table).
    let o = umbra(&["verify", "--size", "160x90", "--method", "shadow-map-cube:1048576"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("GL_MAX_CUBE_MAP_TEXTURE_SIZE"), "{}", stderr(&o));
}

#[test]
fn verify_json_contract_and_exit_status() {
    let o = umbra(&["verify", "--size", "160x120", "--method", "cpu-silhouette,none", "--json"]);
    let v = json(&o);
    let rows = v.as_array().expect("array");
    assert_eq!(rows.len(), 2);
    for r in rows {
        for key in [
            "method",
            "samples",
            "shadowed_reference",
            "mismatches",
            "band_samples",
            "band_mismatches",
            "mismatches_outside_band",
            "reference_ms",
            "render_ms",
        ] {
            assert!(r.get(key).is_some(), "missing {key} in {r}");
        }
    }
    let cpu = rows.iter().find(|r| r["method"] == "cpu-silhouette").unwrap();
    let none = rows.iter().find(|r| r["method"] == "none").unwrap();
    assert!(cpu["samples"].as_u64().unwrap() > 10_000);
    assert!(cpu["shadowed_reference"].as_u64().unwrap() > 500, "the default scene has shadows");
    assert_eq!(cpu["mismatches_outside_band"], 0, "{cpu}");
    // `none` casts no shadow: its only dark samples are surfaces seen from the side facing
    // away from the light (the lighting pass gives them no diffuse), so it misses every cast
    // shadow: many mismatches, none of them false shadow.
    let (nm, ns) = (none["mismatches"].as_u64().unwrap(), none["shadowed_reference"].as_u64().unwrap());
    assert!(nm > 500 && nm <= ns, "none: {none}");
    // `none` is measured, never failed: exit status 0.
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // "counter": which count the method used (--counter, default auto: stencil8 when the
    // winding bound proves 8 bits exact, as on the default scene); "none" for methods that
    // classify in their shader (shadow maps).
    assert_eq!(cpu["counter"], "stencil8", "{cpu}");
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "cpu-silhouette,shadow-map-cube:1024",
        "--counter",
        "float32",
        "--json",
    ]);
    let v = json(&o);
    assert_eq!(v[0]["counter"], "float32", "{v}");
    assert_eq!(v[0]["mismatches_outside_band"], 0, "{v}");
    assert_eq!(v[1]["counter"], "none", "{v}");
    let o = umbra(&["verify", "--size", "160x120", "--counter", "int9"]);
    assert_eq!(o.status.code(), Some(2), "a bad --counter is a usage error");
    assert!(stderr(&o).contains("int9"), "{}", stderr(&o));
}

/// `--subpixel-bits`: the band of a coarser rasterizer (an external mask from a browser that
/// reports 4 bits) holds more samples than this context's own (llvmpipe: 8 bits); the decision
/// of every sample outside both is the same, so the method still passes. Out of GL's range and
/// with the wgpu backend it is an error naming the flag.
#[test]
fn verify_subpixel_bits_sets_the_bands_precision() {
    let band = |extra: &[&str]| {
        let mut args = vec!["verify", "--size", "160x120", "--method", "cpu-silhouette", "--json"];
        args.extend_from_slice(extra);
        let o = umbra(&args);
        let v = json(&o);
        assert_eq!(v[0]["mismatches_outside_band"], 0, "{extra:?}: {v}");
        v[0]["band_samples"].as_u64().unwrap()
    };
    let (own, coarse) = (band(&[]), band(&["--subpixel-bits", "4"]));
    assert!(coarse > own, "4 subpixel bits: {coarse} band samples, the context's own: {own}");
    for bad in
        [vec!["--subpixel-bits", "3"], vec!["--subpixel-bits", "17"], vec!["--subpixel-bits", "8", "--backend", "wgpu"]]
    {
        let mut args = vec!["verify", "--size", "16x16"];
        args.extend_from_slice(&bad);
        let o = umbra(&args);
        assert!(!o.status.success(), "{bad:?} should fail");
        let e = stderr(&o);
        assert!(e.contains("--subpixel-bits") && !e.contains("panicked"), "{bad:?}: {e}");
    }
}

/// An external mask was decided on its renderer's own depth pass: its band adds the samples
/// where that pass may show another surface (seen-surface, umbra_oracle::seen_surface), while
/// the native method beside it, which decides the reference's own samples, keeps its band.
#[test]
fn verify_external_mask_band_adds_the_surfaces_its_depth_pass_may_see() {
    let m = tmp("black-mask-band.png");
    solid_png(&m, 160, 120, [0, 0, 0]);
    let args = ["verify", "--size", "160x120", "--method", "vs-silhouette", "--json", "--subpixel-bits", "4"];
    let native = json(&umbra(&args));
    let mut with_mask = args.to_vec();
    with_mask.extend_from_slice(&["--external-mask", m.to_str().unwrap()]);
    let both = json(&umbra(&with_mask));
    assert_eq!(both[0]["band_samples"], native[0]["band_samples"], "{both}");
    let (own, external) = (both[0]["band_samples"].as_u64().unwrap(), both[1]["band_samples"].as_u64().unwrap());
    assert!(external > own, "the mask's band {external}, the native method's {own}");
}

#[test]
fn verify_json_per_light_and_the_default_light_by_name() {
    // `--light default` is the light derived from the scene's bounds, so it can be combined
    // with others; each row's `per_light` holds the counts of every light, which add up to the
    // row's own.
    let alone = umbra(&["verify", "--size", "160x120", "--method", "cpu-silhouette", "--json"]);
    let alone = json(&alone)[0].clone();
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "cpu-silhouette",
        "--light",
        "default",
        "--light",
        "0.4,1,0.3,0",
        "--json",
    ]);
    let row = json(&o)[0].clone();
    let lights = row["per_light"].as_array().expect("per_light array");
    assert_eq!(lights.len(), 2, "{row}");
    assert_eq!(lights[1]["light"], serde_json::json!([0.4, 1.0, 0.3, 0.0]), "{row}");
    for key in
        ["samples", "shadowed_reference", "mismatches", "band_samples", "band_mismatches", "mismatches_outside_band"]
    {
        assert_eq!(lights[0][key], alone[key], "{key}: the default light alone gives the same counts");
        let sum = lights[0][key].as_u64().unwrap() + lights[1][key].as_u64().unwrap();
        assert_eq!(row[key].as_u64().unwrap(), sum, "{key}");
    }
}

#[test]
fn verify_zpass_with_camera_in_shadow_fails_with_status_1() {
    // Camera on the ground under the default scene's sphere, inside its shadow volume:
    // z-pass counting is wrong there (the documented reason z-fail is the default).
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "cpu-silhouette",
        "--zpass",
        "--eye",
        "-2.2,0.2,0.3",
        "--target",
        "3,0,3",
        "--light",
        "-2.2,8,0.3",
    ]);
    assert_eq!(o.status.code(), Some(1), "stdout {}\nstderr {}", stdout(&o), stderr(&o));
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "cpu-silhouette",
        "--eye",
        "-2.2,0.2,0.3",
        "--target",
        "3,0,3",
        "--light",
        "-2.2,8,0.3",
    ]);
    assert_eq!(o.status.code(), Some(0), "z-fail is right: stdout {}\nstderr {}", stdout(&o), stderr(&o));
}

#[test]
fn verify_zmode_contract() {
    // "zpass" per light: auto (the default) counts z-pass where the eye is provably outside
    // every volume (the default view), z-fail where it is inside one, and both are exact.
    let o = umbra(&["verify", "--size", "160x120", "--method", "cpu-silhouette", "--json"]);
    let v = json(&o);
    assert_eq!(v[0]["zpass"], serde_json::json!([true]), "{v}");
    assert_eq!(v[0]["mismatches_outside_band"], 0, "{v}");
    let shadowed = ["--eye", "-2.2,0.2,0.3", "--target", "3,0,3", "--light", "-2.2,8,0.3"];
    // Under the sphere: the silhouette method counts z-pass from the sphere's W0 (edges of
    // multiplicity 0 may cross the eye's pyramid), the per-triangle one keeps z-fail there.
    let o = umbra(
        &[&["verify", "--size", "160x120", "--method", "cpu-silhouette,vs-triangle", "--json"][..], &shadowed[..]]
            .concat(),
    );
    let v = json(&o);
    assert_eq!(v[0]["zpass"], serde_json::json!([true]), "{v}");
    assert_eq!(v[1]["zpass"], serde_json::json!([false]), "{v}");
    assert_eq!(v[0]["mismatches_outside_band"], 0, "{v}");
    assert_eq!(v[1]["mismatches_outside_band"], 0, "{v}");
    // --zmode zfail never, --zmode zpass (like --zpass) always.
    let o = umbra(&["verify", "--size", "160x120", "--method", "cpu-silhouette", "--zmode", "zfail", "--json"]);
    assert_eq!(json(&o)[0]["zpass"], serde_json::json!([false]));
    let o = umbra(
        &[
            &["verify", "--size", "160x120", "--method", "cpu-silhouette", "--zmode", "zpass", "--json"][..],
            &shadowed[..],
        ]
        .concat(),
    );
    assert_eq!(o.status.code(), Some(1), "forced z-pass with the eye in shadow is wrong: {}", stdout(&o));
    // Bad values and contradictions are usage errors naming the flag.
    for bad in [&["--zmode", "zmaybe"][..], &["--zmode", "zfail", "--zpass"][..]] {
        let o = umbra(&[&["verify", "--size", "160x120"][..], bad].concat());
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--zmode"), "{}", stderr(&o));
    }
}

/// `--volume-cull on|off` (on by default): cpu-silhouette exact both ways, in the default view
/// (z-pass) and with the eye under the sphere (z-pass from its winding W0, then forced z-fail);
/// a bad value is a usage error naming the flag, on every subcommand that takes it.
#[test]
fn volume_cull_contract() {
    let shadowed = ["--eye", "-2.2,0.2,0.3", "--target", "3,0,3", "--light", "-2.2,8,0.3"];
    for extra in [&[][..], &shadowed[..], &[&shadowed[..], &["--zmode", "zfail"][..]].concat()[..]] {
        for cull in ["on", "off"] {
            let o = umbra(
                &[
                    &["verify", "--size", "160x120", "--method", "cpu-silhouette", "--json", "--volume-cull", cull][..],
                    extra,
                ]
                .concat(),
            );
            assert_eq!(o.status.code(), Some(0), "{extra:?} {cull}: {}", stdout(&o));
            assert_eq!(json(&o)[0]["mismatches_outside_band"], 0, "{extra:?} {cull}");
        }
    }
    for command in ["render", "verify", "bench", "view"] {
        let o = umbra(&[command, "--volume-cull", "sometimes"]);
        assert_eq!(o.status.code(), Some(2), "{command}: {}", stderr(&o));
        assert!(stderr(&o).contains("--volume-cull") && stderr(&o).contains("expected on"), "{}", stderr(&o));
    }
}

/// `--volume-cull on` and `off` are accepted by `render` (a PNG either way), `bench` (the row
/// says which) and `view` (past the flags, it stops only for the missing display); `verify`:
/// [`volume_cull_contract`].
#[test]
fn volume_cull_on_and_off_on_every_subcommand() {
    for cull in ["on", "off"] {
        let png = tmp(&format!("cull-{cull}.png"));
        let _ = std::fs::remove_file(&png);
        let o = umbra(&["render", "--size", "80x60", "--volume-cull", cull, "--out", png.to_str().unwrap()]);
        assert!(o.status.success(), "render {cull}: {}", stderr(&o));
        assert_eq!(&std::fs::read(&png).expect("render wrote its PNG")[..4], b"\x89PNG");
        let bench = ["bench", "--json", "--methods", "cpu-silhouette", "--frames", "1", "--warmup", "0"];
        let o = umbra(&[&bench[..], &["--size", "32x24", "--stage-every", "0", "--volume-cull", cull]].concat());
        assert!(o.status.success(), "bench {cull}: {}", stderr(&o));
        assert_eq!(json(&o)[0]["volume_cull"], cull == "on", "bench {cull}");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_umbra"))
            .args(["view", "--volume-cull", cull])
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("run umbra");
        assert!(
            stderr(&o).contains("no display") && !stderr(&o).contains("--volume-cull"),
            "view {cull}: {}",
            stderr(&o)
        );
    }
}

/// A floor (facing up) under a sheet that faces down, seen from above, lit from above: with
/// `--receivers both` a pixel shows the sheet's back (lit: the eye and the light are on the same
/// side of it); with `--receivers front` the depth pass culls it and shows the floor behind,
/// in the sheet's shadow, as three.js draws a `FrontSide` material. The sheet casts either way.
fn sheet_over_floor() -> PathBuf {
    let obj = tmp("sheet-over-floor.obj");
    std::fs::write(
        &obj,
        "# floor at y = 0, counter-clockwise seen from above (+y)\n\
         v -4 0 -4\nv -4 0 4\nv 4 0 4\nv 4 0 -4\n\
         # sheet at y = 1, counter-clockwise seen from below (-y)\n\
         v -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1\n\
         f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n",
    )
    .expect("write the scene");
    obj
}

#[test]
fn receivers_front_shows_the_floor_behind_a_back_facing_sheet_and_both_verify() {
    let obj = sheet_over_floor();
    let view = ["--scene", obj.to_str().unwrap(), "--size", "160x120", "--eye", "0,4,5", "--target", "0,0,0"];
    let view = [&view[..], &["--light", "0.5,6,0.3"]].concat();
    let verify = |receivers: &str, methods: &str| {
        let o = umbra(&[&["verify", "--json", "--method", methods, "--receivers", receivers][..], &view].concat());
        assert_eq!(o.status.code(), Some(0), "{receivers}: {}\n{}", stdout(&o), stderr(&o));
        json(&o)
    };
    // The methods that decide per sample without rasterizing volume caps (the hier methods'
    // samples pass and ray-bvh's re-draw the scene over the depth pass, culled as it is). The
    // stencil-volume methods push every light cap to the far plane (paper 003 Eq. 6), which
    // counts a caster that lies in front of the sample as if it were behind: not exact for a
    // sample seen through a back-facing caster (docs/cli.md, `--receivers`).
    let exact = "hier-triangle,hier-silhouette,ray-bvh";
    let (both, front) = (verify("both", &format!("cpu-silhouette,vs-silhouette,{exact}")), verify("front", exact));
    for (rows, receivers) in [(&both, "both"), (&front, "front")] {
        for row in rows.as_array().unwrap() {
            assert_eq!(row["receivers"], receivers, "{row}");
            assert_eq!(row["mismatches_outside_band"], 0, "{receivers}: {row}");
        }
    }
    // The same pixels hold a sample (the floor covers the sheet's image), but under the sheet
    // `front` shows the shadowed floor where `both` shows the lit sheet.
    let count = |v: &serde_json::Value, key: &str| v.as_array().unwrap().last().unwrap()[key].as_u64().unwrap();
    assert_eq!(count(&front, "samples"), count(&both, "samples"));
    let (shadowed_both, shadowed_front) = (count(&both, "shadowed_reference"), count(&front, "shadowed_reference"));
    assert!(shadowed_front > shadowed_both + 200, "front: {shadowed_front} shadowed samples, both: {shadowed_both}");
    // The sheet's image is the floor's shadow seen through it: render shows it too.
    let png = |receivers: &str| {
        let out = tmp(&format!("sheet-{receivers}.png"));
        let o = umbra(&[&["render", "--receivers", receivers, "--out", out.to_str().unwrap()][..], &view].concat());
        assert!(o.status.success(), "render {receivers}: {}", stderr(&o));
        std::fs::read(&out).expect("render wrote its PNG")
    };
    assert_ne!(png("front"), png("both"));
    // Default: both.
    let o = umbra(&[&["verify", "--json", "--method", "ray-bvh"][..], &view].concat());
    assert_eq!(json(&o)[0]["shadowed_reference"], shadowed_both);
    // The stencil-volume methods under `front`: the floor behind the sheet counted lit.
    let o = umbra(&[&["verify", "--json", "--method", "cpu-silhouette", "--receivers", "front"][..], &view].concat());
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    // Bad values and the wgpu backend (both faces only) are usage errors naming the flag.
    for (command, extra) in [("verify", &[][..]), ("render", &[][..]), ("verify", &["--backend", "wgpu"][..])] {
        let value = if extra.is_empty() { "back" } else { "front" };
        let o = umbra(&[&[command, "--size", "16x16", "--receivers", value][..], extra].concat());
        assert_eq!(o.status.code(), Some(2), "{command} {value} {extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--receivers") && !stderr(&o).contains("panicked"), "{}", stderr(&o));
    }
}

#[test]
fn verify_writes_diff_image() {
    let d = tmp("diff.png");
    let _ = std::fs::remove_file(&d);
    let o = umbra(&["verify", "--size", "80x60", "--method", "cpu-silhouette", "--diff", d.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(&std::fs::read(&d).expect("diff written")[..4], b"\x89PNG");
}

/// Writes a `w x h` RGB PNG of one colour.
fn solid_png(path: &std::path::Path, w: u32, h: u32, rgb: [u8; 3]) {
    let mut e = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(path).unwrap()), w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let bytes: Vec<u8> = (0..w * h).flat_map(|_| rgb).collect();
    e.write_header().unwrap().write_image_data(&bytes).unwrap();
}

#[test]
fn verify_external_mask_is_judged_as_one_more_row() {
    // --external-mask (the WebGL2 viewer's mask, web/testlib/exactness.mjs): white = lit. An
    // all-white mask lights every shadowed sample: false light outside the band, exit status 1,
    // one more row named by the file, next to the native method's.
    let m = tmp("white-mask.png");
    solid_png(&m, 160, 120, [255, 255, 255]);
    let path = m.to_str().unwrap();
    let d = tmp("external-diff.png");
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "vs-silhouette",
        "--external-mask",
        path,
        "--json",
        "--explain",
        "2",
        "--diff",
        d.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v[0]["method"], "vs-silhouette");
    assert_eq!(v[0]["mismatches_outside_band"], 0, "{v}");
    assert_eq!(v[1]["method"], path, "{v}");
    let (outside, shadowed) =
        (v[1]["mismatches_outside_band"].as_u64().unwrap(), v[1]["shadowed_reference"].as_u64().unwrap());
    assert!(outside > 500 && outside <= shadowed, "{v}");
    assert!(stderr(&o).contains(&format!("{path} light 0 false light (")), "{}", stderr(&o));
    assert!(tmp("external-diff.external.png").exists() && tmp("external-diff.vs-silhouette.png").exists());
    // An all-black mask shadows every lit sample instead.
    let black = tmp("black-mask.png");
    solid_png(&black, 160, 120, [0, 0, 0]);
    let o = umbra(&[
        "verify",
        "--size",
        "160x120",
        "--method",
        "none",
        "--external-mask",
        black.to_str().unwrap(),
        "--json",
    ]);
    let v = json(&o);
    let r = &v[1];
    assert_eq!(
        r["mismatches"].as_u64().unwrap() + r["shadowed_reference"].as_u64().unwrap(),
        r["samples"].as_u64().unwrap(),
        "{r}"
    );
    // Errors name the file: wrong size, not a PNG, absent.
    solid_png(&m, 80, 60, [255, 255, 255]);
    let o = umbra(&["verify", "--size", "160x120", "--method", "none", "--external-mask", path]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(&format!("method {path}: the mask is 80x60, the view 160x120")), "{}", stderr(&o));
    std::fs::write(&m, b"not a png").unwrap();
    let o = umbra(&["verify", "--size", "160x120", "--method", "none", "--external-mask", path]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(&format!("{path}: not a readable PNG")), "{}", stderr(&o));
}

#[test]
fn sm_options_reach_the_shadow_map_in_render_and_verify() {
    // --sm-bias / --sm-pcf are accepted by render and verify as by bench, and change what the
    // shadow map decides: without any bias a depth map shadows its own receivers (acne), so
    // verify counts many more false shadows than with the default bias.
    let verify = |extra: &[&str]| {
        let mut args = vec!["verify", "--method", "shadow-map-cube:256", "--size", "160x120", "--json"];
        args.extend_from_slice(extra);
        let o = umbra(&args);
        assert_eq!(o.status.code(), Some(0), "shadow maps are never failed: {}", stderr(&o));
        json(&o)[0]["mismatches"].as_u64().unwrap()
    };
    let default_bias = verify(&[]);
    let no_bias = verify(&["--sm-bias", "0,0"]);
    assert!(no_bias > default_bias + 100, "no bias {no_bias} vs default {default_bias}");
    let pcf = verify(&["--sm-pcf"]);
    assert_ne!(pcf, default_bias, "3x3 PCF must change some decisions");
    let (a, b) = (tmp("sm-plain.png"), tmp("sm-pcf.png"));
    for (out, extra) in [(&a, None), (&b, Some("--sm-pcf"))] {
        let mut args =
            vec!["render", "--method", "shadow-map-cube:256", "--size", "160x120", "--out", out.to_str().unwrap()];
        args.extend(extra);
        let o = umbra(&args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "--sm-pcf must reach render");
    let o = umbra(&["render", "--method", "shadow-map-cube:256", "--sm-bias", "-1", "--out", a.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--sm-bias"), "{}", stderr(&o));
}

/// `--method help` (render, view, verify) and `--methods help` (bench) list the registered
/// methods, one per line, and draw nothing.
#[test]
fn method_help_lists_the_methods_in_every_command() {
    for args in [
        &["render", "--method", "help"][..],
        &["verify", "--method", "help"],
        &["verify", "--method", "list"],
        &["bench", "--methods", "help"],
    ] {
        let o = umbra(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let out = String::from_utf8_lossy(&o.stdout);
        let names: Vec<&str> = out.lines().collect();
        for m in ["cpu-silhouette", "hier-triangle", "hier-silhouette", "ts-triangle-1pass"] {
            assert!(names.contains(&m), "{args:?}: {m} missing from {out}");
        }
        assert!(!out.contains("samples"), "{args:?} verified or benchmarked something: {out}");
    }
}
