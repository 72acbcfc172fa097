//! `umbra view` used as a person would: started under a virtual X server (Debian's `xvfb`,
//! `xvfb-run`) with a scripted camera path and `--screenshot`, and the screenshot compared with
//! the headless `umbra render` of the same view (the script's last pose as --eye/--target,
//! same scene, lights and size).
//!
//! The comparison is by shadow classification, decided from colour: every pixel of either
//! image is background (the clear colour), shadowed (exactly the ambient colour: no light
//! reaches it) or lit (anything else). This needs nothing but the two PNGs a user gets.
//! Background (26, 31, 41) and ambient (31, 31, 31) are told apart by blue; a lit pixel has a
//! diffuse term added. (A lit facet so nearly edge-on to every light that its diffuse term
//! rounds to 0 would count as shadowed — in both images alike.) The classifications must
//! agree outside the one-pixel band around every class boundary of the reference (pixels
//! whose 3x3 neighbourhood is not uniform). The mask view (`--mask`,
//! black = lit by no light) is checked the same way: black exactly where the reference is
//! background or shadowed.
//!
//! The shadow-volume wireframe (F in the window; `wireframe on` in a script) changes the
//! screenshot along lines — some pixels, far fewer than all, only darkened — and `--counter
//! float32` gives the same screenshot as the default counter on this scene (both count
//! exactly; fewer than 256 overlapping volumes).
//!
//! Skipped, with a message, when `xvfb-run` is not installed (`.ci/run` installs it).

use std::path::{Path, PathBuf};
use std::process::Command;

const UMBRA: &str = env!("CARGO_BIN_EXE_umbra");

fn has_xvfb_run() -> bool {
    Command::new("xvfb-run").arg("--help").output().is_ok()
}

fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view-test");
    std::fs::create_dir_all(&d).expect("test output directory");
    d
}

struct Png {
    width: u32,
    height: u32,
    rgba: Vec<[u8; 4]>,
}

fn read_png(path: &Path) -> Png {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("png header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("png data");
    assert_eq!(info.color_type, png::ColorType::Rgba, "{}", path.display());
    let rgba = buf[..info.buffer_size()].chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    Png { width: info.width, height: info.height, rgba }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Background,
    Shadow,
    Lit,
}

/// umbra's default shading: background (0.10, 0.12, 0.16), ambient 0.15 * albedo 0.8.
fn classify(c: [u8; 4]) -> Class {
    let near = |a: [u8; 3]| c[..3].iter().zip(&a).all(|(x, y)| x.abs_diff(*y) <= 1);
    if near([26, 31, 41]) {
        Class::Background
    } else if near([31, 31, 31]) {
        Class::Shadow
    } else {
        Class::Lit
    }
}

/// Pixels whose 3x3 neighbourhood holds more than one class.
fn band(classes: &[Class], w: u32, h: u32) -> Vec<bool> {
    let (w, h) = (w as i64, h as i64);
    let at = |x: i64, y: i64| classes[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| (-1..=1).any(|dy| (-1..=1).any(|dx| at(x + dx, y + dy) != at(x, y))))
        .collect()
}

fn run(cmd: &mut Command, what: &str) {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

const SCENE_FLAGS: [&str; 7] = ["--size", "320x240", "--light", "2,6,1", "--light", "-0.5,1,0.3,0", "--ground"];

fn view_screenshot(script: &Path, shot: &Path, extra: &[&str]) {
    let _ = std::fs::remove_file(shot);
    let mut cmd = Command::new("xvfb-run");
    // -a: a free display number (tests run in parallel); a 24-bit screen for an RGBA8 visual.
    cmd.args(["-a", "-s", "-screen 0 1024x768x24", UMBRA, "view", "default"]).args(SCENE_FLAGS).args(extra);
    cmd.arg("--script").arg(script).arg("--screenshot").arg(shot);
    run(&mut cmd, "umbra view under xvfb-run");
}

#[test]
fn view_screenshot_under_xvfb_matches_the_headless_render() {
    if !has_xvfb_run() {
        eprintln!("SKIPPED: xvfb-run not installed (apt-get install xvfb); umbra view needs a display");
        return;
    }
    let dir = out_dir();
    // A short path; the last pose is the view compared.
    let script = dir.join("camera.path");
    let poses = "# orbit in, then settle\neye 9 6 9 target 0 1 0\neye 7 5 8 target 0 1 0\n6.5,4.5,6.5  0.2,1,0\neye 5.5 4 6 target 0.2 0.9 0\n";
    std::fs::write(&script, poses).expect("script");
    let shot = dir.join("view.png");
    let mask_shot = dir.join("view-mask.png");
    let reference = dir.join("render.png");
    view_screenshot(&script, &shot, &[]);
    view_screenshot(&script, &mask_shot, &["--mask"]);
    let mut render = Command::new(UMBRA);
    render.args(["render", "--scene", "default"]).args(SCENE_FLAGS);
    render.args(["--eye", "5.5,4,6", "--target", "0.2,0.9,0", "--out"]).arg(&reference);
    run(&mut render, "umbra render");

    let (v, m, r) = (read_png(&shot), read_png(&mask_shot), read_png(&reference));
    for img in [&v, &m] {
        assert_eq!((img.width, img.height), (r.width, r.height), "the window is the requested 320x240");
    }
    let ref_classes: Vec<Class> = r.rgba.iter().map(|&c| classify(c)).collect();
    let band = band(&ref_classes, r.width, r.height);
    let count = |c: Class| ref_classes.iter().filter(|&&x| x == c).count();
    let (bg, shadow, lit) = (count(Class::Background), count(Class::Shadow), count(Class::Lit));
    assert!(bg > 1000 && shadow > 1000 && lit > 10000, "the view shows sky, shadow and light: {bg} / {shadow} / {lit}");

    let (mut view_off, mut mask_off, mut bytes_differ) = (0, 0, 0);
    for i in 0..ref_classes.len() {
        bytes_differ += usize::from(v.rgba[i] != r.rgba[i]);
        if band[i] {
            continue;
        }
        view_off += usize::from(classify(v.rgba[i]) != ref_classes[i]);
        let mask_dark = m.rgba[i][..3] == [0, 0, 0];
        mask_off += usize::from(mask_dark != (ref_classes[i] != Class::Lit));
    }
    let outside = band.iter().filter(|&&b| !b).count();
    println!("{outside} pixels outside the band; view differs in class at {view_off}, mask at {mask_off}; {bytes_differ} pixels differ in colour at all");
    assert_eq!(view_off, 0, "window screenshot and umbra render classify differently outside the band");
    assert_eq!(mask_off, 0, "mask view and umbra render classify differently outside the band");
}

#[test]
fn view_without_a_display_or_with_an_absent_one_says_so_and_suggests_render() {
    let out = Command::new(UMBRA)
        .args(["view", "default", "--size", "64x48"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("umbra view");
    assert_eq!(out.status.code(), Some(2), "an error exit");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no display") && err.contains("umbra render"), "{err}");

    // A display that is named but not there: the event loop cannot start.
    let out = Command::new(UMBRA)
        .args(["view", "default", "--size", "64x48"])
        .env("DISPLAY", ":987")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("umbra view");
    assert_eq!(out.status.code(), Some(2), "an error exit, not a panic");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot connect to the display server") && err.contains("umbra render"), "{err}");
}

#[test]
fn view_rejects_a_bad_script_naming_file_and_line() {
    let dir = out_dir();
    let script = dir.join("bad.path");
    std::fs::write(&script, "eye 1 2 3 target 0 0 0\neye 1 2 target 0 0 0\n").expect("script");
    // The script is checked before any window is opened: no display needed.
    let out = Command::new(UMBRA)
        .args(["view", "default", "--script"])
        .arg(&script)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("umbra view");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("{}:2:", script.display())), "{err}");
}

#[test]
fn view_wireframe_toggle_and_counter_flag_under_xvfb() {
    if !has_xvfb_run() {
        eprintln!("SKIPPED: xvfb-run not installed (apt-get install xvfb); umbra view needs a display");
        return;
    }
    let dir = out_dir();
    let plain = dir.join("wire-off.path");
    let wired = dir.join("wire-on.path");
    let poses = "eye 7 5 8 target 0 1 0\neye 5.5 4 6 target 0.2 0.9 0\n";
    std::fs::write(&plain, poses).expect("script");
    // Toggled on for the second (last) pose only.
    std::fs::write(&wired, "eye 7 5 8 target 0 1 0\nwireframe on\neye 5.5 4 6 target 0.2 0.9 0\n").expect("script");
    let (off_png, on_png, float_png) = (dir.join("wire-off.png"), dir.join("wire-on.png"), dir.join("float32.png"));
    view_screenshot(&plain, &off_png, &["--method", "cpu-silhouette", "--counter", "stencil8"]);
    view_screenshot(&wired, &on_png, &["--method", "cpu-silhouette", "--counter", "stencil8"]);
    view_screenshot(&plain, &float_png, &["--method", "cpu-silhouette", "--counter", "float32"]);
    let (off, on, float) = (read_png(&off_png), read_png(&on_png), read_png(&float_png));
    assert_eq!((on.width, on.height), (off.width, off.height));
    let total = off.rgba.len();
    let mut changed = 0;
    for (a, b) in off.rgba.iter().zip(&on.rgba) {
        if a != b {
            changed += 1;
            assert!(b[0] <= a[0] && b[1] <= a[1] && b[2] <= a[2], "the wireframe only darkens: {a:?} -> {b:?}");
        }
    }
    println!("wireframe changed {changed} of {total} pixels");
    assert!(changed > 100, "the wireframe changed only {changed} pixels");
    assert!(changed < total / 3, "the wireframe changed {changed} of {total} pixels: not lines");
    let float_differs = off.rgba.iter().zip(&float.rgba).filter(|(a, b)| a != b).count();
    assert_eq!(float_differs, 0, "--counter float32 and stencil8 screenshots differ in {float_differs} pixels");
}

#[test]
fn view_rejects_a_bad_counter_as_a_usage_error() {
    // Checked before any window is opened: no display needed.
    let out = Command::new(UMBRA)
        .args(["view", "default", "--counter", "int16"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("umbra view");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--counter") && err.contains("int16"), "{err}");
}

#[test]
fn view_rejects_a_bad_wireframe_toggle_naming_file_and_line() {
    let dir = out_dir();
    let script = dir.join("bad-toggle.path");
    std::fs::write(&script, "eye 1 2 3 target 0 0 0\nwireframe maybe\neye 1 2 4 target 0 0 0\n").expect("script");
    let out = Command::new(UMBRA)
        .args(["view", "default", "--script"])
        .arg(&script)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("umbra view");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("{}:2:", script.display())) && err.contains("wireframe"), "{err}");
}
