//! STL loader: ASCII, binary, binary whose header starts with "solid", three vertices per
//! facet, and every bad-input error naming the file and line / byte offset.

use std::path::PathBuf;
use umbra_geom::load::{self, Format, LoadError, Location};
use umbra_geom::Mesh;

fn stl(bytes: &[u8]) -> Result<Mesh, LoadError> {
    load::load_bytes(bytes, Format::Stl, "test.stl")
}

/// A binary STL with the given 80-byte header prefix and facets (normal, 3 vertices).
fn binary(header: &[u8], facets: &[([f32; 3], [[f32; 3]; 3])]) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend_from_slice(&(facets.len() as u32).to_le_bytes());
    for (n, vs) in facets {
        for c in n.iter().chain(vs.iter().flatten()) {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

const TWO: [([f32; 3], [[f32; 3]; 3]); 2] = [
    ([0.0, 0.0, 1.0], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    ([0.0, 0.0, 1.0], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]),
];

fn expected_two() -> Mesh {
    Mesh {
        positions: TWO.iter().flat_map(|f| f.1).collect(),
        triangles: vec![[0, 1, 2], [3, 4, 5]],
        normals: Some(vec![[0.0, 0.0, 1.0]; 6]),
    }
}

type Check = fn(&LoadError) -> bool;

fn assert_err_at(result: Result<Mesh, LoadError>, at: Location, check: fn(&LoadError) -> bool) {
    let err = result.expect_err("expected an error");
    assert!(check(&err), "wrong variant: {err:?}");
    assert_eq!(err.location(), Some(&at), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("test.stl"), "{msg}");
    let where_ = match at {
        Location::Line(l) => format!("line {l}"),
        Location::Byte(b) => format!("byte offset {b}"),
        Location::Json(j) => j,
    };
    assert!(msg.contains(&where_), "{msg} lacks {where_}");
}

#[test]
fn ascii_fixture_three_vertices_per_facet() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/two_facets_ascii.stl");
    assert_eq!(load::load_path(&path).unwrap(), expected_two());
}

#[test]
fn binary_equals_ascii() {
    assert_eq!(stl(&binary(b"exported by a test", &TWO)).unwrap(), expected_two());
}

#[test]
fn binary_starting_with_solid_is_binary() {
    let bytes = binary(b"solid this header lies", &TWO);
    assert_eq!(stl(&bytes).unwrap(), expected_two());
    // also with leading whitespace and all-printable payload bytes would not fool it: the
    // size matches 84 + 50 * count exactly
    let bytes = binary(b"  SOLID x", &TWO);
    assert_eq!(stl(&bytes).unwrap(), expected_two());
}

#[test]
fn binary_starting_with_solid_with_wrong_size_is_still_binary() {
    let mut bytes = binary(b"solid x", &TWO);
    bytes.extend_from_slice(&[0, 0, 0]); // trailing garbage
    let loaded = load::load_bytes_detailed(&bytes, Format::Stl, "test.stl").unwrap();
    assert_eq!(loaded.mesh, expected_two());
    assert!(loaded.warnings.iter().any(|w| w.contains("test.stl") && w.contains("3 bytes")), "{:?}", loaded.warnings);
}

#[test]
fn zero_normals_are_dropped() {
    let facets = [([0.0, 0.0, 0.0], TWO[0].1)];
    let m = stl(&binary(b"", &facets)).unwrap();
    assert!(m.normals.is_none());
    assert_eq!(m.triangles.len(), 1);
    let m = stl(b"solid s\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n").unwrap();
    assert!(m.normals.is_none());
}

#[test]
fn ascii_multiple_solids_polygons_case_and_crlf() {
    let text = "solid a\r\nFACET NORMAL 0 0 1\r\nOUTER LOOP\r\nVERTEX 0 0 0\r\nVERTEX 1 0 0\r\nVERTEX 1 1 0\r\nVERTEX 0 1 0\r\nENDLOOP\r\nENDFACET\r\nENDSOLID a\r\n\
                solid b\nfacet normal 0 0 1\nouter loop\nvertex 0 0 5\nvertex 1 0 5\nvertex 0 1 5\nendloop\nendfacet\nendsolid";
    let m = stl(text.as_bytes()).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]]);
    assert_eq!(m.positions[3..6], [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(m.positions[6], [0.0, 0.0, 5.0]);
}

#[test]
fn empty_solids_are_empty_meshes() {
    assert_eq!(stl(b"solid empty\nendsolid empty\n").unwrap(), Mesh::default());
    assert_eq!(stl(&binary(b"", &[])).unwrap(), Mesh::default());
}

#[test]
fn error_binary_count_exceeds_file() {
    let mut bytes = binary(b"", &TWO);
    bytes[80..84].copy_from_slice(&1_000_000_000u32.to_le_bytes());
    assert_err_at(stl(&bytes), Location::Byte(80), |e| {
        matches!(e, LoadError::TooManyElements { claimed: 1_000_000_000, max_possible: 2, .. })
    });
    // the same with a "solid" header and a body that is not text
    let mut bytes = binary(b"solid x", &TWO);
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    assert_err_at(stl(&bytes), Location::Byte(80), |e| matches!(e, LoadError::TooManyElements { .. }));
    // truncated last facet
    let bytes = binary(b"", &TWO);
    assert_err_at(stl(&bytes[..bytes.len() - 1]), Location::Byte(80), |e| {
        matches!(e, LoadError::TooManyElements { claimed: 2, max_possible: 1, .. })
    });
}

#[test]
fn error_binary_header_too_short() {
    assert_err_at(stl(b""), Location::Byte(0), |e| matches!(e, LoadError::Truncated { .. }));
    assert_err_at(stl(&[7u8; 50]), Location::Byte(50), |e| matches!(e, LoadError::Truncated { .. }));
}

#[test]
fn error_binary_non_finite_offset() {
    let mut facets = TWO;
    facets[1].1[2][1] = f32::NAN; // facet 1, vertex 2, y
    let bytes = binary(b"", &facets);
    assert_err_at(stl(&bytes), Location::Byte(84 + 50 + 12 + 24 + 4), |e| matches!(e, LoadError::NonFinite { .. }));
    facets[1].1[2][1] = f32::NEG_INFINITY;
    assert_err_at(stl(&binary(b"", &facets)), Location::Byte(84 + 50 + 12 + 24 + 4), |e| {
        matches!(e, LoadError::NonFinite { .. })
    });
}

#[test]
fn error_ascii_lines() {
    let facet = |v: &str| {
        format!(
            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n{v}\nendloop\nendfacet\nendsolid s\n"
        )
    };
    let cases: [(String, u64, Check); 7] = [
        (facet("vertex 0 nan 0"), 6, |e| matches!(e, LoadError::NonFinite { .. })),
        (facet("vertex 0 1e99 0"), 6, |e| matches!(e, LoadError::NonFinite { .. })),
        (facet("vertex 0 1.x 0"), 6, |e| matches!(e, LoadError::Malformed { .. })),
        (facet("vertex 0 1"), 6, |e| matches!(e, LoadError::Malformed { .. })),
        (facet("endfacet"), 6, |e| matches!(e, LoadError::Malformed { .. })), // only 2 vertices
        (facet("bogus 1 2 3"), 6, |e| matches!(e, LoadError::Malformed { .. })),
        ("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n".to_string(), 4, |e| {
            matches!(e, LoadError::Truncated { .. })
        }),
    ];
    for (text, line, check) in cases {
        assert_err_at(stl(text.as_bytes()), Location::Line(line), check);
    }
    assert_err_at(stl(b"solid s\nfacet 0 0 1\n"), Location::Line(2), |e| matches!(e, LoadError::Malformed { .. }));
    assert_err_at(stl(b"solid s\nendsolid\nvertex 1 2 3\n"), Location::Line(3), |e| {
        matches!(e, LoadError::Malformed { .. })
    });
}

#[test]
fn arbitrary_mutations_never_panic() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        state >> 33
    };
    let bases = [
        binary(b"solid", &TWO),
        std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/two_facets_ascii.stl")).unwrap(),
    ];
    for base in &bases {
        for _ in 0..3000 {
            let mut bytes = base.clone();
            for _ in 0..1 + next() % 4 {
                let i = next() as usize % bytes.len();
                bytes[i] = next() as u8;
            }
            let cut = next() as usize % (bytes.len() + 1);
            let bytes = if next() % 3 == 0 { &bytes[..cut] } else { &bytes[..] };
            if let Ok(m) = stl(bytes) {
                assert_eq!(m.positions.len(), 3 * m.triangles.len());
            }
        }
    }
}
