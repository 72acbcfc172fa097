//! `umbra bench --suite NAME`: the papers' benchmark tables as runnable suites.
//!
//! | suite | paper table | what |
//! | --- | --- | --- |
//! | `001-spheres` | 001 Table 3 | 10 x 10 spheres, 32,400 ... 1,960,000 triangles; TS/GS silhouettes, reference edge and 3-edge |
//! | `001-objects` | 001 Table 5 | 1M triangles over 1 ... 15,625 spheres |
//! | `001-vs-sm` | 001 Table 6 | ts-silhouette, hier-triangle and hier-silhouette vs 8K cube shadow map over the sphere sweep |
//! | `001-overall` | 001 Table 8 | per-triangle vs silhouette methods vs 8K shadow maps, Sponza and 4M-triangle spheres |
//! | `003-scenes` | 003 Tables 1-2 | Sponza, Conference, Sibenik fly-throughs: none, cube SM 1K-8K, every volume method |
//! | `003-stages` | 003 Tables 3-4 | stage breakdown of vs-silhouette, hier-triangle and hier-silhouette on the Sponza fly-through at 4 resolutions |
//!
//! Methods that are not registered are skipped with a note (checked at run time), so the
//! suites grow with the registry. Scene files are found in `$UMBRA_SCENES` (default
//! `shared/scenes` beside the workspace), fly-throughs in `$UMBRA_BENCH_DIR` (default
//! `bench/` of the workspace); a missing scene skips its run with a note. Default frame
//! counts keep each suite within minutes on a 2-core llvmpipe machine; `--frames`,
//! `--warmup`, `--methods`, `--size` and `--runs` override them.

use std::path::{Path, PathBuf};

use umbra_gl::method_names;

use crate::error::CliError;

/// How a suite's results are tabulated and plotted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Mean frame time over a swept parameter (rows), one column per method.
    Sweep,
    /// One run per scene fly-through; one column per scene.
    Scenes,
    /// Stage breakdown per resolution.
    Stages,
}

/// One measurement of a suite.
#[derive(Clone, Debug)]
pub struct Run {
    pub label: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub methods: Vec<String>,
    /// `orbit` or a fly-through file.
    pub path: String,
    /// The swept parameter (triangles, objects, megapixels), for tables and plots.
    pub x: f64,
}

pub struct Suite {
    pub name: &'static str,
    pub title: &'static str,
    pub kind: Kind,
    pub x_desc: &'static str,
    pub runs: Vec<Run>,
    pub frames: usize,
    pub warmup: usize,
    pub stage_every: usize,
    pub notes: Vec<String>,
}

pub const SUITES: [(&str, &str); 6] = [
    ("001-spheres", "paper 001 Table 3: 10x10 spheres, 32,400 ... 1,960,000 triangles, TS/GS silhouettes"),
    ("001-objects", "paper 001 Table 5: 1M triangles over 1 ... 15,625 objects"),
    ("001-vs-sm", "paper 001 Table 6: ts-silhouette, hier-triangle and hier-silhouette vs 8K cube shadow map over the sphere sweep"),
    ("001-overall", "paper 001 Table 8: per-triangle vs silhouette methods vs 8K shadow maps"),
    ("003-scenes", "paper 003 Tables 1-2: Sponza, Conference, Sibenik fly-throughs"),
    ("003-stages", "paper 003 Tables 3-4: stage breakdown on the Sponza fly-through at 4 resolutions"),
];

/// Sphere-triangle counts of paper 001 Table 3 (10 x 10 spheres).
pub const SPHERE_SWEEP: [u64; 7] = [32_400, 67_600, 102_400, 360_000, 1_081_600, 1_440_000, 1_960_000];
/// Sphere grid sides of the 1M-triangle object sweep (Table 5: 1 ... 15,600 objects).
pub const OBJECT_SWEEP: [u32; 10] = [1, 2, 5, 8, 10, 20, 25, 50, 71, 125];

pub fn scenes_dir() -> PathBuf {
    std::env::var_os("UMBRA_SCENES")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"))
}

pub fn bench_dir() -> PathBuf {
    std::env::var_os("UMBRA_BENCH_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench"))
}

fn sphere_spec(t: u64) -> String {
    if t == 32_400 {
        "spheres:10".into()
    } else {
        format!("spheres:10:{}", t + 2)
    }
}

/// Real scenes by short name: (label, file, fly-through file).
const REAL: [(&str, &str, &str); 3] = [
    ("sponza", "crytek-sponza.obj.gz", "sponza.flythrough"),
    ("conference", "conference.obj.gz", "conference.flythrough"),
    ("sibenik", "sibenik.obj.gz", "sibenik.flythrough"),
];

fn real(label: &str) -> (String, String) {
    let (_, file, fly) = REAL.iter().find(|(l, _, _)| *l == label).copied().unwrap_or(REAL[0]);
    (scenes_dir().join(file).display().to_string(), bench_dir().join(fly).display().to_string())
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// The suite definitions (before filtering methods that do not exist).
pub fn suite(name: &str) -> Result<Suite, CliError> {
    let ts_gs = strings(&["ts-silhouette", "ts-silhouette-3edge", "gs-silhouette", "gs-silhouette-3edge"]);
    let (w, h) = (800, 600);
    let run = |label: String, scene: String, width, height, methods: &Vec<String>, path: String, x: f64| Run {
        label,
        scene,
        width,
        height,
        methods: methods.clone(),
        path,
        x,
    };
    let s = match name {
        "001-spheres" => Suite {
            name: "001-spheres",
            title: SUITES[0].1,
            kind: Kind::Sweep,
            x_desc: "sphere triangles",
            runs: SPHERE_SWEEP
                .iter()
                .map(|&t| run(format!("{t}"), sphere_spec(t), w, h, &ts_gs, "orbit".into(), t as f64))
                .collect(),
            frames: 4,
            warmup: 1,
            stage_every: 0,
            notes: vec![],
        },
        "001-objects" => Suite {
            name: "001-objects",
            title: SUITES[1].1,
            kind: Kind::Sweep,
            x_desc: "objects (spheres)",
            runs: OBJECT_SWEEP
                .iter()
                .map(|&n| {
                    let objects = u64::from(n) * u64::from(n);
                    run(format!("{objects}"), format!("spheres:{n}:1M"), w, h, &ts_gs, "orbit".into(), objects as f64)
                })
                .collect(),
            frames: 4,
            warmup: 1,
            stage_every: 0,
            notes: vec![
                "The renderer draws the whole scene in ONE draw call, so the per-object draw-call overhead that dominates \
                 the paper's Table 5 beyond ~1000 objects is absent here; what remains is the change in silhouette size."
                    .into(),
            ],
        },
        "001-vs-sm" => {
            // hier-triangle and hier-silhouette against the 8K map at every size.
            let methods = strings(&["ts-silhouette", "hier-triangle", "hier-silhouette", "shadow-map-cube:8192"]);
            Suite {
                name: "001-vs-sm",
                title: SUITES[2].1,
                kind: Kind::Sweep,
                x_desc: "sphere triangles",
                runs: SPHERE_SWEEP
                    .iter()
                    .map(|&t| run(format!("{t}"), sphere_spec(t), w, h, &methods, "orbit".into(), t as f64))
                    .collect(),
                frames: 4,
                warmup: 1,
                stage_every: 0,
                notes: vec!["Paper 001 used a single 8K map for its point light; here it is an 8K cube map (6 faces).".into()],
            }
        }
        "001-overall" => {
            // Paper 001's per-triangle and silhouette methods (not hier-triangle and
            // hier-silhouette, which are 001-vs-sm's and 003-scenes' and would add hours on the
            // 4M spheres: docs/benchmarks.md).
            let mut methods: Vec<String> = method_names()
                .iter()
                .filter(|n| n.contains("triangle") && !n.starts_with("hier"))
                .map(|s| s.to_string())
                .collect();
            methods.extend(
                method_names().iter().filter(|n| n.contains("silhouette") && !n.starts_with("hier")).map(|s| s.to_string()),
            );
            methods.push("shadow-map-cube:8192".into());
            let (sponza, fly) = real("sponza");
            Suite {
                name: "001-overall",
                title: SUITES[3].1,
                kind: Kind::Scenes,
                x_desc: "scene",
                runs: vec![
                    run("sponza".into(), sponza, 1280, 720, &methods, fly, 0.0),
                    run("spheres 4M".into(), "spheres:10:4000000".into(), 1280, 720, &methods, "orbit".into(), 1.0),
                ],
                frames: 3,
                warmup: 1,
                stage_every: 0,
                notes: vec![],
            }
        }
        "003-scenes" => {
            let mut methods = strings(&[
                "none",
                "shadow-map-cube:1024",
                "shadow-map-cube:2048",
                "shadow-map-cube:4096",
                "shadow-map-cube:8192",
                "vs-silhouette",
            ]);
            for n in method_names() {
                if !methods.iter().any(|m| m == n) && !n.starts_with("shadow-map") {
                    methods.push(n.to_string());
                }
            }
            Suite {
                name: "003-scenes",
                title: SUITES[4].1,
                kind: Kind::Scenes,
                x_desc: "scene",
                runs: REAL
                    .iter()
                    .enumerate()
                    .map(|(i, (label, _, _))| {
                        let (scene, fly) = real(label);
                        run(label.to_string(), scene, 1920, 1080, &methods, fly, i as f64)
                    })
                    .collect(),
                frames: 8,
                warmup: 1,
                stage_every: 0,
                notes: vec![],
            }
        }
        "003-stages" => {
            let (sponza, fly) = real("sponza");
            // hier-triangle and hier-silhouette: how their shadow stage grows with the pixels.
            let methods = strings(&["vs-silhouette", "hier-triangle", "hier-silhouette"]);
            Suite {
                name: "003-stages",
                title: SUITES[5].1,
                kind: Kind::Stages,
                x_desc: "megapixels",
                runs: [(800, 600), (1920, 1080), (2560, 1600), (3840, 2160)]
                    .iter()
                    .map(|&(w, h)| {
                        run(format!("{w}x{h}"), sponza.clone(), w, h, &methods, fly.clone(), f64::from(w * h) / 1e6)
                    })
                    .collect(),
                frames: 6,
                warmup: 1,
                stage_every: 1,
                notes: vec![
                    "vs-silhouette evaluates the silhouette in the vertex shader of the sides draw, so paper 003's stages 2 \
                     (silhouette evaluation) and 3 (rasterisation) are one stage, \"sides\", here."
                        .into(),
                ],
            }
        }
        other => {
            let known: Vec<&str> = SUITES.iter().map(|(n, _)| *n).collect();
            return Err(CliError::BadFlag {
                flag: "--suite",
                message: format!("unknown suite {other:?}; known: {} (or `list`)", known.join(", ")),
            });
        }
    };
    Ok(s)
}

/// `--suite list`: every suite with its title, one per line.
pub fn list() {
    for (n, t) in SUITES {
        println!("{n:<12} {t}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_suite_is_defined_and_sweeps_match_the_papers() {
        for (name, _) in SUITES {
            let s = suite(name).expect(name);
            assert!(!s.runs.is_empty() && s.frames > 0, "{name}");
        }
        let sp = suite("001-spheres").expect("defined");
        assert_eq!(sp.runs.len(), 7);
        assert_eq!(sp.runs[0].scene, "spheres:10");
        // spheres:10:T (T = sphere triangles + 2 ground) is within 2% of Table 3's count.
        for (r, &t) in sp.runs.iter().zip(&SPHERE_SWEEP) {
            let spec = umbra_geom::scene::parse(&r.scene).expect("valid spec");
            let n = spec.triangle_count().expect("procedural");
            assert!((n as f64 - t as f64).abs() <= 0.02 * t as f64 + 2.0, "{}: {n} vs {t}", r.scene);
        }
        let ob = suite("001-objects").expect("defined");
        assert_eq!(ob.runs.last().map(|r| r.x), Some(15_625.0));
        for r in &ob.runs {
            assert!(umbra_geom::scene::parse(&r.scene).is_ok(), "{}", r.scene);
        }
        assert!(suite("nope").is_err());
    }
}
