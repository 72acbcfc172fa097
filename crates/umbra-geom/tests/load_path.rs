//! Format dispatch by extension, the `.gz` wrapper, the input size limit and file errors.

use std::io::Write;
use std::path::PathBuf;
use umbra_geom::load::{self, Format, LoadError, LoadOptions, DEFAULT_MAX_INPUT_BYTES};

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-load-path");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

const TRI_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const TRI_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
const TRI_STL: &str = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";

#[test]
fn extension_dispatch_is_case_insensitive() {
    for (name, text) in [("a.obj", TRI_OBJ), ("b.OBJ", TRI_OBJ), ("c.Ply", TRI_PLY), ("d.STL", TRI_STL)] {
        let path = tmp(name);
        std::fs::write(&path, text).unwrap();
        let m = load::load_path(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangles.len(), 1, "{name}");
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0], "{name}");
    }
    assert_eq!(Format::from_extension("GlTf"), Some(Format::Gltf));
    assert_eq!(Format::from_extension("glb"), Some(Format::Glb));
    assert_eq!(Format::from_extension("fbx"), None);
}

#[test]
fn gz_suffix_decompresses_then_dispatches_on_inner_extension() {
    for (name, text) in [("a.obj.gz", TRI_OBJ), ("b.ply.GZ", TRI_PLY), ("c.Stl.gz", TRI_STL)] {
        let path = tmp(name);
        std::fs::write(&path, gzip(text.as_bytes())).unwrap();
        let m = load::load_path(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangles.len(), 1, "{name}");
    }
    // concatenated gzip members are one stream
    let mut two = gzip(b"v 0 0 0\nv 1 0 0\n");
    two.extend(gzip(b"v 0 1 0\nf 1 2 3\n"));
    let path = tmp("multi.obj.gz");
    std::fs::write(&path, two).unwrap();
    assert_eq!(load::load_path(&path).unwrap().triangles, vec![[0, 1, 2]]);
}

#[test]
fn errors_inside_gz_name_the_file_and_line() {
    let path = tmp("bad-inside.obj.gz");
    std::fs::write(&path, gzip(b"v 0 0 0\nv 0 0 nan\n")).unwrap();
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::NonFinite { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("bad-inside.obj.gz") && msg.contains("line 2"), "{msg}");
}

#[test]
fn unknown_extensions_are_named() {
    for (name, ext) in [("mesh.fbx", "fbx"), ("mesh", ""), ("mesh.txt.gz", "txt.gz"), ("mesh.gz", ".gz")] {
        let path = tmp(name);
        std::fs::write(&path, TRI_OBJ).unwrap();
        let err = load::load_path(&path).unwrap_err();
        match &err {
            LoadError::UnknownFormat { extension, .. } => assert_eq!(extension, ext, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
        let msg = err.to_string();
        assert!(msg.contains(name) && msg.contains(&format!("{ext:?}")), "{msg}");
    }
}

#[test]
fn unreadable_file_is_an_io_error_naming_the_path() {
    let path = tmp("does-not-exist.obj");
    let _ = std::fs::remove_file(&path);
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("does-not-exist.obj"));
    // a directory is not a mesh either
    let dir = tmp("a-directory.obj");
    std::fs::create_dir_all(&dir).unwrap();
    let err = load::load_path(&dir).unwrap_err();
    assert!(matches!(err, LoadError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("a-directory.obj"));
}

#[test]
fn size_limit_applies_to_plain_and_decompressed_input() {
    assert_eq!(LoadOptions::default().max_input_bytes, DEFAULT_MAX_INPUT_BYTES);
    let small = LoadOptions { max_input_bytes: 10 };
    let plain = tmp("limit.obj");
    std::fs::write(&plain, TRI_OBJ).unwrap();
    let err = load::load_path_with(&plain, &small).unwrap_err();
    assert!(matches!(err, LoadError::InputTooLarge { limit: 10, .. }), "{err:?}");
    assert!(err.to_string().contains("limit.obj"));
    // exactly at the limit is fine
    let exact = LoadOptions { max_input_bytes: TRI_OBJ.len() as u64 };
    assert!(load::load_path_with(&plain, &exact).is_ok());

    // a 16 MiB "bomb" that compresses to ~16 KiB stops at the 1 MiB limit
    let bomb = tmp("bomb.obj.gz");
    std::fs::write(&bomb, gzip(&vec![b'\n'; 16 << 20])).unwrap();
    let err = load::load_path_with(&bomb, &LoadOptions { max_input_bytes: 1 << 20 }).unwrap_err();
    assert!(matches!(err, LoadError::InputTooLarge { limit: 1048576, .. }), "{err:?}");
    assert!(err.to_string().contains("bomb.obj.gz"));
    // and loads (as an empty mesh) without the limit
    assert_eq!(load::load_path(&bomb).unwrap().triangles.len(), 0);
}

#[test]
fn corrupt_gzip_is_a_decompression_error() {
    let mut bytes = gzip(TRI_OBJ.as_bytes());
    let n = bytes.len();
    bytes[n / 2] ^= 0xff;
    bytes[n - 6] ^= 0xff; // and the CRC
    let path = tmp("corrupt.obj.gz");
    std::fs::write(&path, &bytes).unwrap();
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::Decompress { .. }), "{err:?}");
    assert!(err.to_string().contains("corrupt.obj.gz"));
    // not gzip at all
    let path = tmp("plain-text.obj.gz");
    std::fs::write(&path, TRI_OBJ).unwrap();
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::Decompress { offset: 0, .. }), "{err:?}");
    // truncated gzip
    let path = tmp("truncated.obj.gz");
    std::fs::write(&path, &gzip(TRI_OBJ.as_bytes())[..12]).unwrap();
    let err = load::load_path(&path).unwrap_err();
    assert!(matches!(err, LoadError::Decompress { .. }), "{err:?}");
}

#[test]
fn warnings_are_returned_by_the_detailed_api() {
    let path = tmp("short-face.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap();
    let loaded = load::load_path_detailed(&path, &LoadOptions::default()).unwrap();
    assert_eq!(loaded.warnings.len(), 1);
    assert!(loaded.warnings[0].contains("short-face.obj") && loaded.warnings[0].contains("line 3"));
}
