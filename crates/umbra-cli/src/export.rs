//! `umbra export`: paper 003's preprocessed scene for a browser.
//!
//! Paper 003 (Milet et al., "Fast robust and precise shadow algorithm for WebGL 1.0
//! platform"), Section 2.6: the sides-data and caps-data are built once, stored beside the
//! scene and downloaded; the browser's vertex shaders only evaluate them. This module writes
//! exactly the buffers the native `vs-silhouette` method uploads — same builders
//! ([`umbra_geom::sides_data::build_sides_data`] / [`umbra_geom::sides_data::build_caps_data`]),
//! same layout and `maxMult` (16 vertex attributes, the minimum of OpenGL 4.5, OpenGL ES 3.0 and
//! WebGL 2, and what `umbra info` reports) — plus the drawable welded mesh and a JSON manifest.
//! The buffers come from [`umbra_geom::export_buffers`], which umbra-wasm runs in a browser.
//! Every file is little-endian binary a browser fetches as one ArrayBuffer:
//!
//! | buffer | file | contents | bytes |
//! | --- | --- | --- | --- |
//! | `positions` | `positions.bin` | welded vertex positions, 3 × f32 | `12 v` |
//! | `normals` | `normals.bin` | flat unit normal per triangle (the renderer's, computed in f64), 3 × f32 | `12 t` |
//! | `indices` | `indices.bin` | triangles, 3 × u32, counter-clockwise = front | `12 t` |
//! | `sides_data` | `sides.bin` | `2 + maxMult` vec4 per edge record (Eq. 8) | `16 (2 + maxMult) e` |
//! | `caps_data` | `caps.bin` | 3 vec4 per triangle (Eq. 9) | `48 t` |
//! | `edge_triangles` | `edge_triangles.bin` | per edge record, `maxMult` × i32: the signed triangle behind each opposite slot ([`umbra_geom::edge_triangles`]) | `4 maxMult e` |
//!
//! The manifest (`manifest.json`, [`Manifest`]) states the format version, the counts,
//! `maxMult`, the bounds, every buffer's file, byte offset and byte size, and the light and
//! camera `umbra render` would use for the same scene (the same [`ViewConfig`] derivation).
//! [`read_manifest`] reads one back with typed errors that name the file and the JSON path
//! (`manifest.json: $.buffers.sides_data.bytes: …`); [`check_export`] also checks every
//! buffer file's length (`umbra export --check DIR`).
//!
//! `edge_triangles` lets the viewer orient every triangle once per light and let the sides and
//! the caps read that one value (docs/web.md): it says which triangle each opposite slot of the
//! sides-data stands for.

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde_json::Value;
use umbra_geom::export_buffers::{build_export_buffers, le_bytes};
use umbra_geom::sides_data::{caps_data_bytes, sides_data_bytes, MAX_MULT_LIMIT};
use umbra_geom::weld::weld;
use umbra_geom::Aabb;

use crate::config::{ExportConfig, ViewConfig};
use crate::error::CliError;

/// `format` of every manifest this module writes.
pub const FORMAT: &str = "umbra-export";
/// Manifest version; readers reject any other (the viewer checks it too).
pub const VERSION: u64 = 2;
/// The manifest's file name inside the export directory.
pub const MANIFEST: &str = "manifest.json";
/// One buffer: which file, where in it, how many bytes, and how to read them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BufferRef {
    pub file: String,
    pub offset: u64,
    pub bytes: u64,
    /// `f32`, `u32` or `i32`, little-endian.
    pub component_type: String,
    /// Components per element (3 for positions, normals, indices; 4 for the vec4 records).
    pub components: u64,
    /// Elements (vertices, triangles, vec4s).
    pub count: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Buffers {
    pub positions: BufferRef,
    pub normals: BufferRef,
    pub indices: BufferRef,
    pub sides_data: BufferRef,
    pub caps_data: BufferRef,
    pub edge_triangles: BufferRef,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Counts {
    /// Welded vertices.
    pub vertices: u64,
    /// Welded, non-degenerate triangles (`t` of Eq. 9).
    pub triangles: u64,
    /// Unique edges.
    pub edges: u64,
    /// Edge records (`e` of Eq. 8; more than `edges` when some were split).
    pub sides_data_records: u64,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// The camera `umbra render` uses for this scene (its near plane included).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CameraSpec {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    pub fov_y_degrees: f64,
    pub near: f64,
    /// `umbra export --ortho HEIGHT`: an orthographic camera this many world units tall
    /// (absent: perspective, `fov_y_degrees`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ortho_height: Option<f64>,
}

/// `manifest.json`; see the module documentation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Manifest {
    pub format: String,
    pub version: u64,
    /// The scene spec it was exported from.
    pub scene: String,
    pub ground: bool,
    pub counts: Counts,
    /// Opposite-vertex slots per edge record (`maxMult` of Eq. 8).
    pub max_mult: u64,
    /// Eq. 8, `16 (2 + maxMult) e`.
    pub sides_data_bytes: u64,
    /// Eq. 9, `48 t`.
    pub caps_data_bytes: u64,
    /// Bounds of the drawn triangles (ground included).
    pub bounds: Bounds,
    /// Homogeneous light (w = 1 point, w = 0 directional).
    pub light: [f32; 4],
    pub camera: CameraSpec,
    pub buffers: Buffers,
}

/// Why an export could not be read back. Every variant names the file; JSON problems name the
/// JSON path (`$.buffers.positions.bytes`) or the line and column.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{file}: {source}")]
    Io { file: PathBuf, source: std::io::Error },
    #[error("{file}:{line}:{column}: not valid JSON: {message}")]
    Syntax { file: PathBuf, line: usize, column: usize, message: String },
    #[error("{file}: {path}: {message}")]
    Field { file: PathBuf, path: String, message: String },
    #[error("{file}: $.version: this reader knows version {VERSION}, the manifest is version {found}")]
    Version { file: PathBuf, found: u64 },
    #[error("{file}: {path}: {message}")]
    Inconsistent { file: PathBuf, path: String, message: String },
    #[error("{file}: has {found} bytes, but {path} needs {needed} (offset {offset} + {bytes})")]
    Truncated { file: PathBuf, path: String, found: u64, needed: u64, offset: u64, bytes: u64 },
}

/// Typed access to a JSON value, remembering its path for the errors.
struct At<'a> {
    file: &'a Path,
    path: String,
    value: &'a Value,
}

impl<'a> At<'a> {
    fn err(&self, message: impl Into<String>) -> ManifestError {
        ManifestError::Field { file: self.file.to_path_buf(), path: self.path.clone(), message: message.into() }
    }

    fn get(&self, key: &str) -> Result<At<'a>, ManifestError> {
        let path = format!("{}.{key}", self.path);
        let obj = self.value.as_object().ok_or_else(|| self.err("expected an object"))?;
        let value = obj.get(key).ok_or_else(|| ManifestError::Field {
            file: self.file.to_path_buf(),
            path: path.clone(),
            message: "missing".into(),
        })?;
        Ok(At { file: self.file, path, value })
    }

    fn u64(&self) -> Result<u64, ManifestError> {
        self.value.as_u64().ok_or_else(|| self.err(format!("expected an unsigned integer, got {}", self.value)))
    }

    fn bool(&self) -> Result<bool, ManifestError> {
        self.value.as_bool().ok_or_else(|| self.err(format!("expected true or false, got {}", self.value)))
    }

    fn str(&self) -> Result<String, ManifestError> {
        self.value.as_str().map(String::from).ok_or_else(|| self.err(format!("expected a string, got {}", self.value)))
    }

    fn f64(&self) -> Result<f64, ManifestError> {
        self.value
            .as_f64()
            .filter(|v| v.is_finite())
            .ok_or_else(|| self.err(format!("expected a finite number, got {}", self.value)))
    }

    fn numbers<const N: usize>(&self) -> Result<[f64; N], ManifestError> {
        let a = self.value.as_array().ok_or_else(|| self.err(format!("expected an array of {N} numbers")))?;
        if a.len() != N {
            return Err(self.err(format!("expected {N} numbers, got {}", a.len())));
        }
        let mut out = [0.0; N];
        for (i, v) in a.iter().enumerate() {
            out[i] = At { file: self.file, path: format!("{}[{i}]", self.path), value: v }.f64()?;
        }
        Ok(out)
    }
}

fn f32s<const N: usize>(v: [f64; N]) -> [f32; N] {
    v.map(|x| x as f32)
}

fn buffer_ref(at: &At<'_>) -> Result<BufferRef, ManifestError> {
    let file = at.get("file")?;
    let name = file.str()?;
    // The viewer fetches the file relative to the manifest: a plain file name only.
    if name.is_empty() || name.contains(['/', '\\']) || name == "." || name == ".." {
        return Err(file.err(format!("{name:?} is not a plain file name")));
    }
    let component_type = at.get("component_type")?;
    let ty = component_type.str()?;
    if ty != "f32" && ty != "u32" && ty != "i32" {
        return Err(component_type.err(format!("expected \"f32\", \"u32\" or \"i32\", got {ty:?}")));
    }
    Ok(BufferRef {
        file: name,
        offset: at.get("offset")?.u64()?,
        bytes: at.get("bytes")?.u64()?,
        component_type: ty,
        components: at.get("components")?.u64()?,
        count: at.get("count")?.u64()?,
    })
}

/// Parses and checks a manifest's text (`file` names it in errors): syntax, version, types
/// and the internal consistency of the sizes (every buffer's bytes = 4 · components · count,
/// Eq. 8 and Eq. 9).
pub fn parse_manifest(file: &Path, text: &str) -> Result<Manifest, ManifestError> {
    let value: Value = serde_json::from_str(text).map_err(|e| ManifestError::Syntax {
        file: file.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let root = At { file, path: "$".into(), value: &value };
    let format = root.get("format")?;
    if format.str()? != FORMAT {
        return Err(format.err(format!("expected {FORMAT:?}")));
    }
    let version = root.get("version")?.u64()?;
    if version != VERSION {
        return Err(ManifestError::Version { file: file.to_path_buf(), found: version });
    }
    let counts = root.get("counts")?;
    let bounds = root.get("bounds")?;
    let camera = root.get("camera")?;
    let buffers = root.get("buffers")?;
    let m = Manifest {
        format: FORMAT.into(),
        version,
        scene: root.get("scene")?.str()?,
        ground: root.get("ground")?.bool()?,
        counts: Counts {
            vertices: counts.get("vertices")?.u64()?,
            triangles: counts.get("triangles")?.u64()?,
            edges: counts.get("edges")?.u64()?,
            sides_data_records: counts.get("sides_data_records")?.u64()?,
        },
        max_mult: root.get("max_mult")?.u64()?,
        sides_data_bytes: root.get("sides_data_bytes")?.u64()?,
        caps_data_bytes: root.get("caps_data_bytes")?.u64()?,
        bounds: Bounds { min: f32s(bounds.get("min")?.numbers()?), max: f32s(bounds.get("max")?.numbers()?) },
        light: f32s(root.get("light")?.numbers()?),
        camera: CameraSpec {
            eye: camera.get("eye")?.numbers()?,
            target: camera.get("target")?.numbers()?,
            up: camera.get("up")?.numbers()?,
            fov_y_degrees: camera.get("fov_y_degrees")?.f64()?,
            near: camera.get("near")?.f64()?,
            ortho_height: camera.get("ortho_height").ok().map(|h| h.f64()).transpose()?,
        },
        buffers: Buffers {
            positions: buffer_ref(&buffers.get("positions")?)?,
            normals: buffer_ref(&buffers.get("normals")?)?,
            indices: buffer_ref(&buffers.get("indices")?)?,
            sides_data: buffer_ref(&buffers.get("sides_data")?)?,
            caps_data: buffer_ref(&buffers.get("caps_data")?)?,
            edge_triangles: buffer_ref(&buffers.get("edge_triangles")?)?,
        },
    };
    check_sizes(file, &m)?;
    Ok(m)
}

/// The sizes a manifest states must agree with each other and with Eq. 8 / Eq. 9.
fn check_sizes(file: &Path, m: &Manifest) -> Result<(), ManifestError> {
    let bad = |path: &str, message: String| ManifestError::Inconsistent {
        file: file.to_path_buf(),
        path: path.into(),
        message,
    };
    if m.max_mult == 0 || m.max_mult > MAX_MULT_LIMIT as u64 {
        return Err(bad("$.max_mult", format!("must be between 1 and {MAX_MULT_LIMIT}, got {}", m.max_mult)));
    }
    let c = &m.counts;
    let b = &m.buffers;
    let expected: [(&str, &BufferRef, u64, u64); 6] = [
        ("positions", &b.positions, 3, c.vertices),
        ("normals", &b.normals, 3, c.triangles),
        ("indices", &b.indices, 3, c.triangles),
        ("sides_data", &b.sides_data, 4, c.sides_data_records * (2 + m.max_mult)),
        ("caps_data", &b.caps_data, 4, 3 * c.triangles),
        ("edge_triangles", &b.edge_triangles, m.max_mult, c.sides_data_records),
    ];
    for (name, r, components, count) in expected {
        let path = format!("$.buffers.{name}");
        if r.components != components || r.count != count {
            return Err(bad(
                &path,
                format!(
                    "expected {count} elements of {components} components (counts), got {} of {}",
                    r.count, r.components
                ),
            ));
        }
        let bytes = count.checked_mul(4 * components).ok_or_else(|| bad(&path, "size overflows".into()))?;
        if r.bytes != bytes {
            return Err(bad(
                &format!("{path}.bytes"),
                format!("expected {bytes} (4 x {components} x {count}), got {}", r.bytes),
            ));
        }
    }
    let eq8 = sides_data_bytes(c.sides_data_records as usize, m.max_mult as usize) as u64;
    let eq9 = caps_data_bytes(c.triangles as usize) as u64;
    if m.sides_data_bytes != eq8 || b.sides_data.bytes != eq8 {
        return Err(bad(
            "$.sides_data_bytes",
            format!("Eq. 8 gives {eq8}, the manifest states {}", m.sides_data_bytes),
        ));
    }
    if m.caps_data_bytes != eq9 || b.caps_data.bytes != eq9 {
        return Err(bad("$.caps_data_bytes", format!("Eq. 9 gives {eq9}, the manifest states {}", m.caps_data_bytes)));
    }
    if b.indices.component_type != "u32" {
        return Err(bad("$.buffers.indices.component_type", "indices must be u32".into()));
    }
    if b.edge_triangles.component_type != "i32" {
        return Err(bad("$.buffers.edge_triangles.component_type", "edge triangles must be i32".into()));
    }
    Ok(())
}

/// Reads `DIR/manifest.json` (see [`parse_manifest`]).
pub fn read_manifest(dir: &Path) -> Result<Manifest, ManifestError> {
    let file = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&file).map_err(|source| ManifestError::Io { file: file.clone(), source })?;
    parse_manifest(&file, &text)
}

/// [`read_manifest`], then every buffer file must hold at least `offset + bytes` bytes.
pub fn check_export(dir: &Path) -> Result<Manifest, ManifestError> {
    let m = read_manifest(dir)?;
    let b = &m.buffers;
    for (name, r) in [
        ("positions", &b.positions),
        ("normals", &b.normals),
        ("indices", &b.indices),
        ("sides_data", &b.sides_data),
        ("caps_data", &b.caps_data),
        ("edge_triangles", &b.edge_triangles),
    ] {
        let file = dir.join(&r.file);
        let found = std::fs::metadata(&file).map_err(|source| ManifestError::Io { file: file.clone(), source })?.len();
        let needed = r.offset.saturating_add(r.bytes);
        if found < needed {
            return Err(ManifestError::Truncated {
                file,
                path: format!("$.buffers.{name}"),
                found,
                needed,
                offset: r.offset,
                bytes: r.bytes,
            });
        }
    }
    Ok(m)
}

/// The exported bytes of every buffer, in [`Buffers`] order, and the manifest describing them.
pub struct Export {
    pub manifest: Manifest,
    pub files: Vec<(String, Vec<u8>)>,
}

/// Builds every buffer and the manifest for a checked view (its mesh, first light, camera).
pub fn build_export(view: &ViewConfig, ground: bool) -> Result<Export, CliError> {
    let welded = weld(&view.mesh);
    if welded.triangles.is_empty() {
        return Err(CliError::Other(format!("scene {:?} has no triangles to export", view.scene_spec)));
    }
    // Planned for the 16 vertex attributes GL 4.5, ES 3.0 and WebGL 2 all guarantee; the same
    // builder umbra-wasm runs in a browser.
    let b = build_export_buffers(&welded).map_err(|e| CliError::Other(e.to_string()))?;
    let positions = le_bytes(&b.positions);
    let normals = le_bytes(&b.normals);
    let indices = le_bytes(&b.indices);
    let sides_bytes = le_bytes(&b.sides_data);
    let caps_bytes = le_bytes(&b.caps_data);
    let edge_triangle_bytes = le_bytes(&b.edge_triangles);

    let bounds = b.bounds.unwrap_or(Aabb { min: [-1.0; 3], max: [1.0; 3] });
    let r = |file: &str, bytes: &[u8], component_type: &str, components: u64| BufferRef {
        file: file.into(),
        offset: 0,
        bytes: bytes.len() as u64,
        component_type: component_type.into(),
        components,
        count: bytes.len() as u64 / (4 * components),
    };
    let buffers = Buffers {
        positions: r("positions.bin", &positions, "f32", 3),
        normals: r("normals.bin", &normals, "f32", 3),
        indices: r("indices.bin", &indices, "u32", 3),
        sides_data: r("sides.bin", &sides_bytes, "f32", 4),
        caps_data: r("caps.bin", &caps_bytes, "f32", 4),
        edge_triangles: r("edge_triangles.bin", &edge_triangle_bytes, "i32", b.max_mult as u64),
    };
    let c = &view.camera;
    let manifest = Manifest {
        format: FORMAT.into(),
        version: VERSION,
        scene: view.scene_spec.clone(),
        ground,
        counts: Counts {
            vertices: b.vertices as u64,
            triangles: b.triangles as u64,
            edges: b.edges as u64,
            sides_data_records: b.records as u64,
        },
        max_mult: b.max_mult as u64,
        sides_data_bytes: sides_bytes.len() as u64,
        caps_data_bytes: caps_bytes.len() as u64,
        bounds: Bounds { min: bounds.min, max: bounds.max },
        light: view.lights.first().copied().unwrap_or([0.0, 1.0, 0.0, 0.0]),
        camera: CameraSpec {
            eye: c.eye,
            target: c.target,
            up: c.up,
            fov_y_degrees: c.fov_y_degrees,
            // `Session::frame_params`: 1e-3 of the drawn scene's diagonal.
            near: f64::from(bounds.diagonal()).max(1e-6) * 1e-3,
            ortho_height: c.ortho,
        },
        buffers,
    };
    let files = vec![
        (manifest.buffers.positions.file.clone(), positions),
        (manifest.buffers.normals.file.clone(), normals),
        (manifest.buffers.indices.file.clone(), indices),
        (manifest.buffers.sides_data.file.clone(), sides_bytes),
        (manifest.buffers.caps_data.file.clone(), caps_bytes),
        (manifest.buffers.edge_triangles.file.clone(), edge_triangle_bytes),
    ];
    Ok(Export { manifest, files })
}

/// Writes an export into `dir` (created if needed): the buffer files, then the manifest.
pub fn write_export(dir: &Path, e: &Export) -> Result<(), CliError> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| CliError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    for (name, bytes) in &e.files {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(io(&path))?;
    }
    let path = dir.join(MANIFEST);
    let mut text = serde_json::to_string_pretty(&e.manifest).map_err(|e| CliError::Other(e.to_string()))?;
    text.push('\n');
    std::fs::write(&path, text).map_err(io(&path))
}

pub fn run(c: &ExportConfig) -> Result<(), CliError> {
    let job = match c {
        ExportConfig::Check { dir } => {
            let m = check_export(Path::new(dir)).map_err(|e| CliError::Other(e.to_string()))?;
            println!(
                "{dir}: {} version {}, {} triangles, {} edge records, maxMult {}: sides-data {} bytes (Eq. 8), caps-data {} bytes (Eq. 9)",
                m.format, m.version, m.counts.triangles, m.counts.sides_data_records, m.max_mult, m.sides_data_bytes, m.caps_data_bytes
            );
            return Ok(());
        }
        ExportConfig::Write(job) => job,
    };
    let e = build_export(&job.view, job.ground)?;
    write_export(Path::new(&job.out), &e)?;
    let m = &e.manifest;
    eprintln!(
        "umbra: exported {} to {} in {:.2} s: {} triangles, {} vertices, {} edge records, maxMult {}, sides-data {} bytes, caps-data {} bytes",
        job.scene,
        job.out,
        job.started.elapsed().as_secs_f64(),
        m.counts.triangles,
        m.counts.vertices,
        m.counts.sides_data_records,
        m.max_mult,
        m.sides_data_bytes,
        m.caps_data_bytes
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::ViewArgs;

    fn sample() -> Export {
        build_export(&ViewConfig::from_args(&sample_flags()).expect("box"), true).expect("export")
    }

    fn sample_flags() -> ViewArgs {
        ViewArgs {
            scene: "box".into(),
            light: vec![],
            eye: None,
            target: None,
            up: "0,1,0".into(),
            fov: 60.0,
            ortho: None,
            ortho_far: None,
            size: "64x64".into(),
            ground: true,
            zpass: false,
            zmode: "auto".into(),
            volume_cull: "on".into(),
            receivers: "both".into(),
            max_input_bytes: None,
        }
    }

    fn text(e: &Export) -> String {
        serde_json::to_string_pretty(&e.manifest).expect("json")
    }

    #[test]
    fn manifest_round_trips() {
        let e = sample();
        let mut m = parse_manifest(Path::new("m.json"), &text(&e)).expect("valid");
        // serde_json (without its float_roundtrip feature) may read an f64 back one ulp off;
        // JavaScript's JSON.parse, the viewer's reader, is exact.
        let near = e.manifest.camera.near;
        assert!((m.camera.near - near).abs() <= near * 1e-15, "{} vs {near}", m.camera.near);
        m.camera.near = near;
        assert_eq!(m, e.manifest);
    }

    #[test]
    fn truncated_manifest_is_a_syntax_error_with_line() {
        let t = text(&sample());
        let cut = &t[..t.len() / 2];
        match parse_manifest(Path::new("m.json"), cut) {
            Err(ManifestError::Syntax { file, line, .. }) => {
                assert_eq!(file, Path::new("m.json"));
                assert!(line > 1, "line {line}");
            }
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    #[test]
    fn wrong_type_names_the_json_path() {
        let t = text(&sample()).replacen("\"max_mult\": ", "\"max_mult\": \"x\", \"old\": ", 1);
        let err = parse_manifest(Path::new("m.json"), &t).expect_err("string max_mult");
        assert!(matches!(&err, ManifestError::Field { path, .. } if path == "$.max_mult"), "{err}");
        assert!(err.to_string().starts_with("m.json: $.max_mult: "), "{err}");
    }

    #[test]
    fn missing_buffer_field_names_the_json_path() {
        let mut v: Value = serde_json::from_str(&text(&sample())).unwrap();
        v["buffers"]["caps_data"].as_object_mut().unwrap().remove("bytes");
        let err = parse_manifest(Path::new("m.json"), &v.to_string()).expect_err("missing");
        assert_eq!(err.to_string(), "m.json: $.buffers.caps_data.bytes: missing");
    }

    #[test]
    fn other_version_is_rejected() {
        let mut v: Value = serde_json::from_str(&text(&sample())).unwrap();
        v["version"] = Value::from(VERSION + 1);
        let err = parse_manifest(Path::new("m.json"), &v.to_string()).expect_err("version");
        assert!(matches!(err, ManifestError::Version { found, .. } if found == VERSION + 1));
    }

    #[test]
    fn sizes_that_contradict_eq8_are_rejected() {
        let mut v: Value = serde_json::from_str(&text(&sample())).unwrap();
        let b = v["sides_data_bytes"].as_u64().unwrap();
        v["sides_data_bytes"] = Value::from(b + 16);
        let err = parse_manifest(Path::new("m.json"), &v.to_string()).expect_err("Eq. 8");
        assert!(matches!(&err, ManifestError::Inconsistent { path, .. } if path == "$.sides_data_bytes"), "{err}");
    }

    #[test]
    fn path_in_file_name_is_rejected() {
        let mut v: Value = serde_json::from_str(&text(&sample())).unwrap();
        v["buffers"]["positions"]["file"] = Value::from("../etc/passwd");
        let err = parse_manifest(Path::new("m.json"), &v.to_string()).expect_err("path");
        assert!(matches!(&err, ManifestError::Field { path, .. } if path == "$.buffers.positions.file"), "{err}");
    }

    #[test]
    fn layout_is_the_portable_plan_of_umbra_gl() {
        use umbra_geom::export_buffers::build_export_buffers;
        use umbra_geom::EdgeAdjacency;
        use umbra_gl::methods::vs_silhouette::plan_portable_layout;
        let flags = |scene: &str| ViewArgs { scene: scene.into(), ground: false, ..sample_flags() };
        for scene in ["box", "spheres:3", "default"] {
            let view = ViewConfig::from_args(&flags(scene)).expect("scene");
            let welded = weld(&view.mesh);
            let adj = EdgeAdjacency::build(&welded);
            let plan = plan_portable_layout(&adj, welded.triangles.len());
            let b = build_export_buffers(&welded).expect("buffers");
            assert_eq!((b.max_mult, b.records, b.edges), (plan.max_mult, plan.records, plan.edges), "{scene}");
            assert_eq!(4 * b.sides_data.len(), plan.sides_bytes, "{scene}");
        }
    }

    #[test]
    fn buffers_match_the_manifest_and_eq8_eq9() {
        let e = sample();
        let m = &e.manifest;
        let sizes: Vec<u64> = e.files.iter().map(|(_, b)| b.len() as u64).collect();
        let b = &m.buffers;
        assert_eq!(
            sizes,
            vec![
                b.positions.bytes,
                b.normals.bytes,
                b.indices.bytes,
                b.sides_data.bytes,
                b.caps_data.bytes,
                b.edge_triangles.bytes
            ]
        );
        assert_eq!(m.sides_data_bytes, 16 * (2 + m.max_mult) * m.counts.sides_data_records);
        assert_eq!(b.edge_triangles.bytes, 4 * m.max_mult * m.counts.sides_data_records);
        assert_eq!(m.caps_data_bytes, 48 * m.counts.triangles);
    }
}
