//! The winit example (a window with a host renderer of its own that uses umbra's shadows) run
//! for a few frames under a virtual X server (Debian's `xvfb-run`), single- and multisampled:
//! it must open its window, present every frame through lavapipe's X11 swapchain and exit 0.
//! Skipped, with a message, without `xvfb-run`, without the example binary (built by
//! `cargo test`), or without a wgpu adapter.

mod common;

use std::path::PathBuf;
use std::process::Command;

/// target/<profile>/examples/winit_host, next to this test's deps/ directory.
fn example_binary() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let profile = exe.parent()?.parent()?;
    let bin = profile.join("examples").join(format!("winit_host{}", std::env::consts::EXE_SUFFIX));
    bin.is_file().then_some(bin)
}

#[test]
fn winit_example_presents_frames_under_xvfb() {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        eprintln!("SKIPPED: xvfb-run not installed (apt-get install xvfb)");
        return;
    }
    let Some(bin) = example_binary() else {
        eprintln!("SKIPPED: the winit_host example is not built (cargo test builds it)");
        return;
    };
    if common::gpu().is_none() {
        return;
    }
    for extra in [&[][..], &["--msaa"][..]] {
        let out = Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 640x480x24"])
            .arg(&bin)
            .args(["--frames", "5"])
            .args(extra)
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("run xvfb-run");
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success(), "winit_host {extra:?} failed: {stdout}\n{stderr}");
        assert!(stdout.contains("cs-silhouette on ") && stdout.contains("5 frames in"), "{stdout}");
    }
}
