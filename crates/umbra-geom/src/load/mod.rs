//! Mesh file loaders: Wavefront OBJ, PLY, STL, glTF 2.0 (`.gltf` + `.glb`), each optionally
//! gzip-compressed (`scene.obj.gz`).
//!
//! * [`load_path`] picks the format from the extension (case-insensitive); a trailing `.gz`
//!   is decompressed first (bounded by [`LoadOptions::max_input_bytes`]) and the inner
//!   extension decides.
//! * [`load_bytes`] parses an in-memory file of a known [`Format`] and [`gunzip_bytes`]
//!   decompresses one (both used by fuzzing).
//! * The `*_detailed` variants also return non-fatal [`Loaded::warnings`] (e.g. glTF
//!   primitives of a mode other than triangles, which are skipped). [`load_path`] and
//!   [`load_path_with`] print those warnings to stderr and return just the mesh;
//!   [`load_bytes`] drops them silently.
//!
//! Every loader yields f32 positions, u32 triangles and per-vertex normals when the file
//! has them (see each format module for when normals are dropped). Polygons are
//! fan-triangulated. Bad input yields a [`LoadError`] naming the file and the line / byte
//! offset / JSON path; no input makes a loader panic, and no header makes it allocate
//! more than the input could possibly describe.

mod error;
pub mod gltf;
pub mod obj;
pub mod ply;
pub mod stl;
mod text;

pub use error::{LoadError, Location};

use crate::Mesh;
use std::io::Read;
use std::path::Path;

/// Default cap on the size of a (decompressed) input file: 4 GiB.
pub const DEFAULT_MAX_INPUT_BYTES: u64 = 4 << 30;

/// Options for [`load_path_with`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Largest accepted input in bytes, after decompression (and for a glTF, per buffer).
    pub max_input_bytes: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions { max_input_bytes: DEFAULT_MAX_INPUT_BYTES }
    }
}

/// A supported mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Stanford PLY (`.ply`), ASCII or binary.
    Ply,
    /// STL (`.stl`), ASCII or binary.
    Stl,
    /// glTF 2.0 JSON (`.gltf`); buffers as data URIs or files next to it.
    Gltf,
    /// Binary glTF 2.0 container (`.glb`).
    Glb,
}

impl Format {
    /// The format for a file extension without the dot, case-insensitive (`"OBJ"`, `"glb"`).
    pub fn from_extension(ext: &str) -> Option<Format> {
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "stl" => Some(Format::Stl),
            "gltf" => Some(Format::Gltf),
            "glb" => Some(Format::Glb),
            _ => None,
        }
    }
}

/// A loaded mesh together with non-fatal warnings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The mesh as loaded (a soup: not welded).
    pub mesh: Mesh,
    /// Human-readable notes about skipped content, each naming the file.
    pub warnings: Vec<String>,
}

/// Loads a mesh file, choosing the format by extension; see the module docs.
pub fn load_path(path: &Path) -> Result<Mesh, LoadError> {
    load_path_with(path, &LoadOptions::default())
}

/// [`load_path`] with explicit options. Warnings are printed to stderr.
pub fn load_path_with(path: &Path, options: &LoadOptions) -> Result<Mesh, LoadError> {
    let loaded = load_path_detailed(path, options)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    Ok(loaded.mesh)
}

/// [`load_path_with`] returning the warnings instead of printing them.
pub fn load_path_detailed(path: &Path, options: &LoadOptions) -> Result<Loaded, LoadError> {
    let file = path.display().to_string();
    let (format, gzipped) = format_of_path(path, &file)?;
    let bytes = read_limited(path, &file, gzipped, options.max_input_bytes)?;
    let base_dir = path.parent();
    parse(&bytes, format, &file, base_dir, options)
}

/// Parses an in-memory file. `name_for_errors` is used in every error message. A `.gltf`
/// parsed this way can only use data-URI buffers (there is no directory to look in).
pub fn load_bytes(bytes: &[u8], format: Format, name_for_errors: &str) -> Result<Mesh, LoadError> {
    load_bytes_detailed(bytes, format, name_for_errors).map(|l| l.mesh)
}

/// [`load_bytes`] returning the warnings too.
pub fn load_bytes_detailed(bytes: &[u8], format: Format, name_for_errors: &str) -> Result<Loaded, LoadError> {
    parse(bytes, format, name_for_errors, None, &LoadOptions::default())
}

fn parse(
    bytes: &[u8],
    format: Format,
    file: &str,
    base_dir: Option<&Path>,
    options: &LoadOptions,
) -> Result<Loaded, LoadError> {
    let mut warnings = Vec::new();
    let mesh = match format {
        Format::Obj => obj::parse(bytes, file, &mut warnings)?,
        Format::Ply => ply::parse(bytes, file, &mut warnings)?,
        Format::Stl => stl::parse(bytes, file, &mut warnings)?,
        Format::Gltf | Format::Glb => gltf::parse(bytes, file, base_dir, options, &mut warnings)?,
    };
    Ok(Loaded { mesh, warnings })
}

/// The format of `path` and whether it is gzip-wrapped.
fn format_of_path(path: &Path, file: &str) -> Result<(Format, bool), LoadError> {
    let unknown = |ext: &str| LoadError::UnknownFormat { file: file.to_string(), extension: ext.to_string() };
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext.eq_ignore_ascii_case("gz") {
        let inner = path.file_stem().map(Path::new).and_then(|s| s.extension()).and_then(|e| e.to_str());
        return match inner.and_then(Format::from_extension) {
            Some(f) => Ok((f, true)),
            None => Err(unknown(&format!("{}.{ext}", inner.unwrap_or("")))),
        };
    }
    Format::from_extension(ext).map(|f| (f, false)).ok_or_else(|| unknown(ext))
}

/// Reads a whole file (gunzipping it if asked), refusing more than `limit` bytes.
pub(crate) fn read_limited(path: &Path, file: &str, gzipped: bool, limit: u64) -> Result<Vec<u8>, LoadError> {
    let io_err = |source| LoadError::Io { file: file.to_string(), source };
    let f = std::fs::File::open(path).map_err(io_err)?;
    let too_large = || LoadError::InputTooLarge { file: file.to_string(), limit };
    if !gzipped {
        let len = f.metadata().map_err(io_err)?.len();
        if len > limit {
            return Err(too_large());
        }
        let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
        f.take(limit.saturating_add(1)).read_to_end(&mut bytes).map_err(io_err)?;
        if bytes.len() as u64 > limit {
            return Err(too_large());
        }
        return Ok(bytes);
    }
    gunzip_limited(std::io::BufReader::new(f), file, limit)
}

/// Decompresses an in-memory (possibly multi-member) gzip file as [`load_path`] does for
/// `.gz` files, refusing more than `limit` decompressed bytes (used by fuzzing).
pub fn gunzip_bytes(bytes: &[u8], name_for_errors: &str, limit: u64) -> Result<Vec<u8>, LoadError> {
    gunzip_limited(bytes, name_for_errors, limit)
}

/// Decompresses a (possibly multi-member) gzip stream, refusing more than `limit` bytes.
pub(crate) fn gunzip_limited<R: std::io::BufRead>(reader: R, file: &str, limit: u64) -> Result<Vec<u8>, LoadError> {
    let mut decoder = flate2::bufread::MultiGzDecoder::new(reader);
    let mut out = Vec::new();
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = match decoder.read(&mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                return Err(LoadError::Decompress {
                    file: file.to_string(),
                    offset: out.len() as u64,
                    message: e.to_string(),
                })
            }
        };
        if (out.len() as u64).saturating_add(n as u64) > limit {
            return Err(LoadError::InputTooLarge { file: file.to_string(), limit });
        }
        out.extend_from_slice(chunk.get(..n).unwrap_or(&[]));
    }
    Ok(out)
}
