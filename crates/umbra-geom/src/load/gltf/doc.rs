//! The parsed glTF document ([`Doc`]): the JSON, the GLB BIN chunk, the buffers loaded so
//! far, and the checked accessors every other part reads the JSON through (each error names
//! the JSON path).

use crate::load::{LoadError, LoadOptions, Location};
use gltf::json::Value;
use std::path::Path;

/// Required extensions whose geometry we cannot decode.
const UNSUPPORTED_EXTENSIONS: &[&str] =
    &["KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression"];

pub(super) struct Doc<'a> {
    pub(super) file: &'a str,
    pub(super) json: &'a Value,
    pub(super) bin: Option<&'a [u8]>,
    pub(super) base_dir: Option<&'a Path>,
    pub(super) options: &'a LoadOptions,
    /// Lazily loaded buffers.
    pub(super) buffers: Vec<Option<std::rc::Rc<Vec<u8>>>>,
    pub(super) input_len: u64,
}

impl<'a> Doc<'a> {
    pub(super) fn malformed(&self, path: String, message: String) -> LoadError {
        LoadError::Malformed { file: self.file.to_string(), location: Location::Json(path), message }
    }

    pub(super) fn check_asset(&self) -> Result<(), LoadError> {
        if !self.json.is_object() {
            return Err(self.malformed("(root)".into(), "the glTF document must be a JSON object".into()));
        }
        let version = self.json.get("asset").and_then(|a| a.get("version")).and_then(Value::as_str);
        match version {
            Some(v) if v.starts_with("2.") => {}
            Some(v) => {
                return Err(LoadError::Unsupported {
                    file: self.file.to_string(),
                    location: Location::Json("asset.version".into()),
                    what: format!("glTF version {v:?} (only 2.x)"),
                })
            }
            None => return Err(self.malformed("asset.version".into(), "missing glTF asset version".into())),
        }
        if let Some(required) = self.json.get("extensionsRequired").and_then(Value::as_array) {
            for (k, ext) in required.iter().enumerate() {
                if let Some(name) = ext.as_str().filter(|n| UNSUPPORTED_EXTENSIONS.contains(n)) {
                    return Err(LoadError::Unsupported {
                        file: self.file.to_string(),
                        location: Location::Json(format!("extensionsRequired[{k}]")),
                        what: format!("required extension {name}"),
                    });
                }
            }
        }
        Ok(())
    }

    pub(super) fn array(&self, key: &str) -> Result<&'a [Value], LoadError> {
        match self.json.get(key) {
            None => Ok(&[]),
            Some(Value::Array(a)) => Ok(a),
            Some(_) => Err(self.malformed(key.to_string(), "must be an array".into())),
        }
    }

    pub(super) fn element(&self, key: &str, index: usize) -> Result<&'a Value, LoadError> {
        let items = self.array(key)?;
        let item = items.get(index).ok_or_else(|| {
            self.malformed(format!("{key}[{index}]"), format!("index out of range ({} {key})", items.len()))
        })?;
        if !item.is_object() {
            return Err(self.malformed(format!("{key}[{index}]"), "must be an object".into()));
        }
        Ok(item)
    }

    pub(super) fn index_value(&self, v: &Value, path: &str) -> Result<usize, LoadError> {
        v.as_u64().and_then(|i| usize::try_from(i).ok()).ok_or_else(|| {
            self.malformed(path.to_string(), format!("expected a non-negative integer index, found {v}"))
        })
    }

    /// An optional non-negative integer field.
    pub(super) fn uint(&self, obj: &Value, key: &str, path: &str) -> Result<Option<u64>, LoadError> {
        match obj.get(key) {
            None => Ok(None),
            Some(v) => v.as_u64().map(Some).ok_or_else(|| {
                self.malformed(format!("{path}.{key}"), format!("expected a non-negative integer, found {v}"))
            }),
        }
    }

    pub(super) fn required_uint(&self, obj: &Value, key: &str, path: &str) -> Result<u64, LoadError> {
        self.uint(obj, key, path)?
            .ok_or_else(|| self.malformed(format!("{path}.{key}"), "missing required field".into()))
    }

    pub(super) fn numbers<const N: usize>(
        &self,
        obj: &Value,
        key: &str,
        path: &str,
    ) -> Result<Option<[f64; N]>, LoadError> {
        let Some(v) = obj.get(key) else { return Ok(None) };
        let bad = || self.malformed(format!("{path}.{key}"), format!("expected an array of {N} finite numbers"));
        let a = v.as_array().filter(|a| a.len() == N).ok_or_else(bad)?;
        let mut out = [0f64; N];
        for (o, x) in out.iter_mut().zip(a) {
            *o = x.as_f64().filter(|f| f.is_finite()).ok_or_else(bad)?;
        }
        Ok(Some(out))
    }
}
