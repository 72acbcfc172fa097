//! What a measurement prints and writes: `--json` rows, `--csv` lines, the Markdown table,
//! `--plot` SVGs.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use super::measure::Measurement;
use super::plot;
use crate::error::CliError;

/// One object of `bench --json`; the first seven keys are the contract.
#[derive(Serialize, Debug, Clone)]
pub struct JsonRow {
    pub method: String,
    pub frames: usize,
    pub mean_ms: Option<f64>,
    pub median_ms: Option<f64>,
    pub p95_ms: Option<f64>,
    /// Stage name -> mean ms over the stage-timed frames.
    pub stages: BTreeMap<String, f64>,
    pub gpu_bytes: usize,
    /// Work counts (dispatches, nodes_tested, leaves_tested, nodes_pruned), mean per counted
    /// frame (the stage-timed rounds); only for methods that count work.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work: Option<BTreeMap<String, f64>>,
    pub scene: String,
    pub triangles: usize,
    /// "stencil8", "float32", or "none" (the method does not count in the stencil).
    pub counter: String,
    /// Share of the measured frames' lights counted z-pass (`--zmode`), 0 to 1.
    pub zpass_share: f64,
    /// Whether the method's volumes were culled and clamped against the receivers
    /// (`--volume-cull`, methods that can).
    pub volume_cull: bool,
    /// Fragments the volume passes rasterized per frame (summed over lights; mean of the
    /// counted frames, the stage-timed rounds), counted by `volume_fragments_query`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_fragments: Option<f64>,
    /// "fragment_shader_invocations" (GL_FRAGMENT_SHADER_INVOCATIONS) or "samples_passed"
    /// (GL_SAMPLES_PASSED, without ARB_pipeline_statistics_query); with `volume_fragments`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_fragments_query: Option<&'static str>,
    /// Caster triangles not dropped by the receiver cull, per frame (summed over lights).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_triangles: Option<f64>,
    /// Silhouette edges drawn, with multiplicity (side quads), per frame (summed over lights).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volume_edges: Option<f64>,
    pub width: u32,
    pub height: u32,
    /// "gl" or "wgpu" (`--backend`).
    pub backend: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The method's per-scene preprocessing figures as keys of their own (ray-bvh:
    /// `bvh_build_ms`, `bvh_bytes`, `bvh_nodes`, `bvh_depth`); none for most methods.
    #[serde(flatten)]
    pub figures: BTreeMap<String, f64>,
}

pub fn json_rows(
    m: &Measurement,
    scene: &str,
    width: u32,
    height: u32,
    run: Option<&str>,
    x: Option<f64>,
) -> Vec<JsonRow> {
    m.stats
        .iter()
        .zip(&m.backends)
        .map(|(s, &backend)| JsonRow {
            method: s.method.split('@').next().unwrap_or(&s.method).to_string(),
            frames: s.frame_ms.len(),
            mean_ms: s.mean(),
            median_ms: s.median(),
            p95_ms: s.p95(),
            stages: s.stage_means().into_iter().collect(),
            gpu_bytes: s.gpu_bytes,
            work: (!s.work.is_empty()).then(|| s.work_means().into_iter().map(|(k, v)| (k.to_string(), v)).collect()),
            scene: scene.to_string(),
            triangles: m.triangles,
            counter: s.counter.clone(),
            zpass_share: if s.lights == 0 { 0.0 } else { s.zpass_lights as f64 / s.lights as f64 },
            volume_cull: s.volume_cull,
            volume_fragments: s.volume_means().0,
            volume_fragments_query: s.volume_fragments_query(),
            volume_triangles: s.volume_means().1.map(|v| v.0),
            volume_edges: s.volume_means().1.map(|v| v.1),
            width,
            height,
            backend: backend.to_string(),
            run: run.map(str::to_string),
            x,
            error: s.error.clone(),
            figures: s.figures.iter().map(|&(k, v)| (k.to_string(), v)).collect(),
        })
        .collect()
}

/// Per-frame samples in long form: `scene,width,height,method,frame,kind,name,ms` with kind
/// `frame` (whole frame) or `stage`.
pub fn csv_lines(m: &Measurement, scene: &str, width: u32, height: u32, stage_every: usize) -> Vec<String> {
    let mut out = Vec::new();
    let q = |s: &str| if s.contains([',', '"']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() };
    for s in &m.stats {
        for (f, ms) in s.frame_ms.iter().enumerate() {
            out.push(format!("{},{width},{height},{},{f},frame,total,{ms:.4}", q(scene), q(&s.method)));
        }
        for (name, v) in &s.stage_ms {
            for (k, ms) in v.iter().enumerate() {
                let f = k * stage_every.max(1);
                out.push(format!("{},{width},{height},{},{f},stage,{},{ms:.4}", q(scene), q(&s.method), q(name)));
            }
        }
    }
    out
}

pub const CSV_HEADER: &str = "scene,width,height,method,frame,kind,name,ms";

/// The 1-, 5- and 15-minute load averages (Linux), for the record.
pub fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    Some(s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

fn fmt_ms(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.2}"))
}

/// Markdown table of one measurement.
pub fn print_table(m: &Measurement) {
    let mut stage_names: Vec<String> = Vec::new();
    for s in &m.stats {
        for (n, _) in &s.stage_ms {
            if !stage_names.contains(n) {
                stage_names.push(n.clone());
            }
        }
    }
    let work_names: Vec<&'static str> = if m.stats.iter().any(|s| !s.work.is_empty()) {
        umbra_gl::WorkCounts::default().entries().map(|(k, _)| k).to_vec()
    } else {
        Vec::new()
    };
    let mut header = "| method | frames | mean ms | median ms | p95 ms | GPU MiB |".to_string();
    for n in &stage_names {
        header.push_str(&format!(" {n} |"));
    }
    for n in &work_names {
        header.push_str(&format!(" {n} |"));
    }
    println!("{header}");
    println!("|{}", " --- |".repeat(6 + stage_names.len() + work_names.len()));
    for s in &m.stats {
        let means = s.stage_means();
        let mut row = format!(
            "| {} | {} | {} | {} | {} | {:.1} |",
            s.method,
            s.frame_ms.len(),
            fmt_ms(s.mean()),
            fmt_ms(s.median()),
            fmt_ms(s.p95()),
            s.gpu_bytes as f64 / (1024.0 * 1024.0)
        );
        for n in &stage_names {
            row.push_str(&format!(" {} |", fmt_ms(means.iter().find(|(k, _)| k == n).map(|(_, v)| *v))));
        }
        let work = s.work_means();
        for n in &work_names {
            let v = work.iter().find(|(k, _)| k == n).map(|(_, v)| *v);
            row.push_str(&format!(" {} |", v.map_or_else(|| "-".into(), |x| format!("{x:.0}"))));
        }
        if let Some(e) = &s.error {
            row.push_str(&format!(" error: {e}"));
        }
        println!("{row}");
    }
}

/// Frame-time plot (`path`) and stage plot (`path`-stages.svg).
pub fn write_plots(path: &Path, title: &str, m: &Measurement) -> Result<(), CliError> {
    let series: Vec<(String, Vec<(f64, f64)>)> = m
        .stats
        .iter()
        .filter(|s| !s.frame_ms.is_empty())
        .map(|s| (s.method.clone(), s.frame_ms.iter().enumerate().map(|(f, &ms)| (f as f64, ms)).collect()))
        .collect();
    plot::lines(path, &format!("{title}: frame time along the path"), "frame", "ms", &series, false)?;
    let mut stage_names: Vec<String> = Vec::new();
    for s in &m.stats {
        for (n, _) in &s.stage_ms {
            if !stage_names.contains(n) {
                stage_names.push(n.clone());
            }
        }
    }
    let rows: Vec<(String, Vec<f64>)> = m
        .stats
        .iter()
        .filter(|s| !s.stage_ms.is_empty())
        .map(|s| {
            let means = s.stage_means();
            (
                s.method.clone(),
                stage_names.iter().map(|n| means.iter().find(|(k, _)| k == n).map_or(0.0, |(_, v)| *v)).collect(),
            )
        })
        .collect();
    plot::stacked_bars(&plot::stages_path(path), &format!("{title}: stages"), &stage_names, &rows)
}
