//! The buffers of a glTF document: the GLB BIN chunk, base64 `data:` URIs (RFC 4648) and files
//! relative to the `.gltf` (percent-decoded URI; absolute paths, other schemes and anything
//! but a regular file refused), each read once and bounded by `LoadOptions::max_input_bytes`.

use super::doc::Doc;
use crate::load::{LoadError, Location};
use std::path::Path;

impl<'a> Doc<'a> {
    /// Bytes of buffer `index`.
    pub(super) fn buffer(&mut self, index: usize) -> Result<std::rc::Rc<Vec<u8>>, LoadError> {
        if let Some(Some(b)) = self.buffers.get(index) {
            return Ok(b.clone());
        }
        let path = format!("buffers[{index}]");
        let buffer = self.element("buffers", index)?;
        let byte_length = self.required_uint(buffer, "byteLength", &path)?;
        let data: Vec<u8> = match buffer.get("uri") {
            None => {
                let bin = self.bin.filter(|_| index == 0).ok_or_else(|| {
                    self.malformed(path.clone(), "buffer has no uri and there is no GLB BIN chunk".into())
                })?;
                bin.to_vec()
            }
            Some(uri) => {
                let uri =
                    uri.as_str().ok_or_else(|| self.malformed(format!("{path}.uri"), "must be a string".into()))?;
                self.read_uri(uri, &format!("{path}.uri"))?
            }
        };
        if (data.len() as u64) < byte_length {
            return Err(LoadError::Truncated {
                file: self.file.to_string(),
                location: Location::Json(path),
                what: format!("buffer declares byteLength {byte_length} but has {} bytes", data.len()),
            });
        }
        let data = std::rc::Rc::new(data);
        if self.buffers.len() <= index {
            self.buffers.resize(index + 1, None);
        }
        self.buffers[index] = Some(data.clone());
        Ok(data)
    }

    pub(super) fn read_uri(&self, uri: &str, path: &str) -> Result<Vec<u8>, LoadError> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (meta, payload) = rest
                .split_once(',')
                .ok_or_else(|| self.malformed(path.to_string(), "data URI without a ','".into()))?;
            if !meta.ends_with(";base64") {
                return Err(LoadError::Unsupported {
                    file: self.file.to_string(),
                    location: Location::Json(path.to_string()),
                    what: "data URI that is not base64".into(),
                });
            }
            return base64_decode(payload.as_bytes()).map_err(|offset| {
                self.malformed(path.to_string(), format!("invalid base64 at character {offset} of the data"))
            });
        }
        let Some(dir) = self.base_dir else {
            return Err(LoadError::Unsupported {
                file: self.file.to_string(),
                location: Location::Json(path.to_string()),
                what: format!("external buffer {uri:?} cannot be resolved without a directory (use load_path)"),
            });
        };
        let relative = percent_decode(uri)
            .ok_or_else(|| self.malformed(path.to_string(), format!("bad percent-encoding in uri {uri:?}")))?;
        // Only files relative to the document: an absolute path or another scheme could
        // point at /dev/zero (4 GiB of zeros up to the limit), a FIFO (a hang) or a URL.
        if relative.contains(':') || Path::new(&relative).has_root() {
            return Err(LoadError::Unsupported {
                file: self.file.to_string(),
                location: Location::Json(path.to_string()),
                what: format!("buffer uri {uri:?} is not a relative file path or a data URI"),
            });
        }
        let full = dir.join(relative);
        if std::fs::metadata(&full).is_ok_and(|m| !m.is_file()) {
            return Err(LoadError::Unsupported {
                file: self.file.to_string(),
                location: Location::Json(path.to_string()),
                what: format!("buffer {} is not a regular file", full.display()),
            });
        }
        crate::load::read_limited(&full, &full.display().to_string(), false, self.options.max_input_bytes)
    }

    pub(super) fn buffers_len(&self) -> u64 {
        self.buffers.iter().flatten().map(|b| b.len() as u64).sum::<u64>() + self.bin.map_or(0, |b| b.len() as u64)
    }
}

/// Standard base64 (RFC 4648), padding optional; the error is the offending character's
/// offset.
fn base64_decode(input: &[u8]) -> Result<Vec<u8>, usize> {
    let mut out = Vec::with_capacity(input.len() / 4 * 3 + 3);
    let mut acc: u32 = 0;
    let mut bits = 0u32;
    let mut padding = false;
    for (i, &c) in input.iter().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => {
                padding = true;
                continue;
            }
            _ => return Err(i),
        };
        if padding {
            return Err(i);
        }
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Decodes `%XX` escapes of a relative URI; `None` on a malformed escape or invalid UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::gltf::parse;
    use crate::load::LoadOptions;

    #[test]
    fn base64_round_trip_known_vectors() {
        assert_eq!(base64_decode(b"").unwrap(), b"");
        assert_eq!(base64_decode(b"Zg==").unwrap(), b"f");
        assert_eq!(base64_decode(b"Zm8=").unwrap(), b"fo");
        assert_eq!(base64_decode(b"Zm9v").unwrap(), b"foo");
        assert_eq!(base64_decode(b"Zm9vYmFy").unwrap(), b"foobar");
        assert_eq!(base64_decode(b"Zm9v!mFy"), Err(4));
    }

    /// Hostile external buffers are refused before they are opened: `/dev/zero` (4 GiB of
    /// zeros up to the default limit), `/dev/stdin` or a FIFO (a hang), a directory, a URL or
    /// an absolute path.
    #[test]
    fn regression_external_buffer_must_be_a_relative_regular_file() {
        let dir = std::env::temp_dir().join(format!("umbra-gltf-uri-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let opts = LoadOptions::default();
        for uri in ["/dev/zero", "/dev/stdin", "file:///dev/zero", "http://example.invalid/a.bin", "sub", "C:/x.bin"] {
            let doc = format!(
                r#"{{"asset": {{"version": "2.0"}}, "buffers": [{{"byteLength": 36, "uri": "{uri}"}}],
                    "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
                    "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}}],
                    "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}], "nodes": [{{"mesh": 0}}]}}"#
            );
            let err = parse(doc.as_bytes(), "uri.gltf", Some(&dir), &opts, &mut Vec::new()).unwrap_err();
            assert!(matches!(err, LoadError::Unsupported { .. }), "{uri}: {err:?}");
            assert_eq!(err.location(), Some(&Location::Json("buffers[0].uri".into())), "{uri}: {err}");
        }
        // a relative regular file still loads
        let bin: Vec<u8> =
            [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|f| f.to_le_bytes()).collect();
        std::fs::write(dir.join("sub").join("ok.bin"), bin).unwrap();
        let doc = r#"{"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": "sub/ok.bin"}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "nodes": [{"mesh": 0}]}"#;
        let mesh = parse(doc.as_bytes(), "ok.gltf", Some(&dir), &opts, &mut Vec::new()).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
