//! A real corpus nobody here wrote: every OBJ, PLY, STL, glTF and GLB file (and `.gz`) of
//! Debian's `assimp-testmodels` (`/usr/share/assimp/models`, installed by `.ci/run`),
//! including its deliberately broken `invalid/` files.
//!
//! Each file either loads — and then goes through weld + edge adjacency + multiplicity — or
//! returns a typed [`LoadError`] whose message names the file and a place (line, byte
//! offset or JSON path). A panic is reported as a failure naming the file (caught with
//! `catch_unwind`), a file with no result after [`TIME_LIMIT`] (a non-termination watchdog, not a speed
//! check) is reported as a hang, and
//! memory is bounded by [`LoadOptions::max_input_bytes`].
//!
//! `UMBRA_ASSIMP_MODELS` overrides the corpus directory; the test skips with a message when
//! it is absent. With `UMBRA_CORPUS_TABLE=FILE` it writes the per-file outcome as a
//! Markdown table (used for docs/robustness.md).

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use umbra_geom::load::{self, Format, LoadError, LoadOptions};
use umbra_geom::{multiplicity, EdgeAdjacency, WeldedMesh};

/// Non-termination watchdog per file (load + weld + adjacency + multiplicity): a file with no
/// result after this long is reported as a hang, by name, instead of stalling the whole test.
/// It detects loops that never end, not slowness: the slowest corpus file took 35 ms here
/// (the table's last column, in ms). Speed is a benchmark.
const TIME_LIMIT: Duration = Duration::from_secs(300);
/// Memory bound: no corpus file is larger than a few MiB.
const MAX_INPUT_BYTES: u64 = 256 << 20;

fn corpus_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("UMBRA_ASSIMP_MODELS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/share/assimp/models"));
    dir.is_dir().then_some(dir)
}

/// Whether the loaders handle `path` by its extension (`x.obj`, `x.GLB`, `x.ply.gz`).
fn supported(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("").to_ascii_lowercase();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    Path::new(name).extension().and_then(|e| e.to_str()).and_then(Format::from_extension).is_some()
}

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            collect(&path, out);
        } else if path.is_file() && supported(&path) {
            out.push(path);
        }
    }
}

/// What happened to one file.
#[derive(Debug)]
enum Outcome {
    Loaded {
        triangles: usize,
        vertices: usize,
        welded_triangles: usize,
        edges: usize,
        max_opposites: usize,
        warnings: usize,
    },
    Error(String),
    Panic(String),
    Hang,
}

/// Loads `path` and runs the geometry pipeline on it; a panic message on panic.
fn process(path: &Path) -> Result<Result<Outcome, String>, String> {
    let options = LoadOptions { max_input_bytes: MAX_INPUT_BYTES };
    let path = path.to_path_buf();
    std::panic::catch_unwind(move || {
        let loaded = match load::load_path_detailed(&path, &options) {
            Ok(l) => l,
            Err(e) => return check_error(&path, &e),
        };
        let mesh = &loaded.mesh;
        let n = mesh.positions.len();
        if let Some(t) = mesh.triangles.iter().find(|t| t.iter().any(|&i| i as usize >= n)) {
            return Err(format!("loaded triangle {t:?} indexes past {n} vertices"));
        }
        if mesh.normals.as_ref().is_some_and(|v| v.len() != n) {
            return Err("normals and positions differ in length".into());
        }
        let welded = WeldedMesh::from_mesh(mesh);
        let adjacency = EdgeAdjacency::build(&welded);
        let light = mesh.bounds().map_or([0.0, 10.0, 0.0, 1.0], |b| {
            let c = b.center();
            [c[0] + 0.3 * b.diagonal(), c[1] + b.diagonal(), c[2] + 0.2 * b.diagonal(), 1.0]
        });
        let mut opposites_seen = 0usize;
        for e in 0..adjacency.len() {
            let ops = adjacency.opposites(e);
            let m = multiplicity::edge_multiplicity(&welded.positions, adjacency.edges[e], ops, light);
            if m.unsigned_abs() as usize > ops.len() {
                return Err(format!("edge {e}: |multiplicity| {m} exceeds its {} opposites", ops.len()));
            }
            opposites_seen += ops.len();
        }
        if opposites_seen != 3 * welded.triangles.len() {
            return Err(format!("adjacency holds {opposites_seen} opposites for {} triangles", welded.triangles.len()));
        }
        Ok(Outcome::Loaded {
            triangles: mesh.triangles.len(),
            vertices: n,
            welded_triangles: welded.triangles.len(),
            edges: adjacency.len(),
            max_opposites: adjacency.max_opposites(),
            warnings: loaded.warnings.len(),
        })
    })
    .map_err(|payload| {
        payload
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "non-string panic payload".into())
    })
}

/// An error must name the file and a place in it.
fn check_error(path: &Path, e: &LoadError) -> Result<Outcome, String> {
    let message = e.to_string();
    // errors about a referenced file (a glTF's .bin) name that file instead
    let names_a_file = message.contains(&path.display().to_string())
        || e.file().starts_with(&path.parent().unwrap_or(path).display().to_string());
    if !names_a_file {
        return Err(format!("error does not name the file: {message}"));
    }
    let has_place = e.location().is_some() || message.contains("byte offset");
    if !has_place {
        return Err(format!("error names no line, byte offset or JSON path: {message}"));
    }
    Ok(Outcome::Error(message))
}

/// Runs [`process`] in its own thread with [`TIME_LIMIT`]; a hung thread is left behind.
fn run_one(path: &Path) -> Result<Outcome, String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    std::thread::Builder::new()
        .name(format!("corpus {}", path.display()))
        .spawn(move || {
            let _ = tx.send(process(&p));
        })
        .map_err(|e| format!("cannot spawn a thread: {e}"))?;
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(Ok(result)) => result,
        Ok(Err(panic)) => Ok(Outcome::Panic(panic)),
        Err(_) => Ok(Outcome::Hang),
    }
}

fn table_row(rel: &str, outcome: &Result<Outcome, String>, ms: u128) -> String {
    let cell = |s: &str| s.replace('|', "\\|").replace('\n', " ");
    match outcome {
        Ok(Outcome::Loaded { triangles, vertices, welded_triangles, edges, max_opposites, warnings }) => format!(
            "| `{rel}` | loaded | {triangles} triangles, {vertices} vertices; welded {welded_triangles} triangles, {edges} edges, max {max_opposites} opposites{} | {ms} |",
            if *warnings > 0 { format!("; {warnings} warning(s)") } else { String::new() }
        ),
        Ok(Outcome::Error(m)) => {
            // the message without the (long) directory prefix
            let m = m.replace("/usr/share/assimp/models/", "");
            format!("| `{rel}` | error | {} | {ms} |", cell(&m))
        }
        Ok(Outcome::Panic(m)) => format!("| `{rel}` | **PANIC** | {} | {ms} |", cell(m)),
        Ok(Outcome::Hang) => format!("| `{rel}` | **HANG** | over {} s | {ms} |", TIME_LIMIT.as_secs()),
        Err(m) => format!("| `{rel}` | **FAIL** | {} | {ms} |", cell(m)),
    }
}

#[test]
fn every_assimp_model_loads_or_fails_cleanly() {
    let Some(dir) = corpus_dir() else {
        eprintln!("skipped: /usr/share/assimp/models is absent (apt-get install assimp-testmodels, or set UMBRA_ASSIMP_MODELS)");
        return;
    };
    let mut files = Vec::new();
    collect(&dir, &mut files);
    files.sort();
    assert!(!files.is_empty(), "{} holds no OBJ/PLY/STL/glTF/GLB files", dir.display());
    let mut failures = Vec::new();
    let mut rows = Vec::new();
    let (mut loaded, mut errors) = (0, 0);
    for path in &files {
        let rel = path.strip_prefix(&dir).unwrap_or(path).display().to_string();
        let start = Instant::now();
        let outcome = run_one(path);
        let ms = start.elapsed().as_millis();
        match &outcome {
            Ok(Outcome::Loaded { .. }) => loaded += 1,
            Ok(Outcome::Error(_)) => errors += 1,
            Ok(Outcome::Panic(m)) => failures.push(format!("{rel}: panicked: {m}")),
            Ok(Outcome::Hang) => failures.push(format!("{rel}: no result within {} s", TIME_LIMIT.as_secs())),
            Err(m) => failures.push(format!("{rel}: {m}")),
        }
        rows.push(table_row(&rel, &outcome, ms));
    }
    eprintln!(
        "assimp corpus: {} files, {loaded} loaded, {errors} typed errors, {} failures",
        files.len(),
        failures.len()
    );
    if let Some(out) = std::env::var_os("UMBRA_CORPUS_TABLE") {
        let mut text = String::from("| file | outcome | details | ms |\n| --- | --- | --- | ---: |\n");
        for r in &rows {
            text.push_str(r);
            text.push('\n');
        }
        std::fs::write(&out, text).expect("write UMBRA_CORPUS_TABLE");
    }
    assert!(failures.is_empty(), "{} of {} files failed:\n{}", failures.len(), files.len(), failures.join("\n"));
}
