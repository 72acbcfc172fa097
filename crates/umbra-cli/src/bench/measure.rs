//! One measurement: drivers of the backends asked for, the interleaved schedule run over the
//! camera path, per-method statistics.

use super::driver::Driver;
use super::flythrough::Keyframe;
use super::gl_driver::GlDriver;
use super::options::MeasureOptions;
use super::progress::Progress;
use super::scene::BenchScene;
use super::schedule::schedule;
use super::stats::MethodStats;
use super::wgpu_driver::WgpuDriver;
use crate::backend::Backend;
use crate::config::ViewConfig;
use crate::error::CliError;
use crate::scenes::CameraConfig;

/// What the measurement saw besides the per-method stats.
pub struct Measurement {
    /// Per row of `stats`: its backend.
    pub backends: Vec<&'static str>,
    pub stats: Vec<MethodStats>,
    pub renderer: String,
    pub triangles: usize,
}

/// The view a measurement draws (the camera moves along `cameras`), shared by both backends.
pub fn bench_view(scene: &BenchScene, cameras: &[Keyframe], o: &MeasureOptions) -> Result<ViewConfig, CliError> {
    if cameras.is_empty() {
        return Err(CliError::Other("no frames to measure".into()));
    }
    Ok(ViewConfig {
        scene_spec: scene.spec.clone(),
        mesh: scene.mesh.clone(),
        camera: CameraConfig {
            eye: cameras[0].eye,
            target: cameras[0].target,
            up: [0.0, 1.0, 0.0],
            fov_y_degrees: o.fov,
            ortho: o.ortho,
        },
        lights: scene.lights.clone(),
        width: o.width,
        height: o.height,
        zpass: o.zpass,
        auto_zpass: o.auto_zpass,
        volume_cull: o.volume_cull,
        // Benchmarks draw both faces, as the papers' methods do.
        receivers: umbra_geom::Receivers::Both,
        ortho_far: None,
    })
}

/// One row of a measurement: method `method` of driver `driver`.
struct Entry {
    driver: usize,
    method: usize,
}

/// Runs the interleaved schedule of `entries` (driver, method) over `cameras` (one camera per
/// measured round; warm-up round r uses camera r): warm-up rounds first, then every entry once
/// per round in list order, so drift of a shared machine hits every method and backend alike.
fn run_schedule(
    drivers: &mut [Box<dyn Driver>],
    entries: &[Entry],
    names: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
) -> Vec<MethodStats> {
    let mut stats: Vec<MethodStats> = entries
        .iter()
        .zip(names)
        .map(|(e, name)| MethodStats {
            method: name.clone(),
            counter: drivers[e.driver].counter(e.method),
            ..Default::default()
        })
        .collect();
    let slots = schedule(entries.len(), o.warmup, cameras.len());
    let progress = Progress::new(slots.len(), &o.progress_label);
    for (i, slot) in slots.iter().enumerate() {
        let st = &mut stats[slot.method];
        if st.error.is_some() {
            continue;
        }
        let entry = &entries[slot.method];
        let driver = drivers[entry.driver].as_mut();
        progress.show(i, &st.method);
        if o.trace_order {
            eprintln!("bench-order {} {} {}", if slot.warmup { "warmup" } else { "frame" }, slot.round, st.method);
        }
        let cam = cameras[slot.round % cameras.len()];
        let frame_ms = match driver.frame(entry.method, cam) {
            Ok(ms) => ms,
            Err(e) => {
                eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                st.error = Some(e);
                continue;
            }
        };
        if o.log {
            let kind = if slot.warmup { "warmup" } else { "frame" };
            eprintln!("umbra bench: {} {kind} {} {} {frame_ms:.1} ms", o.progress_label, slot.round, st.method);
        }
        let zpass = driver.zpass_lights(entry.method);
        let stage_round = o.stage_every > 0 && (slot.warmup || slot.round % o.stage_every == 0);
        if stage_round {
            match driver.stages(entry.method, cam) {
                Ok(stages) if !slot.warmup => {
                    for (name, ms) in stages {
                        match st.stage_ms.iter_mut().find(|(n, _)| *n == name) {
                            Some((_, v)) => v.push(ms),
                            None => st.stage_ms.push((name, vec![ms])),
                        }
                    }
                }
                Ok(_) => {}
                Err(e) => {
                    eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                    st.error = Some(e);
                    continue;
                }
            }
            // Work counts in a frame of their own: the counters' atomics stay out of the
            // timed frames and the stage times.
            if !slot.warmup {
                // The volume passes' fragments too: reading the query waits for the pass.
                match driver.volume_counts(entry.method, cam) {
                    Ok(Some(v)) => st.volume.push(v),
                    Ok(None) => {}
                    Err(e) => {
                        eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                        st.error = Some(e);
                        continue;
                    }
                }
                match driver.work(entry.method, cam) {
                    Ok(Some(w)) => st.work.push(w),
                    Ok(None) => {}
                    Err(e) => {
                        eprintln!("umbra bench: {} failed, skipped from now on: {e}", st.method);
                        st.error = Some(e);
                        continue;
                    }
                }
            }
        }
        if !slot.warmup {
            st.frame_ms.push(frame_ms);
            st.zpass_lights += zpass;
            st.lights += driver.lights();
        }
    }
    progress.done();
    for (st, e) in stats.iter_mut().zip(entries) {
        st.gpu_bytes = drivers[e.driver].gpu_bytes(e.method);
        st.figures = drivers[e.driver].scene_figures(e.method);
        st.volume_cull = drivers[e.driver].volume_cull(e.method);
    }
    stats
}

/// Runs the interleaved schedule of `methods` over `cameras` on a fresh GL context.
pub fn measure(
    scene: &BenchScene,
    methods: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
) -> Result<Measurement, CliError> {
    measure_backends(scene, methods, cameras, o, &[Backend::Gl])
}

/// The same for every backend of `backends`, in ONE interleaved schedule (`--backend gl,wgpu`:
/// wgpu against GL in the same run). With several backends each row's method is labelled
/// `NAME@BACKEND` in the table (the JSON rows keep `method` and gain `backend`).
pub fn measure_backends(
    scene: &BenchScene,
    methods: &[String],
    cameras: &[Keyframe],
    o: &MeasureOptions,
    backends: &[Backend],
) -> Result<Measurement, CliError> {
    let view = bench_view(scene, cameras, o)?;
    let mut drivers: Vec<Box<dyn Driver>> = Vec::new();
    let mut entries = Vec::new();
    let mut names = Vec::new();
    for (d, &backend) in backends.iter().enumerate() {
        drivers.push(match backend {
            Backend::Gl => Box::new(GlDriver::new(&view, methods, o)?),
            Backend::Wgpu => Box::new(WgpuDriver::new(&view, methods, o)?),
        });
        for (m, name) in methods.iter().enumerate() {
            entries.push(Entry { driver: d, method: m });
            names.push(if backends.len() > 1 { format!("{name}@{}", backend.name()) } else { name.clone() });
        }
    }
    let stats = run_schedule(&mut drivers, &entries, &names, cameras, o);
    let backend_of: Vec<&'static str> = entries.iter().map(|e| drivers[e.driver].backend()).collect();
    Ok(Measurement {
        backends: backend_of,
        stats,
        renderer: drivers
            .iter()
            .map(|d| format!("{}: {}", d.backend(), d.device_name()))
            .collect::<Vec<_>>()
            .join("; "),
        triangles: drivers.first().map_or(0, |d| d.triangles()),
    })
}
