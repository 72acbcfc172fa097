//! glTF 2.0 loader (`.gltf` JSON and `.glb` binary container), written against the
//! Khronos glTF 2.0 specification with the crate's JSON parser (`gltf::json`, i.e.
//! serde_json) and our own bounds-checked buffer access.
//!
//! * Geometry: every primitive of mode TRIANGLES (4); TRIANGLE_STRIP (5) and TRIANGLE_FAN
//!   (6) are converted to triangles with the spec's vertex order; POINTS and LINES modes are
//!   skipped with a warning. `POSITION` is required (primitives without it are skipped with
//!   a warning); `NORMAL` is kept when every primitive has it; missing `indices` means
//!   `0..count`. Float, and (KHR_mesh_quantization) normalised or plain integer,
//!   component types are accepted; sparse accessors are applied.
//! * Scene graph: nodes of the default scene (`scene`, else `scenes[0]`), or every root node
//!   when there are no scenes, are walked with their `matrix` or TRS transforms applied;
//!   normals use the inverse transpose; a node transform with negative determinant
//!   (mirroring) flips the triangles so they stay counter-clockwise. A node reached twice
//!   (a cycle or a node with two parents, both invalid glTF) is an error.
//! * Output bound: the mesh (positions, normals, triangles at 12 bytes each) may not grow
//!   beyond `LoadOptions::max_input_bytes`, which stops a small document whose nodes
//!   instance one mesh many times ([`LoadError::OutputTooLarge`]).
//! * Buffers: the GLB `BIN` chunk, `data:` URIs with base64, or files relative to the
//!   `.gltf` (percent-decoded URI; absolute paths, other schemes and anything but a regular
//!   file are refused), each bounded by `LoadOptions::max_input_bytes`. A
//!   `.gltf` passed to `load_bytes` has no directory and can only use data URIs.
//! * [`super::Format::Gltf`] and [`super::Format::Glb`] are parsed alike: input starting
//!   with the GLB magic `glTF` is a GLB container, anything else JSON text.
//! * Required extensions that change geometry encoding (Draco, meshopt) are reported as
//!   [`LoadError::Unsupported`]; other extensions are ignored.
//! * Errors name the file and a JSON path (`accessors[3]`) or, for the GLB container, a
//!   byte offset; JSON syntax errors name the line and column.

use super::{LoadError, LoadOptions, Location};
use crate::Mesh;
use gltf::json::Value;
use std::path::Path;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Required extensions whose geometry we cannot decode.
const UNSUPPORTED_EXTENSIONS: &[&str] =
    &["KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression"];

pub(crate) fn parse(
    bytes: &[u8],
    file: &str,
    base_dir: Option<&Path>,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<Mesh, LoadError> {
    let is_glb = bytes.starts_with(GLB_MAGIC);
    let (json_bytes, bin) = if is_glb { split_glb(bytes, file)? } else { (bytes, None) };
    let json: Value = gltf::json::deserialize::from_slice(json_bytes).map_err(|e| LoadError::Malformed {
        file: file.to_string(),
        location: if is_glb {
            Location::Json(format!("JSON chunk (byte offset 20) line {} column {}", e.line(), e.column()))
        } else {
            Location::Line(e.line() as u64)
        },
        message: format!("invalid JSON: {e}"),
    })?;
    let mut doc = Doc { file, json: &json, bin, base_dir, options, buffers: Vec::new(), input_len: bytes.len() as u64 };
    doc.check_asset()?;
    let nodes = doc.root_nodes()?;
    let mut mesh = Mesh::default();
    let mut first_primitive = true;
    let mut visited = vec![false; doc.array("nodes")?.len()];
    // explicit stack: (node index, world-from-parent transform, JSON path for errors)
    let mut stack: Vec<(usize, [f64; 16])> = nodes.into_iter().rev().map(|n| (n, IDENTITY)).collect();
    while let Some((node_index, parent)) = stack.pop() {
        let path = format!("nodes[{node_index}]");
        let node = doc.element("nodes", node_index)?;
        match visited.get_mut(node_index) {
            Some(seen) if *seen => {
                return Err(doc.malformed(
                    path,
                    "node reached twice: the node graph has a cycle or a node with two parents".into(),
                ))
            }
            Some(seen) => *seen = true,
            None => return Err(doc.malformed(path, "node index out of range".into())),
        }
        let world = mul(&parent, &doc.local_transform(node, &path)?);
        if node.get("extensions").and_then(|e| e.get("EXT_mesh_gpu_instancing")).is_some() {
            warnings.push(format!("{file}: {path}: EXT_mesh_gpu_instancing ignored, drawing one instance"));
        }
        if let Some(m) = node.get("mesh") {
            let mesh_index = doc.index_value(m, &format!("{path}.mesh"))?;
            doc.append_mesh(mesh_index, &world, &mut mesh, &mut first_primitive, warnings)?;
        }
        if let Some(children) = node.get("children") {
            let children = children
                .as_array()
                .ok_or_else(|| doc.malformed(format!("{path}.children"), "must be an array".into()))?;
            for (k, c) in children.iter().enumerate().rev() {
                let child = doc.index_value(c, &format!("{path}.children[{k}]"))?;
                stack.push((child, world));
            }
        }
    }
    if doc.array("scenes")?.is_empty() {
        // every node has a parent or is a root; one never reached hangs off a cycle
        if let Some(i) = visited.iter().position(|v| !v) {
            return Err(doc.malformed(
                format!("nodes[{i}]"),
                "node not reachable from any root: the node graph has a cycle".into(),
            ));
        }
    }
    Ok(mesh)
}

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb<'a>(bytes: &'a [u8], file: &str) -> Result<(&'a [u8], Option<&'a [u8]>), LoadError> {
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

struct Doc<'a> {
    file: &'a str,
    json: &'a Value,
    bin: Option<&'a [u8]>,
    base_dir: Option<&'a Path>,
    options: &'a LoadOptions,
    /// Lazily loaded buffers.
    buffers: Vec<Option<std::rc::Rc<Vec<u8>>>>,
    input_len: u64,
}

impl<'a> Doc<'a> {
    fn malformed(&self, path: String, message: String) -> LoadError {
        LoadError::Malformed { file: self.file.to_string(), location: Location::Json(path), message }
    }

    fn check_asset(&self) -> Result<(), LoadError> {
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

    fn array(&self, key: &str) -> Result<&'a [Value], LoadError> {
        match self.json.get(key) {
            None => Ok(&[]),
            Some(Value::Array(a)) => Ok(a),
            Some(_) => Err(self.malformed(key.to_string(), "must be an array".into())),
        }
    }

    fn element(&self, key: &str, index: usize) -> Result<&'a Value, LoadError> {
        let items = self.array(key)?;
        let item = items.get(index).ok_or_else(|| {
            self.malformed(format!("{key}[{index}]"), format!("index out of range ({} {key})", items.len()))
        })?;
        if !item.is_object() {
            return Err(self.malformed(format!("{key}[{index}]"), "must be an object".into()));
        }
        Ok(item)
    }

    fn index_value(&self, v: &Value, path: &str) -> Result<usize, LoadError> {
        v.as_u64().and_then(|i| usize::try_from(i).ok()).ok_or_else(|| {
            self.malformed(path.to_string(), format!("expected a non-negative integer index, found {v}"))
        })
    }

    /// An optional non-negative integer field.
    fn uint(&self, obj: &Value, key: &str, path: &str) -> Result<Option<u64>, LoadError> {
        match obj.get(key) {
            None => Ok(None),
            Some(v) => v.as_u64().map(Some).ok_or_else(|| {
                self.malformed(format!("{path}.{key}"), format!("expected a non-negative integer, found {v}"))
            }),
        }
    }

    fn required_uint(&self, obj: &Value, key: &str, path: &str) -> Result<u64, LoadError> {
        self.uint(obj, key, path)?
            .ok_or_else(|| self.malformed(format!("{path}.{key}"), "missing required field".into()))
    }

    fn root_nodes(&self) -> Result<Vec<usize>, LoadError> {
        let scenes = self.array("scenes")?;
        if scenes.is_empty() {
            // no scenes: every node that is nobody's child
            let nodes = self.array("nodes")?;
            let mut is_child = vec![false; nodes.len()];
            for (i, n) in nodes.iter().enumerate() {
                if let Some(children) = n.get("children").and_then(Value::as_array) {
                    for (k, c) in children.iter().enumerate() {
                        let c = self.index_value(c, &format!("nodes[{i}].children[{k}]"))?;
                        if let Some(flag) = is_child.get_mut(c) {
                            *flag = true;
                        }
                    }
                }
            }
            return Ok((0..nodes.len()).filter(|&i| !is_child[i]).collect());
        }
        let scene_index = match self.json.get("scene") {
            Some(v) => self.index_value(v, "scene")?,
            None => 0,
        };
        let scene = self.element("scenes", scene_index)?;
        let path = format!("scenes[{scene_index}].nodes");
        match scene.get("nodes") {
            None => Ok(Vec::new()),
            Some(Value::Array(nodes)) => {
                nodes.iter().enumerate().map(|(k, n)| self.index_value(n, &format!("{path}[{k}]"))).collect()
            }
            Some(_) => Err(self.malformed(path, "must be an array".into())),
        }
    }

    fn numbers<const N: usize>(&self, obj: &Value, key: &str, path: &str) -> Result<Option<[f64; N]>, LoadError> {
        let Some(v) = obj.get(key) else { return Ok(None) };
        let bad = || self.malformed(format!("{path}.{key}"), format!("expected an array of {N} finite numbers"));
        let a = v.as_array().filter(|a| a.len() == N).ok_or_else(bad)?;
        let mut out = [0f64; N];
        for (o, x) in out.iter_mut().zip(a) {
            *o = x.as_f64().filter(|f| f.is_finite()).ok_or_else(bad)?;
        }
        Ok(Some(out))
    }

    /// The node's local transform as a column-major 4x4 matrix.
    fn local_transform(&self, node: &Value, path: &str) -> Result<[f64; 16], LoadError> {
        if let Some(m) = self.numbers::<16>(node, "matrix", path)? {
            return Ok(m);
        }
        let t = self.numbers::<3>(node, "translation", path)?.unwrap_or([0.0; 3]);
        let [x, y, z, w] = self.numbers::<4>(node, "rotation", path)?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let s = self.numbers::<3>(node, "scale", path)?.unwrap_or([1.0; 3]);
        // rotation matrix of the unit quaternion (normalised here for robustness)
        let len = (x * x + y * y + z * z + w * w).sqrt();
        let (x, y, z, w) = if len > 0.0 { (x / len, y / len, z / len, w / len) } else { (0.0, 0.0, 0.0, 1.0) };
        let r = [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
            [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
            [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
        ];
        // M = T * R * S, column-major: column c = R column c * s[c]
        let mut m = IDENTITY;
        for c in 0..3 {
            for row in 0..3 {
                m[4 * c + row] = r[c][row] * s[c];
            }
        }
        m[12] = t[0];
        m[13] = t[1];
        m[14] = t[2];
        Ok(m)
    }

    /// Appends every primitive of `meshes[mesh_index]`, transformed by `world`.
    fn append_mesh(
        &mut self,
        mesh_index: usize,
        world: &[f64; 16],
        out: &mut Mesh,
        first_primitive: &mut bool,
        warnings: &mut Vec<String>,
    ) -> Result<(), LoadError> {
        let gmesh = self.element("meshes", mesh_index)?;
        let mpath = format!("meshes[{mesh_index}]");
        let primitives = match gmesh.get("primitives") {
            Some(Value::Array(p)) => p.as_slice(),
            _ => return Err(self.malformed(format!("{mpath}.primitives"), "missing or not an array".into())),
        };
        for (pi, prim) in primitives.iter().enumerate() {
            let ppath = format!("{mpath}.primitives[{pi}]");
            let mode = self.uint(prim, "mode", &ppath)?.unwrap_or(4);
            if !(4..=6).contains(&mode) {
                let name =
                    ["POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"].get(mode as usize).copied().unwrap_or("unknown");
                warnings.push(format!("{}: {ppath}: mode {mode} ({name}) is not triangles, skipped", self.file));
                continue;
            }
            let attributes = prim.get("attributes").filter(|a| a.is_object());
            let Some(position) = attributes.and_then(|a| a.get("POSITION")) else {
                warnings.push(format!("{}: {ppath}: no POSITION attribute, skipped", self.file));
                continue;
            };
            let position = self.index_value(position, &format!("{ppath}.attributes.POSITION"))?;
            let pos = self.read_accessor(position, &[3])?;
            let vertex_count = pos.len() / 3;
            let normal = match attributes.and_then(|a| a.get("NORMAL")) {
                Some(n) => {
                    let n = self.index_value(n, &format!("{ppath}.attributes.NORMAL"))?;
                    let data = self.read_accessor(n, &[3])?;
                    if data.len() != pos.len() {
                        return Err(self.malformed(
                            format!("accessors[{n}]"),
                            format!("NORMAL has {} elements, POSITION {vertex_count}", data.len() / 3),
                        ));
                    }
                    Some(data)
                }
                None => None,
            };
            let indices: Vec<u64> = match prim.get("indices") {
                Some(i) => {
                    let i = self.index_value(i, &format!("{ppath}.indices"))?;
                    let data = self.read_accessor(i, &[1])?;
                    let mut out = Vec::with_capacity(data.len());
                    for (k, &v) in data.iter().enumerate() {
                        if v < 0.0 || v >= vertex_count as f64 || v.fract() != 0.0 {
                            return Err(LoadError::IndexOutOfRange {
                                file: self.file.to_string(),
                                location: Location::Json(format!("accessors[{i}][{k}] (used by {ppath}.indices)")),
                                index: v as i64,
                                count: vertex_count as u64,
                            });
                        }
                        out.push(v as u64);
                    }
                    out
                }
                None => (0..vertex_count as u64).collect(),
            };
            // Node instancing multiplies a mesh by the nodes using it: a small document
            // could expand quadratically (every node x every vertex), so the output is
            // bounded by the input limit before it is allocated.
            let new_triangles = match mode {
                4 => indices.len() / 3,
                _ => indices.len().saturating_sub(2),
            } as u64;
            let vertex_bytes = 12 + if normal.is_some() { 12 } else { 0 };
            let output_bytes = (out.positions.len() as u64 + vertex_count as u64) * vertex_bytes
                + (out.triangles.len() as u64 + new_triangles) * 12;
            if output_bytes > self.options.max_input_bytes {
                return Err(LoadError::OutputTooLarge {
                    file: self.file.to_string(),
                    location: Location::Json(ppath),
                    bytes: output_bytes,
                    limit: self.options.max_input_bytes,
                });
            }
            let base = out.positions.len() as u64;
            if base + vertex_count as u64 > u64::from(u32::MAX) {
                return Err(self.malformed(ppath, "more than 2^32 - 1 vertices in total".into()));
            }
            let flip = det3(world) < 0.0;
            let tri = |a: u64, b: u64, c: u64| {
                let t = [a, b, c].map(|i| (base + i) as u32);
                if flip {
                    [t[0], t[2], t[1]]
                } else {
                    t
                }
            };
            let mut triangles = Vec::new();
            match mode {
                4 => triangles.extend(indices.chunks_exact(3).map(|t| tri(t[0], t[1], t[2]))),
                5 => triangles.extend(indices.windows(3).enumerate().map(|(i, w)| {
                    if i % 2 == 0 {
                        tri(w[0], w[1], w[2])
                    } else {
                        tri(w[0], w[2], w[1])
                    }
                })),
                _ => {
                    if let Some((&first, rest)) = indices.split_first() {
                        triangles.extend(rest.windows(2).map(|w| tri(w[0], w[1], first)));
                    }
                }
            }
            let mut positions = Vec::with_capacity(vertex_count);
            for (k, p) in pos.chunks_exact(3).enumerate() {
                let q = transform_point(world, [p[0], p[1], p[2]]).map(|c| c as f32);
                if q.iter().any(|c| !c.is_finite()) {
                    return Err(LoadError::NonFinite {
                        file: self.file.to_string(),
                        location: Location::Json(format!(
                            "accessors[{position}][{k}] (transformed by the node matrix)"
                        )),
                        value: format!("{q:?}"),
                    });
                }
                positions.push(q);
            }
            let normals = normal.map(|n| {
                let normal_from_object = inverse_transpose3(world);
                n.chunks_exact(3)
                    .map(|v| {
                        let t = mul3(&normal_from_object, [v[0], v[1], v[2]]);
                        let len = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
                        if len > 0.0 && len.is_finite() {
                            t.map(|c| (c / len) as f32)
                        } else {
                            [0.0; 3]
                        }
                    })
                    .collect::<Vec<[f32; 3]>>()
            });
            let prim_mesh = Mesh { positions, triangles: Vec::new(), normals };
            // Mesh::append offsets indices; we already offset, so append vertices then triangles
            let had_normals = out.normals.is_some() || *first_primitive;
            let keep = had_normals && prim_mesh.normals.is_some();
            out.positions.extend_from_slice(&prim_mesh.positions);
            match (keep, prim_mesh.normals) {
                (true, Some(n)) => out.normals.get_or_insert_with(Vec::new).extend(n),
                _ => out.normals = None,
            }
            out.triangles.extend(triangles);
            *first_primitive = false;
        }
        Ok(())
    }

    /// Bytes of buffer `index`.
    fn buffer(&mut self, index: usize) -> Result<std::rc::Rc<Vec<u8>>, LoadError> {
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

    fn read_uri(&self, uri: &str, path: &str) -> Result<Vec<u8>, LoadError> {
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
        super::read_limited(&full, &full.display().to_string(), false, self.options.max_input_bytes)
    }

    /// Decodes accessor `index` into `count * components` f64 values, row-major, checking its type has `components` in
    /// `allowed_components`, every byte it reads lies inside its buffer view and buffer,
    /// and every value is finite.
    fn read_accessor(&mut self, index: usize, allowed_components: &[usize]) -> Result<Vec<f64>, LoadError> {
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

    fn buffers_len(&self) -> u64 {
        self.buffers.iter().flatten().map(|b| b.len() as u64).sum::<u64>() + self.bin.map_or(0, |b| b.len() as u64)
    }

    /// The buffer of `bufferViews[view_index]`, the offset of the accessor's first element in
    /// it and the element stride, after checking `count` elements fit in the view and the
    /// view fits in the buffer.
    fn view_range(
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
    fn apply_sparse(
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
    fn sparse_range(
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

const IDENTITY: [f64; 16] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// Column-major 4x4 product `a * b`.
fn mul(a: &[f64; 16], b: &[f64; 16]) -> [f64; 16] {
    let mut out = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            out[4 * c + r] = (0..4).map(|k| a[4 * k + r] * b[4 * c + k]).sum();
        }
    }
    out
}

/// Affine transform of a point (glTF node matrices are affine; the bottom row is ignored).
fn transform_point(m: &[f64; 16], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r])
}

/// Determinant of the upper-left 3x3 block.
fn det3(m: &[f64; 16]) -> f64 {
    let a = |r: usize, c: usize| m[4 * c + r];
    a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
        + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0))
}

/// Row-major 3x3 inverse transpose of the upper-left block (the cofactor matrix; the
/// determinant's scale is irrelevant because normals are renormalised, its sign is kept).
fn inverse_transpose3(m: &[f64; 16]) -> [[f64; 3]; 3] {
    let a = |r: usize, c: usize| m[4 * c + r];
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let s = if det3(m) < 0.0 { -1.0 } else { 1.0 };
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| s * cof(r, c)))
}

fn mul3(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
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

    #[test]
    fn base64_round_trip_known_vectors() {
        assert_eq!(base64_decode(b"").unwrap(), b"");
        assert_eq!(base64_decode(b"Zg==").unwrap(), b"f");
        assert_eq!(base64_decode(b"Zm8=").unwrap(), b"fo");
        assert_eq!(base64_decode(b"Zm9v").unwrap(), b"foo");
        assert_eq!(base64_decode(b"Zm9vYmFy").unwrap(), b"foobar");
        assert_eq!(base64_decode(b"Zm9v!mFy"), Err(4));
    }

    /// Hostile external buffers (found reviewing the loader for issue 8): `/dev/zero` read
    /// 4 GiB of zeros up to the default limit, a FIFO or `/dev/stdin` hung, a directory or a
    /// URL must not be opened.
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

    #[test]
    fn trs_matches_spec_order() {
        // scale 2, rotate 90 degrees about Z, translate (1, 0, 0): (1,0,0) -> (2,0,0) -> (0,2,0) -> (1,2,0)
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let node: Value = gltf::json::deserialize::from_str(&format!(
            r#"{{"translation":[1,0,0],"rotation":[0,0,{s},{s}],"scale":[2,2,2]}}"#
        ))
        .unwrap();
        let json = Value::Null;
        let opts = LoadOptions::default();
        let doc = Doc {
            file: "t",
            json: &json,
            bin: None,
            base_dir: None,
            options: &opts,
            buffers: Vec::new(),
            input_len: 0,
        };
        let m = doc.local_transform(&node, "nodes[0]").unwrap();
        let p = transform_point(&m, [1.0, 0.0, 0.0]);
        for (a, b) in p.iter().zip([1.0, 2.0, 0.0]) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
    }
}
