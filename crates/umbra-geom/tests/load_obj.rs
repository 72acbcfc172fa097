//! Wavefront OBJ loader: statement forms, relative indices, fan triangulation, normals,
//! and every bad-input error naming the file and line.

use std::path::PathBuf;
use umbra_geom::load::{self, Format, LoadError, Location};
use umbra_geom::Mesh;

fn obj(text: &str) -> Result<Mesh, LoadError> {
    load::load_bytes(text.as_bytes(), Format::Obj, "test.obj")
}

fn signed_volume(m: &Mesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize].map(f64::from));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// Asserts the error's variant via `check`, that it is located at `line` and that the
/// message names the file and the line.
fn assert_line_error(result: Result<Mesh, LoadError>, line: u64, check: fn(&LoadError) -> bool) {
    let err = result.expect_err("expected an error");
    assert!(check(&err), "wrong variant: {err:?}");
    assert_eq!(err.location(), Some(&Location::Line(line)), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("test.obj"), "{msg}");
    assert!(msg.contains(&format!("line {line}")), "{msg}");
}

#[test]
fn cube_fixture_with_every_face_form() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/cube_quads.obj");
    let loaded = load::load_path_detailed(&path, &load::LoadOptions::default()).unwrap();
    let m = &loaded.mesh;
    assert_eq!(m.positions.len(), 8);
    assert_eq!(m.triangles.len(), 12);
    assert_eq!(m.positions[4], [-1.0, -1.0, 1.0], "w and colour components ignored");
    assert!((signed_volume(m) - 8.0).abs() < 1e-9, "outward quads stay outward: {}", signed_volume(m));
    // fan triangulation from the first vertex of "f 5/1/1 6/2/1 7/3/1 8/4/1"
    assert_eq!(m.triangles[0], [4, 5, 6]);
    assert_eq!(m.triangles[1], [4, 6, 7]);
    // "f -5 -1 -2 -6" with 8 vertices defined
    assert_eq!(m.triangles[8], [3, 7, 6]);
    assert_eq!(m.triangles[9], [3, 6, 2]);
    // some faces lack normals: dropped, with a warning naming the file
    assert!(m.normals.is_none());
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(loaded.warnings[0].contains("cube_quads.obj"));
}

#[test]
fn face_vertex_forms_are_equivalent() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    let expected = vec![[0u32, 1, 2]];
    for f in ["f 1 2 3", "f 1/1 2/1 3/1", "f 1//1 2//1 3//1", "f 1/1/1 2/1/1 3/1/1", "f -3 -2 -1", "f -3/-1/-1 2//1 3"]
    {
        let m = obj(&format!("{head}{f}\n")).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_eq!(m.triangles, expected, "{f}");
    }
}

#[test]
fn relative_indices_refer_to_vertices_defined_so_far() {
    let m = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -1 -2\n").unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);
}

#[test]
fn polygons_are_fan_triangulated() {
    let m = obj("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n").unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
}

#[test]
fn consistent_normals_are_kept_per_vertex() {
    let m =
        obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 2//1 4//2 3//1\n").unwrap();
    assert_eq!(m.normals, Some(vec![[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]));
}

#[test]
fn conflicting_normals_are_dropped_with_a_warning() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n";
    let loaded = load::load_bytes_detailed(text.as_bytes(), Format::Obj, "test.obj").unwrap();
    assert!(loaded.mesh.normals.is_none());
    assert_eq!(loaded.mesh.triangles.len(), 2);
    assert!(loaded.warnings.iter().any(|w| w.contains("different normals")), "{:?}", loaded.warnings);
}

#[test]
fn equal_normal_values_under_different_indices_are_consistent() {
    let m = obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n").unwrap();
    assert!(m.normals.is_some());
}

#[test]
fn empty_and_comment_only_files_are_empty_meshes() {
    for text in ["", "\n\n", "# nothing here\n", "o empty\ng none\n", "\u{feff}# bom\n"] {
        let m = obj(text).unwrap();
        assert!(m.positions.is_empty() && m.triangles.is_empty() && m.normals.is_none(), "{text:?}");
    }
}

#[test]
fn crlf_tabs_bom_and_missing_final_newline() {
    let m = obj("\u{feff}v\t0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3").unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
}

#[test]
fn number_formats() {
    let m = obj("v 1e-006 -2.5E+2 +3.\nv .5 -0 1e2\nv 0x0 0 0\n").err();
    // hexadecimal is not an OBJ number
    assert!(matches!(m, Some(LoadError::Malformed { .. })), "{m:?}");
    let m = obj("v 1e-006 -2.5E+2 +3.\nv .5 -0 1e2\n").unwrap();
    assert_eq!(m.positions, vec![[1e-6, -250.0, 3.0], [0.5, -0.0, 100.0]]);
}

#[test]
fn short_faces_are_skipped_with_a_warning() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\nf\n";
    let loaded = load::load_bytes_detailed(text.as_bytes(), Format::Obj, "test.obj").unwrap();
    assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2]]);
    assert!(loaded.warnings.iter().any(|w| w.contains("test.obj") && w.contains("line 4") && w.contains('2')));
}

#[test]
fn error_index_out_of_range() {
    assert_line_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n"), 5, |e| {
        matches!(e, LoadError::IndexOutOfRange { index: 4, count: 3, .. })
    });
    assert_line_error(obj("v 0 0 0\nv 1 0 0\nf 1 2 -3\n"), 3, |e| {
        matches!(e, LoadError::IndexOutOfRange { index: -3, count: 2, .. })
    });
    assert_line_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), 4, |e| {
        matches!(e, LoadError::IndexOutOfRange { index: 0, .. })
    });
    // a face may not refer to a vertex defined later
    assert_line_error(obj("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), 3, |e| {
        matches!(e, LoadError::IndexOutOfRange { index: 3, .. })
    });
    // normal index out of range
    assert_line_error(obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n"), 5, |e| {
        matches!(e, LoadError::IndexOutOfRange { index: 2, count: 1, .. })
    });
    // an index that overflows i64 is malformed, not a panic
    assert_line_error(obj("v 0 0 0\nf 1 1 99999999999999999999999\n"), 2, |e| matches!(e, LoadError::Malformed { .. }));
}

#[test]
fn error_non_finite_coordinates() {
    for (text, line) in [
        ("v 0 0 0\nv nan 0 0\n", 2),
        ("v 0 inf 0\n", 1),
        ("\n\nv 0 0 -infinity\n", 3),
        ("v 0 0 1e999\n", 1),
        ("v 0 0 0\nvn NaN 0 1\n", 2),
    ] {
        assert_line_error(obj(text), line, |e| matches!(e, LoadError::NonFinite { .. }));
    }
}

#[test]
fn error_malformed_tokens() {
    for (text, line) in [
        ("v 0 0 0\nv 1.2.3 0 0\n", 2),
        ("v 0 0 zero\n", 1),
        ("v 0 0\n", 1), // a truncated vertex line
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", 4),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/a 2 3\n", 4),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", 4),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/ 2 3\n", 4),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n", 4),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1// 2 3\n", 5),
        ("vn 0 1\n", 1),
    ] {
        assert_line_error(obj(text), line, |e| matches!(e, LoadError::Malformed { .. }));
    }
}

#[test]
fn truncated_file_mid_line() {
    let full = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    // every prefix loads or fails cleanly, never panics
    for cut in 0..=full.len() {
        let _ = obj(&full[..cut]);
    }
    assert_line_error(obj("v 0 0 0\nv 1 0"), 2, |e| matches!(e, LoadError::Malformed { .. }));
}

#[test]
fn arbitrary_bytes_never_panic() {
    let mut state = 0x1234_5678_u64;
    let alphabet = b"vfn/ -0123456789.e#\n\t\rx";
    for _ in 0..2000 {
        let len = (state % 64) as usize;
        let mut text = Vec::with_capacity(len);
        for _ in 0..len {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            text.push(alphabet[(state >> 33) as usize % alphabet.len()]);
        }
        if let Ok(m) = load::load_bytes(&text, Format::Obj, "fuzz.obj") {
            let n = m.positions.len() as u32;
            assert!(m.triangles.iter().flatten().all(|&i| i < n));
        }
    }
}
