//! glTF 2.0 loader: .gltf with external .bin and data URIs, .glb, node transforms
//! (TRS, matrix, hierarchy, mirroring), strips/fans, skipped modes, index types,
//! interleaving, quantization, sparse accessors, and bad-input errors.

use std::path::PathBuf;
use umbra_geom::load::{self, Format, LoadError, Location};
use umbra_geom::Mesh;

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-load-gltf");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Quad positions (48 bytes), normals (48 bytes), u16 indices (12 bytes).
fn quad_buffer() -> Vec<u8> {
    let mut b = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    b.extend(f32s(&[0.0, 0.0, 1.0].repeat(4)));
    b.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    b
}

const QUAD_VIEWS_ACCESSORS: &str = r#""bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 48},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}]"#;

/// A root node translated by (10,0,0) with a child scaled by 2 holding the quad, and a
/// second root whose matrix translates by (0,0,5) holding the quad again.
const TREE: &str = r#""scene": 0,
  "scenes": [{"nodes": [0, 2]}],
  "nodes": [
    {"children": [1], "translation": [10, 0, 0]},
    {"mesh": 0, "scale": [2, 2, 2]},
    {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}]"#;

fn gltf_doc(buffer_json: &str, nodes: &str, views: &str) -> String {
    format!(r#"{{"asset": {{"version": "2.0"}}, "buffers": [{buffer_json}], {views}, {nodes}}}"#)
}

fn expected_tree() -> Mesh {
    Mesh {
        positions: vec![
            [10.0, 0.0, 0.0],
            [12.0, 0.0, 0.0],
            [12.0, 2.0, 0.0],
            [10.0, 2.0, 0.0],
            [0.0, 0.0, 5.0],
            [1.0, 0.0, 5.0],
            [1.0, 1.0, 5.0],
            [0.0, 1.0, 5.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        normals: Some(vec![[0.0, 0.0, 1.0]; 8]),
    }
}

fn data_uri_doc(nodes: &str) -> String {
    let b = quad_buffer();
    gltf_doc(
        &format!(r#"{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}"#, b.len(), base64(&b)),
        nodes,
        QUAD_VIEWS_ACCESSORS,
    )
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(0x4E4F534Au32.to_le_bytes());
    out.extend(j);
    if !b.is_empty() {
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(0x004E4942u32.to_le_bytes());
        out.extend(b);
    }
    out
}

fn glb_tree() -> Vec<u8> {
    let b = quad_buffer();
    glb(&gltf_doc(&format!(r#"{{"byteLength": {}}}"#, b.len()), TREE, QUAD_VIEWS_ACCESSORS), &b)
}

fn gltf_str(text: &str) -> Result<Mesh, LoadError> {
    load::load_bytes(text.as_bytes(), Format::Gltf, "test.gltf")
}

fn assert_close(a: &Mesh, b: &Mesh) {
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(a.positions.len(), b.positions.len());
    for (p, q) in a.positions.iter().zip(&b.positions) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-5, "{p:?} vs {q:?}");
        }
    }
    match (&a.normals, &b.normals) {
        (Some(n), Some(m)) => {
            for (p, q) in n.iter().zip(m) {
                for k in 0..3 {
                    assert!((p[k] - q[k]).abs() < 1e-5, "normal {p:?} vs {q:?}");
                }
            }
        }
        (None, None) => {}
        other => panic!("normals differ: {other:?}"),
    }
}

fn assert_err(result: Result<Mesh, LoadError>, file: &str, at: Location, check: fn(&LoadError) -> bool) {
    let err = result.expect_err("expected an error");
    assert!(check(&err), "wrong variant: {err:?}");
    assert_eq!(err.location(), Some(&at), "{err}");
    let msg = err.to_string();
    assert!(msg.contains(file), "{msg}");
    let where_ = match at {
        Location::Line(l) => format!("line {l}"),
        Location::Byte(b) => format!("byte offset {b}"),
        Location::Json(j) => j,
    };
    assert!(msg.contains(&where_), "{msg} lacks {where_}");
}

#[test]
fn gltf_with_external_bin_and_node_transforms() {
    let bin = quad_buffer();
    std::fs::write(tmp("tree data.bin"), &bin).unwrap();
    let doc =
        gltf_doc(&format!(r#"{{"byteLength": {}, "uri": "tree%20data.bin"}}"#, bin.len()), TREE, QUAD_VIEWS_ACCESSORS);
    let path = tmp("tree.gltf");
    std::fs::write(&path, doc).unwrap();
    assert_close(&load::load_path(&path).unwrap(), &expected_tree());
}

#[test]
fn gltf_with_data_uri() {
    assert_close(&gltf_str(&data_uri_doc(TREE)).unwrap(), &expected_tree());
}

#[test]
fn glb_in_memory_on_disk_and_gzipped() {
    let bytes = glb_tree();
    assert_close(&load::load_bytes(&bytes, Format::Glb, "test.glb").unwrap(), &expected_tree());
    let path = tmp("tree.GLB");
    std::fs::write(&path, &bytes).unwrap();
    assert_close(&load::load_path(&path).unwrap(), &expected_tree());
    let gz = tmp("tree.glb.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut enc, &bytes).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    assert_close(&load::load_path(&gz).unwrap(), &expected_tree());
}

#[test]
fn no_scenes_means_all_root_nodes() {
    let nodes = r#""nodes": [
    {"children": [1], "translation": [10, 0, 0]},
    {"mesh": 0, "scale": [2, 2, 2]},
    {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}]"#;
    assert_close(&gltf_str(&data_uri_doc(nodes)).unwrap(), &expected_tree());
}

#[test]
fn non_default_scene_is_chosen_by_scene_index() {
    let nodes = r#""scene": 1, "scenes": [{"nodes": [0]}, {"nodes": [2]}],
  "nodes": [
    {"children": [1], "translation": [10, 0, 0]},
    {"mesh": 0, "scale": [2, 2, 2]},
    {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}]"#;
    let m = gltf_str(&data_uri_doc(nodes)).unwrap();
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.positions[0], [0.0, 0.0, 5.0]);
}

#[test]
fn rotation_turns_normals_and_mirroring_flips_winding() {
    // 90 degrees about X: +Z normal becomes -Y
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let nodes = format!(r#""nodes": [{{"mesh": 0, "rotation": [{s}, 0, 0, {s}]}}]"#);
    let m = gltf_str(&data_uri_doc(&nodes)).unwrap();
    for n in m.normals.as_ref().unwrap() {
        assert!((n[1] + 1.0).abs() < 1e-6 && n[0].abs() < 1e-6 && n[2].abs() < 1e-6, "{n:?}");
    }
    // mirrored in X with non-uniform scale: winding is flipped so the geometric normal
    // still agrees with the (inverse-transpose) shading normal
    let nodes = r#""nodes": [{"mesh": 0, "scale": [-3, 1, 1]}]"#;
    let m = gltf_str(&data_uri_doc(nodes)).unwrap();
    let normals = m.normals.as_ref().unwrap();
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let g = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let n = normals[t[0] as usize];
        assert!(g[0] * n[0] + g[1] * n[1] + g[2] * n[2] > 0.0, "{t:?} {g:?} {n:?}");
    }
    assert_eq!(m.triangles[0], [0, 2, 1]);
}

/// One primitive per mode over 4 positions with indices 0,1,2,3.
fn modes_doc(modes: &[u32]) -> String {
    let mut b = f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
    b.extend([0u8, 1, 2, 3]);
    let prims: Vec<String> =
        modes.iter().map(|m| format!(r#"{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {m}}}"#)).collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": {}, "uri": "data:application/gltf-buffer;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 4}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}},
                {{"bufferView": 1, "componentType": 5121, "count": 4, "type": "SCALAR"}}],
  "meshes": [{{"primitives": [{}]}}],
  "nodes": [{{"mesh": 0}}]}}"#,
        b.len(),
        base64(&b),
        prims.join(",")
    )
}

#[test]
fn strips_and_fans_are_converted_other_modes_skipped() {
    let m = gltf_str(&modes_doc(&[5])).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);
    let m = gltf_str(&modes_doc(&[6])).unwrap();
    assert_eq!(m.triangles, vec![[1, 2, 0], [2, 3, 0]]);
    let m = gltf_str(&modes_doc(&[4])).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2]], "a 4th index without a full triangle is ignored");
    let loaded = load::load_bytes_detailed(modes_doc(&[0, 1, 2, 3, 6]).as_bytes(), Format::Gltf, "test.gltf").unwrap();
    assert_eq!(loaded.mesh.triangles, vec![[1, 2, 0], [2, 3, 0]]);
    assert_eq!(loaded.mesh.positions.len(), 4, "skipped primitives add no vertices");
    assert_eq!(loaded.warnings.len(), 4, "{:?}", loaded.warnings);
    assert!(loaded.warnings.iter().all(|w| w.contains("test.gltf") && w.contains("meshes[0].primitives[")));
}

#[test]
fn no_indices_interleaved_u32_quantized_and_sparse() {
    // interleaved position+normal (stride 24), no indices
    let mut b = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        b.extend(f32s(&p));
        b.extend(f32s(&[0.0, 0.0, 1.0]));
    }
    // i16 normalised positions (KHR_mesh_quantization) at 72: (32767, 0, -32767) x 3 rows + pad
    for p in [[32767i16, 0, -32767], [0, 32767, 0], [0, 0, 0]] {
        b.extend(p.iter().flat_map(|c| c.to_le_bytes()));
        b.extend([0u8, 0]);
    }
    // u32 indices at 96
    b.extend([2u32, 1, 0].iter().flat_map(|i| i.to_le_bytes()));
    // sparse: index 1 (u8) at 108, replacement value (5, 6, 7) at 112
    b.extend([1u8, 0, 0, 0]);
    b.extend(f32s(&[5.0, 6.0, 7.0]));
    let doc = format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsRequired": ["KHR_mesh_quantization"],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 72, "byteStride": 24}},
                  {{"buffer": 0, "byteOffset": 72, "byteLength": 24, "byteStride": 8}},
                  {{"buffer": 0, "byteOffset": 96, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 108, "byteLength": 16}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}},
                {{"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 3, "type": "VEC3"}},
                {{"bufferView": 1, "componentType": 5122, "normalized": true, "count": 3, "type": "VEC3"}},
                {{"bufferView": 2, "componentType": 5125, "count": 3, "type": "SCALAR"}},
                {{"componentType": 5126, "count": 3, "type": "VEC3",
                  "sparse": {{"count": 1, "indices": {{"bufferView": 3, "componentType": 5121}},
                             "values": {{"bufferView": 3, "byteOffset": 4}}}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}}}]}},
             {{"primitives": [{{"attributes": {{"POSITION": 2}}, "indices": 3}}]}},
             {{"primitives": [{{"attributes": {{"POSITION": 4}}}}]}}],
  "scenes": [{{"nodes": [0, 1, 2]}}],
  "nodes": [{{"mesh": 0}}, {{"mesh": 1}}, {{"mesh": 2}}]}}"#,
        b.len(),
        base64(&b)
    );
    let m = gltf_str(&doc).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [5, 4, 3], [6, 7, 8]]);
    assert_eq!(&m.positions[..3], &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(&m.positions[3..6], &[[1.0, 0.0, -1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]);
    assert_eq!(&m.positions[6..], &[[0.0, 0.0, 0.0], [5.0, 6.0, 7.0], [0.0, 0.0, 0.0]]);
    assert!(m.normals.is_none(), "later primitives have no normals");
}

#[test]
fn empty_documents_are_empty_meshes() {
    for doc in [
        r#"{"asset": {"version": "2.0"}}"#,
        r#"{"asset": {"version": "2.0"}, "scenes": [{}], "scene": 0}"#,
        r#"{"asset": {"version": "2.0"}, "nodes": [{"name": "empty"}]}"#,
    ] {
        assert_eq!(gltf_str(doc).unwrap(), Mesh::default(), "{doc}");
    }
}

#[test]
fn error_node_cycle_and_shared_child() {
    // without scenes: no root at all, the cycle is found as unreachable nodes
    let nodes = r#""nodes": [{"children": [1]}, {"mesh": 0, "children": [0]}]"#;
    assert_err(gltf_str(&data_uri_doc(nodes)), "test.gltf", Location::Json("nodes[0]".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
    let nodes = r#""scenes": [{"nodes": [0]}], "nodes": [{"children": [0]}]"#;
    assert_err(gltf_str(&data_uri_doc(nodes)), "test.gltf", Location::Json("nodes[0]".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
    let nodes = r#""scenes": [{"nodes": [0, 1]}], "nodes": [{"children": [2]}, {"children": [2]}, {"mesh": 0}]"#;
    assert_err(gltf_str(&data_uri_doc(nodes)), "test.gltf", Location::Json("nodes[2]".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
    let nodes = r#""scenes": [{"nodes": [7]}], "nodes": [{"mesh": 0}]"#;
    assert_err(gltf_str(&data_uri_doc(nodes)), "test.gltf", Location::Json("nodes[7]".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
}

fn quad_doc_with(accessors_patch: &str, replace: &str) -> String {
    data_uri_doc(r#""nodes": [{"mesh": 0}]"#).replace(replace, accessors_patch)
}

#[test]
fn error_accessor_claims_more_than_its_view() {
    let doc = quad_doc_with(
        r#""componentType": 5126, "count": 1000000000, "type": "VEC3""#,
        r#""componentType": 5126, "count": 4, "type": "VEC3""#,
    );
    assert_err(gltf_str(&doc), "test.gltf", Location::Json("accessors[0].count".into()), |e| {
        matches!(e, LoadError::TooManyElements { claimed: 1_000_000_000, .. })
    });
    // a view past the end of its buffer
    let doc = data_uri_doc(r#""nodes": [{"mesh": 0}]"#)
        .replace(r#""byteOffset": 96, "byteLength": 12"#, r#""byteOffset": 100, "byteLength": 12"#);
    assert_err(gltf_str(&doc), "test.gltf", Location::Json("bufferViews[2]".into()), |e| {
        matches!(e, LoadError::Truncated { .. })
    });
    // a buffer shorter than its byteLength
    let doc = data_uri_doc(r#""nodes": [{"mesh": 0}]"#).replace(r#""byteLength": 108"#, r#""byteLength": 4000000000"#);
    assert_err(gltf_str(&doc), "test.gltf", Location::Json("buffers[0]".into()), |e| {
        matches!(e, LoadError::Truncated { .. })
    });
    // an accessor without bufferView claiming a huge count
    let doc = r#"{"asset": {"version": "2.0"}, "accessors": [{"componentType": 5126, "count": 4000000000, "type": "VEC3"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "nodes": [{"mesh": 0}]}"#;
    assert_err(gltf_str(doc), "test.gltf", Location::Json("accessors[0].count".into()), |e| {
        matches!(e, LoadError::TooManyElements { .. })
    });
}

#[test]
fn error_index_out_of_range() {
    let mut b = quad_buffer();
    b[96 + 8..96 + 10].copy_from_slice(&9u16.to_le_bytes()); // 5th index
    let doc = gltf_doc(
        &format!(r#"{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}"#, b.len(), base64(&b)),
        r#""nodes": [{"mesh": 0}]"#,
        QUAD_VIEWS_ACCESSORS,
    );
    let err = gltf_str(&doc).unwrap_err();
    assert!(matches!(err, LoadError::IndexOutOfRange { index: 9, count: 4, .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("test.gltf") && msg.contains("accessors[2][4]"), "{msg}");
}

#[test]
fn error_non_finite_position() {
    let mut b = quad_buffer();
    b[16..20].copy_from_slice(&f32::NAN.to_le_bytes()); // vertex 1, y
    let bin_json = format!(r#"{{"byteLength": {}}}"#, b.len());
    let bytes = glb(&gltf_doc(&bin_json, r#""nodes": [{"mesh": 0}]"#, QUAD_VIEWS_ACCESSORS), &b);
    let err = load::load_bytes(&bytes, Format::Glb, "test.glb").unwrap_err();
    assert!(matches!(err, LoadError::NonFinite { .. }), "{err:?}");
    assert!(err.to_string().contains("test.glb") && err.to_string().contains("accessors[0][1]"), "{err}");
    // finite in the file but overflowing after the node transform
    let nodes = r#""nodes": [{"children": [1], "scale": [1e38, 1e38, 1e38]}, {"mesh": 0, "scale": [10, 10, 10]}]"#;
    let err = gltf_str(&data_uri_doc(nodes)).unwrap_err();
    assert!(matches!(err, LoadError::NonFinite { .. }), "{err:?}");
}

#[test]
fn error_bad_json_names_the_line() {
    let doc = "{\"asset\": {\"version\": \"2.0\"},\n\"nodes\": [\n{\"mesh\": 0,}\n]}";
    assert_err(gltf_str(doc), "test.gltf", Location::Line(3), |e| matches!(e, LoadError::Malformed { .. }));
    assert_err(gltf_str(""), "test.gltf", Location::Line(1), |e| matches!(e, LoadError::Malformed { .. }));
    // nesting deeper than the JSON parser's recursion limit is an error, not a stack overflow
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    assert!(matches!(gltf_str(&deep), Err(LoadError::Malformed { .. })));
}

#[test]
fn error_truncated_glb() {
    let bytes = glb_tree();
    let cut = &bytes[..bytes.len() - 10];
    assert_err(load::load_bytes(cut, Format::Glb, "test.glb"), "test.glb", Location::Byte(cut.len() as u64), |e| {
        matches!(e, LoadError::Truncated { .. })
    });
    assert_err(load::load_bytes(&bytes[..7], Format::Glb, "test.glb"), "test.glb", Location::Byte(7), |e| {
        matches!(e, LoadError::Truncated { .. })
    });
    let mut v1 = bytes.clone();
    v1[4] = 1;
    assert_err(load::load_bytes(&v1, Format::Glb, "test.glb"), "test.glb", Location::Byte(4), |e| {
        matches!(e, LoadError::Unsupported { .. })
    });
}

#[test]
fn error_missing_external_buffer_names_the_bin() {
    let doc = gltf_doc(r#"{"byteLength": 108, "uri": "missing-buffer.bin"}"#, TREE, QUAD_VIEWS_ACCESSORS);
    let path = tmp("missing.gltf");
    std::fs::write(&path, &doc).unwrap();
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("missing-buffer.bin"), "{err}");
    // in memory there is no directory to resolve it in
    assert_err(gltf_str(&doc), "test.gltf", Location::Json("buffers[0].uri".into()), |e| {
        matches!(e, LoadError::Unsupported { .. })
    });
}

#[test]
fn error_unsupported_versions_and_extensions() {
    assert_err(
        gltf_str(r#"{"asset": {"version": "1.0"}}"#),
        "test.gltf",
        Location::Json("asset.version".into()),
        |e| matches!(e, LoadError::Unsupported { .. }),
    );
    assert_err(
        gltf_str(
            r#"{"asset": {"version": "2.0"}, "extensionsRequired": ["KHR_materials_unlit", "KHR_draco_mesh_compression"]}"#,
        ),
        "test.gltf",
        Location::Json("extensionsRequired[1]".into()),
        |e| matches!(e, LoadError::Unsupported { .. }),
    );
    assert_err(gltf_str(r#"{"nodes": []}"#), "test.gltf", Location::Json("asset.version".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
    assert_err(gltf_str("[1, 2]"), "test.gltf", Location::Json("(root)".into()), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
}

#[test]
fn arbitrary_mutations_never_panic() {
    let mut state = 0x853c_49e6_748f_ea9b_u64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        state >> 33
    };
    let bases = [glb_tree(), modes_doc(&[4, 5, 6]).into_bytes(), data_uri_doc(TREE).into_bytes()];
    for base in &bases {
        for _ in 0..3000 {
            let mut bytes = base.clone();
            for _ in 0..1 + next() % 3 {
                let i = next() as usize % bytes.len();
                bytes[i] = if next() % 2 == 0 { next() as u8 } else { b"0123456789"[next() as usize % 10] };
            }
            let cut = next() as usize % (bytes.len() + 1);
            let bytes = if next() % 4 == 0 { &bytes[..cut] } else { &bytes[..] };
            if let Ok(m) = load::load_bytes(bytes, Format::Glb, "fuzz.glb") {
                let n = m.positions.len() as u32;
                assert!(m.triangles.iter().flatten().all(|&i| i < n));
            }
        }
    }
}
