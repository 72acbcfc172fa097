//! `--ortho HEIGHT`: orthographic views on every command that draws one. cpu-silhouette's
//! finite volumes are exact under z-pass and z-fail with point and directional lights
//! (docs/exactness.md, "Orthographic views"); methods whose volumes run to infinity are
//! refused with an error naming them; a bad height is an error naming the flag; an external
//! mask is judged in the orthographic view.

mod common;
use common::*;

fn verify_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["verify", "--json"];
    all.extend_from_slice(args);
    let o = umbra(&all);
    assert_eq!(o.status.code(), Some(0), "{args:?}: stdout {}\nstderr {}", stdout(&o), stderr(&o));
    json(&o)
}

#[test]
fn ortho_views_of_the_default_scene_are_exact_for_cpu_silhouette() {
    for light in ["default", "0.4,1,0.3,0"] {
        for zmode in ["zpass", "zfail", "auto"] {
            let light_flag = format!("--light={light}");
            let args =
                ["--ortho", "9", "--size", "160x120", "--method", "cpu-silhouette", "--zmode", zmode, &light_flag];
            let v = verify_json(&args);
            let r = &v[0];
            assert_eq!(r["mismatches_outside_band"], 0, "{args:?}: {r}");
            assert!(r["samples"].as_u64().unwrap() > 10_000, "{args:?}: {r}");
            assert!(r["shadowed_reference"].as_u64().unwrap() > 500, "{args:?}: the view has shadows: {r}");
            // auto counts z-pass for every light of an orthographic view: exact from 0.
            assert_eq!(r["zpass"][0], zmode != "zfail", "{args:?}: {r}");
        }
    }
}

/// The ground under the sphere, seen along it from inside the sphere's shadow volume: the line
/// behind the camera crosses the volume, and casters behind the near plane count. z-pass
/// counts from infinity behind the camera (the light caps behind the near plane included),
/// z-fail from infinity beyond the scene; both are exact.
#[test]
fn ortho_z_pass_and_z_fail_from_inside_a_shadow_volume() {
    for zmode in ["zpass", "zfail"] {
        for eye in ["-2.2,0.2,0.3", "-2.2,0.6,0.3"] {
            let eye_flag = format!("--eye={eye}");
            let args = [
                "--ortho",
                "3",
                "--size",
                "160x120",
                "--method",
                "cpu-silhouette",
                "--zmode",
                zmode,
                &eye_flag,
                "--target=3,0,3",
                "--light=-2.2,8,0.3",
            ];
            let v = verify_json(&args);
            let r = &v[0];
            assert_eq!(r["mismatches_outside_band"], 0, "{args:?}: {r}");
            assert!(r["shadowed_reference"].as_u64().unwrap() > 1_000, "{args:?}: in the shadow: {r}");
        }
    }
}

#[test]
fn ortho_render_draws_parallel_rays() {
    let dir = tmp_dir("ortho");
    let (ortho, persp) = (dir.join("ortho.png"), dir.join("persp.png"));
    for (path, extra) in [(&ortho, vec!["--ortho", "6"]), (&persp, vec![])] {
        let mut args = vec!["render", "--size", "96x64", "--out", path.to_str().unwrap()];
        args.extend(extra);
        let o = umbra(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    let (a, b) = (std::fs::read(&ortho).unwrap(), std::fs::read(&persp).unwrap());
    assert_ne!(a, b, "the orthographic view differs from the perspective one");
    // Bench and export take it too.
    let o = umbra(&[
        "bench",
        "--ortho",
        "6",
        "--methods",
        "cpu-silhouette,none",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--size",
        "64x48",
        "--json",
    ]);
    assert!(o.status.success(), "bench: {}", stderr(&o));
    let out = dir.join("export");
    let o = umbra(&["export", "box", "--out", out.to_str().unwrap(), "--ortho", "5"]);
    assert!(o.status.success(), "export: {}", stderr(&o));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).expect("manifest");
    assert_eq!(manifest["camera"]["ortho_height"], 5.0, "{manifest}");
    let o = umbra(&["export", "--check", out.to_str().unwrap()]);
    assert!(o.status.success(), "export --check: {}", stderr(&o));
}

#[test]
fn ortho_refuses_methods_whose_volumes_run_to_infinity() {
    // verify goes on past them: an ERROR row naming the method, exit status 2.
    let o = umbra(&["verify", "--ortho", "9", "--size", "160x120", "--method", "cpu-silhouette,ts-triangle", "--json"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v[0]["mismatches_outside_band"], 0, "{v}");
    let e = v[1]["error"].as_str().unwrap_or_default();
    assert!(e.contains("method ts-triangle cannot draw an orthographic view"), "{v}");
    // render: the error is the command's.
    let o = umbra(&["render", "--ortho", "9", "--size", "64x48", "--method", "vs-silhouette", "--out", "/dev/null"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("method vs-silhouette cannot draw an orthographic view"), "{}", stderr(&o));
    // The wgpu backend draws no orthographic view (checked before any device is opened).
    let o = umbra(&["render", "--ortho", "9", "--backend", "wgpu", "--out", "/dev/null"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--ortho"), "{}", stderr(&o));
}

#[test]
fn bad_ortho_values_are_errors_naming_the_flag() {
    for value in ["0", "-1", "NaN", "inf", "tall", ""] {
        for cmd in ["render", "verify", "bench", "export", "view"] {
            let mut args = vec![cmd];
            if cmd == "export" {
                args.extend(["box", "--out", "/nonexistent/never-written"]);
            }
            args.extend(["--ortho", value]);
            let o = umbra(&args);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            let e = stderr(&o);
            assert!(e.contains("--ortho") && !e.contains("panicked"), "{args:?}: {e}");
        }
    }
}

/// Writes a `w x h` RGB PNG of one colour.
fn solid_png(path: &std::path::Path, w: u32, h: u32, rgb: [u8; 3]) {
    let mut e = png::Encoder::new(std::io::BufWriter::new(std::fs::File::create(path).unwrap()), w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let bytes: Vec<u8> = (0..w * h).flat_map(|_| rgb).collect();
    e.write_header().unwrap().write_image_data(&bytes).unwrap();
}

/// `verify --ortho H --method none --external-mask FILE`: a browser's mask is judged in the
/// orthographic view. An all-black mask shadows every lit sample of that view, an all-white
/// one lights every shadowed one (false light outside the band: exit status 1).
#[test]
fn ortho_external_mask_is_judged_in_the_orthographic_view() {
    let dir = tmp_dir("ortho");
    let base = ["verify", "--ortho", "9", "--size", "160x120", "--method", "none", "--json", "--external-mask"];
    let black = dir.join("black.png");
    solid_png(&black, 160, 120, [0, 0, 0]);
    let mut args = base.to_vec();
    args.push(black.to_str().unwrap());
    let o = umbra(&args);
    let v = json(&o);
    let r = &v[1];
    assert_eq!(r["method"], black.to_str().unwrap(), "{v}");
    assert_eq!(
        r["mismatches"].as_u64().unwrap() + r["shadowed_reference"].as_u64().unwrap(),
        r["samples"].as_u64().unwrap(),
        "{r}"
    );
    // The orthographic view's samples, not the perspective one's.
    let persp = umbra(&["verify", "--size", "160x120", "--method", "none", "--json"]);
    assert_ne!(json(&persp)[0]["samples"], v[0]["samples"], "{v}");
    let white = dir.join("white.png");
    solid_png(&white, 160, 120, [255, 255, 255]);
    let mut args = base.to_vec();
    args.push(white.to_str().unwrap());
    let o = umbra(&args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let v = json(&o);
    let outside = v[1]["mismatches_outside_band"].as_u64().unwrap();
    assert!(outside > 500 && outside <= v[1]["shadowed_reference"].as_u64().unwrap(), "{v}");
}

/// A real mask judged in the orthographic view: `umbra view --ortho --mask` (under
/// `xvfb-run`) writes the window's shadow mask, `verify --method none --external-mask` judges
/// it: 0 samples outside the band, and the window and the headless verify agree on the view.
#[test]
fn ortho_window_mask_judged_by_verify_is_exact() {
    if !std::process::Command::new("xvfb-run").arg("--help").output().is_ok_and(|o| o.status.success()) {
        eprintln!("SKIPPED: xvfb-run not installed (apt-get install xvfb); umbra view needs a display");
        return;
    }
    let dir = tmp_dir("ortho");
    let (script, mask) = (dir.join("pose.path"), dir.join("window-mask.png"));
    std::fs::write(&script, "eye 6 5 7 target 0 0.5 0\n").unwrap();
    let _ = std::fs::remove_file(&mask);
    let view = ["--size", "160x120", "--ortho", "8", "--eye=6,5,7", "--target=0,0.5,0"];
    let o = std::process::Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24", env!("CARGO_BIN_EXE_umbra"), "view", "default"])
        .args(view)
        .args(["--mask", "--script", script.to_str().unwrap(), "--screenshot", mask.to_str().unwrap()])
        .output()
        .expect("xvfb-run");
    assert!(o.status.success(), "umbra view: {}", stderr(&o));
    let mut args = vec!["verify", "--json", "--method", "none", "--external-mask", mask.to_str().unwrap()];
    args.extend(view);
    let o = umbra(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = json(&o);
    let r = &v[1];
    assert_eq!(r["mismatches_outside_band"], 0, "{v}");
    assert!(r["shadowed_reference"].as_u64().unwrap() > 500, "the view has shadows: {v}");
    // `none` itself misses them: the mask's decisions are the window's, not the samples'.
    assert!(v[0]["mismatches_outside_band"].as_u64().unwrap() > 500, "{v}");
}
