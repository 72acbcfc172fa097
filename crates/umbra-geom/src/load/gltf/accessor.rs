//! Accessors (specification, Sec. 3.6): a typed view of `count` elements into a buffer view,
//! every byte bounds-checked against the view and the buffer, sparse substitution applied,
//! components decoded (normalised integers per Sec. 3.11) and checked finite.

use super::doc::Doc;
use crate::load::{LoadError, Location};
use gltf::json::Value;

impl<'a> Doc<'a> {
    /// Decodes accessor `index` into `count * components` f64 values, row-major, checking its type has `components` in
    /// `allowed_components`, every byte it reads lies inside its buffer view and buffer,
    /// and every value is finite.
    pub(super) fn read_accessor(&mut self, index: usize, allowed_components: &[usize]) -> Result<Vec<f64>, LoadError> {
        let path = format!("accessors[{index}]");
        let acc = self.element("accessors", index)?;
        let count = self.required_uint(acc, "count", &path)?;
        let component_type = self.required_uint(acc, "componentType", &path)?;
        let component_size: u64 = match component_type {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            5125 | 5126 => 4,
            other => {
                return Err(self.malformed(format!("{path}.componentType"), format!("unknown component type {other}")))
            }
        };
        let normalized = acc.get("normalized").and_then(Value::as_bool).unwrap_or(false);
        let type_name = acc.get("type").and_then(Value::as_str).unwrap_or("");
        let components: usize = match type_name {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT2" => 4,
            "MAT3" => 9,
            "MAT4" => 16,
            other => return Err(self.malformed(format!("{path}.type"), format!("unknown accessor type {other:?}"))),
        };
        if !allowed_components.contains(&components) {
            return Err(self.malformed(
                format!("{path}.type"),
                format!("accessor type {type_name} is not valid here (expected {allowed_components:?} components)"),
            ));
        }
        let element_size = component_size * components as u64;
        let mut values: Vec<f64>;
        match acc.get("bufferView") {
            Some(v) => {
                let view_index = self.index_value(v, &format!("{path}.bufferView"))?;
                let (bytes, start, stride) = self.view_range(view_index, acc, &path, count, element_size)?;
                // count * stride <= view length <= buffer length, so this allocation is bounded
                values = Vec::with_capacity(count as usize * components);
                for e in 0..count as usize {
                    let at = start + e * stride;
                    for c in 0..components {
                        let off = at + c * component_size as usize;
                        let raw = bytes.get(off..off + component_size as usize).unwrap_or(&[]);
                        values.push(decode(raw, component_type, normalized));
                    }
                }
            }
            None => {
                // all zeros (sparse may override): bound the size by the input size
                let limit = self.input_len.saturating_add(self.buffers_len());
                if count > limit {
                    return Err(LoadError::TooManyElements {
                        file: self.file.to_string(),
                        location: Location::Json(format!("{path}.count")),
                        what: "elements in an accessor without bufferView".into(),
                        claimed: count,
                        available: limit,
                        max_possible: limit,
                    });
                }
                values = vec![0.0; count as usize * components];
            }
        }
        if let Some(sparse) = acc.get("sparse") {
            self.apply_sparse(
                sparse,
                &path,
                count,
                component_type,
                component_size,
                components,
                normalized,
                &mut values,
            )?;
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(LoadError::NonFinite {
                file: self.file.to_string(),
                location: Location::Json(format!("{path}[{}]", k / components)),
                value: values[k].to_string(),
            });
        }
        Ok(values)
    }

    /// The buffer of `bufferViews[view_index]`, the offset of the accessor's first element in
    /// it and the element stride, after checking `count` elements fit in the view and the
    /// view fits in the buffer.
    pub(super) fn view_range(
        &mut self,
        view_index: usize,
        acc: &Value,
        path: &str,
        count: u64,
        element_size: u64,
    ) -> Result<(std::rc::Rc<Vec<u8>>, usize, usize), LoadError> {
        let vpath = format!("bufferViews[{view_index}]");
        let view = self.element("bufferViews", view_index)?;
        let buffer_index = self.required_uint(view, "buffer", &vpath)?;
        let view_offset = self.uint(view, "byteOffset", &vpath)?.unwrap_or(0);
        let view_length = self.required_uint(view, "byteLength", &vpath)?;
        let stride = self.uint(view, "byteStride", &vpath)?.unwrap_or(element_size);
        if stride < element_size {
            return Err(self.malformed(
                format!("{vpath}.byteStride"),
                format!("stride {stride} is smaller than the element size {element_size}"),
            ));
        }
        let acc_offset = self.uint(acc, "byteOffset", path)?.unwrap_or(0);
        // bytes needed: offset + (count - 1) * stride + element size
        let needed = match count {
            0 => Some(0),
            n => (n - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(element_size))
                .and_then(|x| x.checked_add(acc_offset)),
        };
        match needed {
            Some(n) if n <= view_length => {}
            _ => {
                return Err(LoadError::TooManyElements {
                    file: self.file.to_string(),
                    location: Location::Json(format!("{path}.count")),
                    what: format!("elements of {element_size} bytes (stride {stride}, offset {acc_offset}) in {vpath}"),
                    claimed: count,
                    available: view_length,
                    max_possible: view_length.saturating_sub(acc_offset).saturating_add(stride - element_size)
                        / stride.max(1),
                })
            }
        }
        let buffer_index = usize::try_from(buffer_index).unwrap_or(usize::MAX);
        let buffer = self.buffer(buffer_index)?;
        let view_end = view_offset.checked_add(view_length);
        if view_end.is_none_or(|e| e > buffer.len() as u64) {
            return Err(LoadError::Truncated {
                file: self.file.to_string(),
                location: Location::Json(vpath),
                what: format!(
                    "view bytes {view_offset}..{} lie outside buffers[{buffer_index}] of {} bytes",
                    view_offset.saturating_add(view_length),
                    buffer.len()
                ),
            });
        }
        // everything is now known to fit in buffer.len(), a usize
        Ok((buffer, (view_offset + acc_offset) as usize, stride as usize))
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn apply_sparse(
        &mut self,
        sparse: &Value,
        path: &str,
        count: u64,
        component_type: u64,
        component_size: u64,
        components: usize,
        normalized: bool,
        values: &mut [f64],
    ) -> Result<(), LoadError> {
        let spath = format!("{path}.sparse");
        let n = self.required_uint(sparse, "count", &spath)?;
        let idx = sparse.get("indices").ok_or_else(|| self.malformed(format!("{spath}.indices"), "missing".into()))?;
        let val = sparse.get("values").ok_or_else(|| self.malformed(format!("{spath}.values"), "missing".into()))?;
        let ipath = format!("{spath}.indices");
        let index_type = self.required_uint(idx, "componentType", &ipath)?;
        let index_size: u64 = match index_type {
            5121 => 1,
            5123 => 2,
            5125 => 4,
            other => {
                return Err(self.malformed(format!("{ipath}.componentType"), format!("invalid index type {other}")))
            }
        };
        let element_size = component_size * components as u64;
        let (ibytes, istart) = self.sparse_range(idx, &ipath, n, index_size)?;
        let (vbytes, vstart) = self.sparse_range(val, &format!("{spath}.values"), n, element_size)?;
        for k in 0..n as usize {
            let off = istart + k * index_size as usize;
            let i = decode(ibytes.get(off..off + index_size as usize).unwrap_or(&[]), index_type, false);
            if i < 0.0 || i >= count as f64 {
                return Err(LoadError::IndexOutOfRange {
                    file: self.file.to_string(),
                    location: Location::Json(format!("{ipath}[{k}]")),
                    index: i as i64,
                    count,
                });
            }
            for c in 0..components {
                let off = vstart + k * element_size as usize + c * component_size as usize;
                let raw = vbytes.get(off..off + component_size as usize).unwrap_or(&[]);
                if let Some(slot) = values.get_mut(i as usize * components + c) {
                    *slot = decode(raw, component_type, normalized);
                }
            }
        }
        Ok(())
    }

    /// A tightly packed sparse indices/values block of `n` items of `size` bytes.
    pub(super) fn sparse_range(
        &mut self,
        obj: &Value,
        path: &str,
        n: u64,
        size: u64,
    ) -> Result<(std::rc::Rc<Vec<u8>>, usize), LoadError> {
        let view_index =
            obj.get("bufferView").ok_or_else(|| self.malformed(format!("{path}.bufferView"), "missing".into()))?;
        let view_index = self.index_value(view_index, &format!("{path}.bufferView"))?;
        let offset = self.uint(obj, "byteOffset", path)?.unwrap_or(0);
        // sparse blocks are tightly packed: the view's byteStride does not apply
        let vpath = format!("bufferViews[{view_index}]");
        let view = self.element("bufferViews", view_index)?;
        let view_length = self.required_uint(view, "byteLength", &vpath)?;
        let needed = n.checked_mul(size).and_then(|x| x.checked_add(offset));
        if needed.is_none_or(|x| x > view_length) {
            return Err(LoadError::TooManyElements {
                file: self.file.to_string(),
                location: Location::Json(path.to_string()),
                what: format!("sparse items of {size} bytes in {vpath}"),
                claimed: n,
                available: view_length,
                max_possible: view_length.saturating_sub(offset) / size.max(1),
            });
        }
        let buffer_index = self.required_uint(view, "buffer", &vpath)?;
        let view_offset = self.uint(view, "byteOffset", &vpath)?.unwrap_or(0);
        let buffer = self.buffer(usize::try_from(buffer_index).unwrap_or(usize::MAX))?;
        if view_offset.checked_add(view_length).is_none_or(|e| e > buffer.len() as u64) {
            return Err(LoadError::Truncated {
                file: self.file.to_string(),
                location: Location::Json(vpath),
                what: format!("view lies outside buffers[{buffer_index}] of {} bytes", buffer.len()),
            });
        }
        Ok((buffer, (view_offset + offset) as usize))
    }
}

/// One component from its little-endian bytes; normalised integers per glTF 2.0 Sec. 3.11.
fn decode(raw: &[u8], component_type: u64, normalized: bool) -> f64 {
    let b = |i: usize| raw.get(i).copied().unwrap_or(0);
    match component_type {
        5120 => {
            let v = f64::from(b(0) as i8);
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        5121 => {
            let v = f64::from(b(0));
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        5122 => {
            let v = f64::from(i16::from_le_bytes([b(0), b(1)]));
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        5123 => {
            let v = f64::from(u16::from_le_bytes([b(0), b(1)]));
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        5125 => f64::from(u32::from_le_bytes([b(0), b(1), b(2), b(3)])),
        _ => f64::from(f32::from_le_bytes([b(0), b(1), b(2), b(3)])),
    }
}
