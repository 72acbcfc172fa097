//! glTF loader (being written).
use super::{LoadError, LoadOptions, Location};
use crate::Mesh;
use std::path::Path;

pub(crate) fn parse(
    _bytes: &[u8],
    _glb: bool,
    file: &str,
    _base_dir: Option<&Path>,
    _options: &LoadOptions,
    _warnings: &mut Vec<String>,
) -> Result<Mesh, LoadError> {
    Err(LoadError::Unsupported { file: file.to_string(), location: Location::Byte(0), what: "not implemented yet".into() })
}
