//! Running a `bench --suite`: every selected run measured in turn, then the suite's table
//! (sweep, scenes or stages) and plots.

use std::path::Path;

use super::measure::{measure, Measurement};
use super::options::MeasureOptions;
use super::output::{json_rows, load_average, print_table, write_plots, JsonRow};
use super::plot;
use super::scene::{camera_path, BenchScene};
use super::suites::{Kind, Run, Suite};
use crate::config::BenchConfig;
use crate::error::CliError;
use crate::methods::method_exists;

/// Runs suite `s` ([`crate::config::BenchMode::Suite`]: its selected runs, with
/// `override_methods` and `override_size` in place of each run's own) with the settings of `c`,
/// and prints (or writes) its tables.
pub fn run(
    c: &BenchConfig,
    s: &Suite,
    override_methods: Option<&[String]>,
    override_size: Option<(u32, u32)>,
    frames: usize,
) -> Result<(), CliError> {
    let mut notes = s.notes.clone();
    let mut rows: Vec<JsonRow> = Vec::new();
    let mut results: Vec<(Run, Measurement)> = Vec::new();
    let mut renderer = String::new();
    let load_before = load_average();
    let started = std::time::Instant::now();
    let total = s.runs.len();
    for (i, r) in s.runs.iter().enumerate() {
        let mut r = r.clone();
        if let Some(m) = override_methods {
            r.methods = m.to_vec();
        }
        if let (Some((w, h)), false) = (override_size, s.kind == Kind::Stages) {
            r.width = w;
            r.height = h;
        }
        let (present, missing): (Vec<String>, Vec<String>) = r.methods.iter().cloned().partition(|m| method_exists(m));
        for m in &missing {
            let note = format!("{m}: not registered yet, skipped");
            if !notes.contains(&note) {
                notes.push(note);
            }
        }
        if present.is_empty() {
            notes.push(format!("run {}: no registered method, skipped", r.label));
            continue;
        }
        if !r.scene.starts_with("spheres:") && !Path::new(&r.scene).exists() {
            notes.push(format!("run {}: scene {} not found (set UMBRA_SCENES), skipped", r.label, r.scene));
            continue;
        }
        eprintln!("umbra bench: suite {} run {}/{total}: {} at {}x{}", s.name, i + 1, r.label, r.width, r.height);
        let label = format!("{} {}", s.name, r.label);
        let o = MeasureOptions::for_run(c, r.width, r.height, s.warmup, s.stage_every, &label);
        let scene = BenchScene::load(&r.scene, false, c.max_input_bytes, &c.lights)?;
        let cameras = camera_path(&r.path, &scene, frames)?;
        let m = measure(&scene, &present, &cameras, &o)?;
        renderer = m.renderer.clone();
        rows.extend(json_rows(&m, &r.scene, r.width, r.height, Some(&r.label), Some(r.x)));
        if let (Some(p), Kind::Scenes) = (&c.plot, s.kind) {
            write_plots(
                &plot::tagged_path(Path::new(p), &r.label),
                &format!("{} {}x{}", r.label, r.width, r.height),
                &m,
            )?;
        }
        results.push((r, m));
    }
    let load_after = load_average();
    if let Some(p) = &c.plot {
        suite_plot(Path::new(p), s, &results)?;
    }
    if c.json {
        println!("{}", serde_json::to_string_pretty(&rows).map_err(|e| CliError::Other(e.to_string()))?);
        for n in &notes {
            eprintln!("umbra bench: note: {n}");
        }
        return Ok(());
    }
    println!("## {} — {}", s.name, s.title);
    println!();
    println!(
        "{renderer}; {frames} frame(s) + {} warm-up per method and run; load average {} before, {} after; {:.0} s",
        c.warmup.unwrap_or(s.warmup),
        load_before.as_deref().unwrap_or("?"),
        load_after.as_deref().unwrap_or("?"),
        started.elapsed().as_secs_f64()
    );
    println!();
    print_suite_table(s, &results);
    for n in &notes {
        println!();
        println!("Note: {n}");
    }
    Ok(())
}

fn cell(m: &Measurement, method: &str) -> String {
    match m.stats.iter().find(|s| s.method == method) {
        Some(s) => match (s.mean(), &s.error) {
            (Some(v), _) => format!("{v:.1}"),
            (None, Some(_)) => "error".into(),
            (None, None) => "-".into(),
        },
        None => "-".into(),
    }
}

fn all_methods(results: &[(Run, Measurement)]) -> Vec<String> {
    let mut methods: Vec<String> = Vec::new();
    for (_, m) in results {
        for s in &m.stats {
            if !methods.contains(&s.method) {
                methods.push(s.method.clone());
            }
        }
    }
    methods
}

/// Mean frame time (ms) tables.
pub fn print_suite_table(s: &Suite, results: &[(Run, Measurement)]) {
    let methods = all_methods(results);
    match s.kind {
        Kind::Sweep => {
            println!("Mean frame time in ms (lower is better).");
            println!();
            println!("| {} | triangles | {} |", s.x_desc, methods.join(" | "));
            println!("|{}", " ---: |".repeat(2 + methods.len()));
            for (r, m) in results {
                let cells: Vec<String> = methods.iter().map(|n| cell(m, n)).collect();
                println!("| {} | {} | {} |", r.label, m.triangles, cells.join(" | "));
            }
        }
        Kind::Scenes => {
            println!("Mean frame time in ms (lower is better).");
            println!();
            let labels: Vec<String> = results
                .iter()
                .map(|(r, m)| format!("{} ({}x{}, {} tris)", r.label, r.width, r.height, m.triangles))
                .collect();
            println!("| method | {} |", labels.join(" | "));
            println!("| --- |{}", " ---: |".repeat(results.len()));
            for n in &methods {
                let cells: Vec<String> = results.iter().map(|(_, m)| cell(m, n)).collect();
                println!("| {n} | {} |", cells.join(" | "));
            }
            for (r, m) in results {
                if m.stats.iter().any(|st| !st.stage_ms.is_empty()) {
                    println!();
                    println!("### {} ({}x{}): frame statistics and mean stage times (ms)", r.label, r.width, r.height);
                    println!();
                    print_table(m);
                }
            }
        }
        Kind::Stages => {
            for (r, m) in results {
                println!("### {} ({} frames measured)", r.label, m.stats.first().map_or(0, |s| s.frame_ms.len()));
                println!();
                print_table(m);
                println!();
            }
        }
    }
}

fn suite_plot(path: &Path, s: &Suite, results: &[(Run, Measurement)]) -> Result<(), CliError> {
    match s.kind {
        Kind::Sweep => {
            let series: Vec<(String, Vec<(f64, f64)>)> = all_methods(results)
                .into_iter()
                .map(|n| {
                    let pts = results
                        .iter()
                        .filter_map(|(r, m)| {
                            m.stats.iter().find(|st| st.method == n).and_then(|st| st.mean()).map(|v| (r.x, v))
                        })
                        .collect();
                    (n, pts)
                })
                .collect();
            plot::lines(path, s.title, s.x_desc, "mean ms per frame", &series, true)
        }
        Kind::Scenes => Ok(()),
        Kind::Stages => {
            let mut stage_names: Vec<String> = Vec::new();
            for (_, m) in results {
                for st in &m.stats {
                    for (n, _) in &st.stage_ms {
                        if !stage_names.contains(n) {
                            stage_names.push(n.clone());
                        }
                    }
                }
            }
            let rows: Vec<(String, Vec<f64>)> = results
                .iter()
                .flat_map(|(r, m)| {
                    let names = &stage_names;
                    m.stats.iter().map(move |st| {
                        let means = st.stage_means();
                        (
                            format!("{} {}", st.method, r.label),
                            names.iter().map(|n| means.iter().find(|(k, _)| k == n).map_or(0.0, |(_, v)| *v)).collect(),
                        )
                    })
                })
                .collect();
            plot::stacked_bars(path, s.title, &stage_names, &rows)
        }
    }
}
