//! Mesh primitives into triangles: the modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN in
//! the specification's vertex order (other modes skipped with a warning), `POSITION` and
//! `NORMAL` transformed to world space, triangles flipped under a mirroring transform, and
//! the output bound of `LoadOptions::max_input_bytes`.

use super::doc::Doc;
use super::nodes::{det3, inverse_transpose3, mul3, transform_point};
use crate::load::{LoadError, Location};
use crate::Mesh;
use gltf::json::Value;

impl<'a> Doc<'a> {
    /// Appends every primitive of `meshes[mesh_index]`, transformed by `world`.
    pub(super) fn append_mesh(
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
}
