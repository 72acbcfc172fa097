//! PLY loader: ASCII, binary little- and big-endian, any numeric types, skipped elements
//! and list properties, and every bad-input error naming the file and line / byte offset.

use std::path::PathBuf;
use umbra_geom::load::{self, Format, LoadError, Location};
use umbra_geom::Mesh;

#[derive(Clone, Copy, PartialEq)]
enum Enc {
    Ascii,
    Le,
    Be,
}

impl Enc {
    fn name(self) -> &'static str {
        match self {
            Enc::Ascii => "ascii",
            Enc::Le => "binary_little_endian",
            Enc::Be => "binary_big_endian",
        }
    }
}

/// Writes PLY body values in one encoding.
struct W {
    enc: Enc,
    out: Vec<u8>,
}

macro_rules! put {
    ($name:ident, $t:ty) => {
        fn $name(&mut self, v: $t) -> &mut Self {
            match self.enc {
                Enc::Ascii => self.out.extend_from_slice(format!("{v} ").as_bytes()),
                Enc::Le => self.out.extend_from_slice(&v.to_le_bytes()),
                Enc::Be => self.out.extend_from_slice(&v.to_be_bytes()),
            }
            self
        }
    };
}

impl W {
    fn new(enc: Enc, header: &str) -> Self {
        let header = header.replace("FORMAT", enc.name());
        W { enc, out: header.into_bytes() }
    }
    put!(f32, f32);
    put!(f64, f64);
    put!(i32, i32);
    put!(u32, u32);
    put!(i16, i16);
    put!(u16, u16);
    put!(u8, u8);
    put!(i8, i8);
    fn row(&mut self) -> &mut Self {
        if self.enc == Enc::Ascii {
            self.out.push(b'\n');
        }
        self
    }
}

fn ply(bytes: &[u8]) -> Result<Mesh, LoadError> {
    load::load_bytes(bytes, Format::Ply, "test.ply")
}

const RICH_HEADER: &str = "ply\nformat FORMAT 1.0\ncomment mixed types, skipped lists and elements\n\
element vertex 5\nproperty list uchar float texture\nproperty float x\nproperty double y\nproperty int z\n\
property uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n\
element material 1\nproperty list ushort uchar name\nproperty double shininess\n\
element face 3\nproperty list uchar int vertex_indices\nproperty int flags\n\
element edge 2\nproperty short vertex1\nproperty short vertex2\nend_header\n";

/// Five vertices, a material, a quad and two triangles, two edges.
fn rich(enc: Enc) -> Vec<u8> {
    let mut w = W::new(enc, RICH_HEADER);
    let verts: [([f32; 3], [f32; 3]); 5] = [
        ([0.5, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([1.5, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([1.5, 1.25, 0.0], [1.0, 0.0, 0.0]),
        ([0.5, 1.25, -3.0], [0.0, 0.0, -1.0]),
        ([-0.25, 0.5, 7.0], [0.6, 0.8, 0.0]),
    ];
    for (i, (p, n)) in verts.iter().enumerate() {
        w.u8(i as u8 % 3);
        for k in 0..(i % 3) {
            w.f32(k as f32 * 0.25);
        }
        w.f32(p[0]).f64(f64::from(p[1])).i32(p[2] as i32).u8(200).f32(n[0]).f32(n[1]).f32(n[2]).row();
    }
    // material: a name list of 3 chars and a double
    w.u16(3).u8(b'a').u8(b'b').u8(b'c').f64(0.5).row();
    w.u8(4).i32(0).i32(1).i32(2).i32(3).i32(-1).row();
    w.u8(3).i32(1).i32(4).i32(2).i32(0).row();
    w.u8(3).i32(4).i32(3).i32(2).i32(7).row();
    w.i16(0).i16(1).row();
    w.i16(1).i16(2).row();
    w.out
}

fn expected_rich() -> Mesh {
    Mesh {
        positions: vec![[0.5, 0.0, 0.0], [1.5, 0.0, 0.0], [1.5, 1.25, 0.0], [0.5, 1.25, -3.0], [-0.25, 0.5, 7.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3], [1, 4, 2], [4, 3, 2]],
        normals: Some(vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.6, 0.8, 0.0]]),
    }
}

fn header_len(bytes: &[u8]) -> u64 {
    let end = b"end_header\n";
    (bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len()) as u64
}

type Check = fn(&LoadError) -> bool;

fn assert_err_at(result: Result<Mesh, LoadError>, at: Location, check: fn(&LoadError) -> bool) {
    let err = result.expect_err("expected an error");
    assert!(check(&err), "wrong variant: {err:?}");
    assert_eq!(err.location(), Some(&at), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("test.ply"), "{msg}");
    let where_ = match at {
        Location::Line(l) => format!("line {l}"),
        Location::Byte(b) => format!("byte offset {b}"),
        Location::Json(j) => j,
    };
    assert!(msg.contains(&where_), "{msg} lacks {where_}");
}

#[test]
fn all_three_encodings_load_the_same_mesh() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let m = ply(&rich(enc)).unwrap_or_else(|e| panic!("{}: {e}", enc.name()));
        assert_eq!(m, expected_rich(), "{}", enc.name());
    }
}

#[test]
fn ascii_fixture_with_skipped_lists_and_elements() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/tetra_ascii.ply");
    let m = load::load_path(&path).unwrap();
    assert_eq!(m.positions, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    assert_eq!(m.triangles, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    assert!(m.normals.is_none());
}

#[test]
fn vertex_index_name_and_other_integer_types() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let mut w = W::new(
            enc,
            "ply\nformat FORMAT 1.0\nelement vertex 3\nproperty uchar x\nproperty char y\nproperty ushort z\n\
             element face 1\nproperty list int uint vertex_index\nend_header\n",
        );
        w.u8(0).i8(-1).u16(0).row().u8(255).i8(0).u16(0).row().u8(0).i8(1).u16(65535).row();
        w.i32(3).u32(2).u32(1).u32(0).row();
        let m = ply(&w.out).unwrap();
        assert_eq!(m.positions, vec![[0.0, -1.0, 0.0], [255.0, 0.0, 0.0], [0.0, 1.0, 65535.0]]);
        assert_eq!(m.triangles, vec![[2, 1, 0]]);
    }
}

#[test]
fn empty_ply_is_an_empty_mesh() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n");
        let m = ply(&w.out).unwrap();
        assert!(m.positions.is_empty() && m.triangles.is_empty());
    }
    // CRLF header
    let m = ply(b"ply\r\nformat ascii 1.0\r\nelement vertex 1\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n1 2 3\r\n").unwrap();
    assert_eq!(m.positions, vec![[1.0, 2.0, 3.0]]);
}

#[test]
fn short_faces_and_tristrips_warn() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                element face 2\nproperty list uchar int vertex_indices\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n\
                0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n3 0 1 2\n";
    let loaded = load::load_bytes_detailed(text.as_bytes(), Format::Ply, "test.ply").unwrap();
    assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(loaded.warnings.len(), 2, "{:?}", loaded.warnings);
    assert!(loaded.warnings.iter().all(|w| w.contains("test.ply")));
}

#[test]
fn error_header_claims_billions_of_elements() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let mut w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
        w.f32(1.0).f32(2.0).f32(3.0).row();
        assert_err_at(ply(&w.out), Location::Line(3), |e| {
            matches!(e, LoadError::TooManyElements { claimed: 4_000_000_000, .. })
        });
        // the face count is checked after the vertices' share of the body
        let mut w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 18446744073709551615\nproperty list uchar int vertex_indices\nend_header\n");
        w.f32(1.0).f32(2.0).f32(3.0).row();
        assert_err_at(ply(&w.out), Location::Line(7), |e| matches!(e, LoadError::TooManyElements { .. }));
    }
}

#[test]
fn error_truncated_binary_body_names_the_end_offset() {
    for enc in [Enc::Le, Enc::Be] {
        let full = rich(enc);
        for cut in [1usize, 3, 20] {
            let bytes = &full[..full.len() - cut];
            let err = ply(bytes).expect_err("truncated");
            // either the pre-allocation check or the reader notices, naming a place in the file
            match &err {
                LoadError::Truncated { location, .. } => assert_eq!(location, &Location::Byte(bytes.len() as u64)),
                LoadError::TooManyElements { location: Location::Line(_), .. } => {}
                other => panic!("{other:?}"),
            }
            assert!(err.to_string().contains("test.ply"));
        }
        // cutting inside the last edge row is always a reader-side truncation
        let bytes = &full[..full.len() - 1];
        assert_err_at(ply(bytes), Location::Byte(bytes.len() as u64), |e| matches!(e, LoadError::Truncated { .. }));
    }
}

#[test]
fn error_truncated_ascii_body_names_the_last_line() {
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n";
    assert_err_at(ply(text.as_bytes()), Location::Line(13), |e| matches!(e, LoadError::Truncated { .. }));
}

#[test]
fn error_index_out_of_range_binary_offset() {
    for enc in [Enc::Le, Enc::Be] {
        let mut w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
        for _ in 0..3 {
            w.f32(0.0).f32(0.0).f32(0.0);
        }
        w.u8(3).i32(0).i32(1).i32(7);
        let h = header_len(&w.out);
        assert_err_at(ply(&w.out), Location::Byte(h + 36 + 1 + 8), |e| {
            matches!(e, LoadError::IndexOutOfRange { index: 7, count: 3, .. })
        });
        let mut w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
        for _ in 0..3 {
            w.f32(0.0).f32(0.0).f32(0.0);
        }
        w.u8(3).i32(-1).i32(1).i32(2);
        assert_err_at(ply(&w.out), Location::Byte(h + 36 + 1), |e| {
            matches!(e, LoadError::IndexOutOfRange { index: -1, .. })
        });
    }
}

#[test]
fn error_non_finite_binary_offset() {
    for enc in [Enc::Le, Enc::Be] {
        for bad in [f64::NAN, f64::INFINITY, 1e300] {
            let mut w = W::new(enc, "ply\nformat FORMAT 1.0\nelement vertex 2\nproperty float x\nproperty double y\nproperty float z\nend_header\n");
            w.f32(0.0).f64(0.0).f32(0.0).f32(1.0).f64(bad).f32(0.0);
            let h = header_len(&w.out);
            // 1e300 is finite as a double but not as f32
            assert_err_at(ply(&w.out), Location::Byte(h + 16 + 4), |e| matches!(e, LoadError::NonFinite { .. }));
        }
    }
}

#[test]
fn error_ascii_body_lines() {
    let head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let cases: [(&str, u64, Check); 5] = [
        ("0 0 0\n1 nan 0\n3 0 1 1\n", 11, |e| matches!(e, LoadError::NonFinite { .. })),
        ("0 0 0\n1 1.2.3 0\n3 0 1 1\n", 11, |e| matches!(e, LoadError::Malformed { .. })),
        ("0 0 0\n1 1 0\n3 0 1 2\n", 12, |e| matches!(e, LoadError::IndexOutOfRange { index: 2, count: 2, .. })),
        ("0 0 0\n1 1 0\n3 0 x 1\n", 12, |e| matches!(e, LoadError::Malformed { .. })),
        ("0 0 0\n1 1 0\n-3 0 1 1\n", 12, |e| matches!(e, LoadError::Malformed { .. })),
    ];
    for (body, line, check) in cases {
        assert_err_at(ply(format!("{head}{body}").as_bytes()), Location::Line(line), check);
    }
}

#[test]
fn error_bad_headers() {
    let cases: [(&str, u64, Check); 10] = [
        ("plx\nformat ascii 1.0\nend_header\n", 1, |e| matches!(e, LoadError::Malformed { .. })),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", 5, |e| {
            matches!(e, LoadError::Truncated { .. })
        }),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n", 4, |e| {
            matches!(e, LoadError::Malformed { .. })
        }),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", 3, |e| matches!(e, LoadError::Malformed { .. })),
        ("ply\nelement vertex 0\nend_header\n", 3, |e| matches!(e, LoadError::Malformed { .. })),
        ("ply\nformat binary_middle_endian 1.0\nend_header\n", 2, |e| matches!(e, LoadError::Malformed { .. })),
        ("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", 3, |e| matches!(e, LoadError::Malformed { .. })),
        ("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\nend_header\n", 4, |e| {
            matches!(e, LoadError::Malformed { .. })
        }),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n", 3, |e| {
            matches!(e, LoadError::Malformed { .. })
        }),
        (
            "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar float vertex_indices\nend_header\n3 0 1 2\n",
            3,
            |e| matches!(e, LoadError::Malformed { .. }),
        ),
    ];
    for (text, line, check) in cases {
        assert_err_at(ply(text.as_bytes()), Location::Line(line), check);
    }
    assert_err_at(ply(b""), Location::Line(1), |e| matches!(e, LoadError::Truncated { .. }));
}

#[test]
fn arbitrary_mutations_never_panic() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        state >> 33
    };
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let base = rich(enc);
        for _ in 0..3000 {
            let mut bytes = base.clone();
            for _ in 0..1 + next() % 4 {
                let i = next() as usize % bytes.len();
                bytes[i] = next() as u8;
            }
            let cut = next() as usize % (bytes.len() + 1);
            let bytes = if next() % 4 == 0 { &bytes[..cut] } else { &bytes[..] };
            if let Ok(m) = ply(bytes) {
                let n = m.positions.len() as u32;
                assert!(m.triangles.iter().flatten().all(|&i| i < n));
            }
        }
    }
}
