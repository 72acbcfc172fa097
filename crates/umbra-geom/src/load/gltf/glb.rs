//! The GLB binary container of glTF 2.0 (specification, Sec. 4.4): a 12-byte header, a JSON
//! chunk first, an optional BIN chunk; unknown chunk types are skipped.

use crate::load::{LoadError, Location};

pub(super) const GLB_MAGIC: &[u8; 4] = b"glTF";

const CHUNK_JSON: u32 = 0x4E4F_534A;

const CHUNK_BIN: u32 = 0x004E_4942;

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
pub(super) fn split_glb<'a>(bytes: &'a [u8], file: &str) -> Result<(&'a [u8], Option<&'a [u8]>), LoadError> {
    let truncated = |at: usize, what: &str| LoadError::Truncated {
        file: file.to_string(),
        location: Location::Byte(at as u64),
        what: what.to_string(),
    };
    let u32_at = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let version = u32_at(4).ok_or_else(|| truncated(bytes.len(), "GLB header needs 12 bytes"))?;
    if version != 2 {
        return Err(LoadError::Unsupported {
            file: file.to_string(),
            location: Location::Byte(4),
            what: format!("GLB container version {version} (only 2 is supported)"),
        });
    }
    let declared = u32_at(8).ok_or_else(|| truncated(bytes.len(), "GLB header needs 12 bytes"))? as usize;
    if declared > bytes.len() {
        return Err(truncated(
            bytes.len(),
            &format!("GLB header declares {declared} bytes, the file has {}", bytes.len()),
        ));
    }
    let bytes = &bytes[..declared.max(12).min(bytes.len())];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    while at < bytes.len() {
        let len = u32_at(at).ok_or_else(|| truncated(bytes.len(), "incomplete GLB chunk header"))? as usize;
        let kind = u32_at(at + 4).ok_or_else(|| truncated(bytes.len(), "incomplete GLB chunk header"))?;
        let data = bytes
            .get(at + 8..)
            .and_then(|rest| rest.get(..len))
            .ok_or_else(|| truncated(bytes.len(), &format!("GLB chunk at byte offset {at} declares {len} bytes")))?;
        match kind {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some(data),
            CHUNK_BIN if bin.is_none() && json.is_some() => bin = Some(data),
            _ if at == 12 => {
                return Err(LoadError::Malformed {
                    file: file.to_string(),
                    location: Location::Byte(16),
                    message: "the first GLB chunk must be JSON".into(),
                })
            }
            _ => {} // unknown chunk types are skipped, as the spec asks
        }
        at = at + 8 + len;
    }
    let json = json.ok_or_else(|| truncated(bytes.len(), "GLB has no JSON chunk"))?;
    Ok((json, bin))
}
