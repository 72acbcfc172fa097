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
//!
//! One part per file: `glb.rs` (the binary container), `doc.rs` (the JSON document and its
//! checked accessors), `nodes.rs` (scenes, node transforms, the 4x4 math), `primitives.rs`
//! (mesh primitives into triangles), `accessor.rs` (accessors, buffer views, sparse
//! substitution, component decoding), `buffers.rs` (GLB BIN, data URIs, external files).

mod accessor;
mod buffers;
mod doc;
mod glb;
mod nodes;
mod primitives;

use doc::Doc;
use glb::{split_glb, GLB_MAGIC};
use nodes::{mul, IDENTITY};

use super::{LoadError, LoadOptions, Location};
use crate::Mesh;
use gltf::json::Value;
use std::path::Path;

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
