// The fuzz entry points, shared by the cargo-fuzz targets (fuzz/fuzz_targets/*.rs) and the
// replay test crates/umbra-geom/tests/fuzz_replay.rs, which both `include!` this file so a
// regression input is replayed through exactly the code the fuzzer ran. Each entry point
// panics (a finding) when an invariant of the library's contract breaks:
// * loaders: `Ok` meshes index only existing vertices, have finite positions and normals of
//   the right length; `Err` messages name the file and a place (line, byte offset, JSON
//   path); nothing panics;
// * geometry: weld + edge adjacency + deterministic multiplicity on arbitrary floats (NaN,
//   infinities, denormals) keep their invariants, and each edge's multiplicity (paper 001,
//   Alg. 3) equals the sum of its triangles' own orientations whenever the vertex order is
//   strict (no NaN), which is what makes the shadow volume close.

#[allow(unused_imports)]
use umbra_geom::load::{self, Format, LoadError};
#[allow(unused_imports)]
use umbra_geom::{multiplicity, order, EdgeAdjacency, Mesh, WeldedMesh};

/// Largest decompressed size the gzip target accepts.
#[allow(dead_code)]
pub const FUZZ_GZIP_LIMIT: u64 = 1 << 20;

#[allow(dead_code)]
fn check_loaded(result: Result<Mesh, LoadError>, name: &str) {
    match result {
        Ok(mesh) => {
            let n = mesh.positions.len();
            assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n), "{name}: index out of range");
            assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()), "{name}: non-finite position");
            if let Some(normals) = &mesh.normals {
                assert_eq!(normals.len(), n, "{name}: normals length");
            }
        }
        Err(e) => {
            let message = e.to_string();
            assert!(message.starts_with(name) || e.file() != name, "{name}: error does not name the file: {message}");
            assert!(e.location().is_some() || message.contains("byte offset"), "{name}: error has no place: {message}");
        }
    }
}

#[allow(dead_code)]
pub fn fuzz_obj(data: &[u8]) {
    check_loaded(load::load_bytes(data, Format::Obj, "fuzz.obj"), "fuzz.obj");
}

#[allow(dead_code)]
pub fn fuzz_ply(data: &[u8]) {
    check_loaded(load::load_bytes(data, Format::Ply, "fuzz.ply"), "fuzz.ply");
}

#[allow(dead_code)]
pub fn fuzz_stl(data: &[u8]) {
    check_loaded(load::load_bytes(data, Format::Stl, "fuzz.stl"), "fuzz.stl");
}

/// glTF JSON and GLB alike (the loader dispatches on the `glTF` magic).
#[allow(dead_code)]
pub fn fuzz_gltf(data: &[u8]) {
    check_loaded(load::load_bytes(data, Format::Glb, "fuzz.glb"), "fuzz.glb");
}

/// The `.gz` wrapper, then the OBJ loader on what it yields.
#[allow(dead_code)]
pub fn fuzz_gzip(data: &[u8]) {
    match load::gunzip_bytes(data, "fuzz.obj.gz", FUZZ_GZIP_LIMIT) {
        Ok(bytes) => {
            assert!(bytes.len() as u64 <= FUZZ_GZIP_LIMIT, "gunzip exceeded its limit");
            check_loaded(load::load_bytes(&bytes, Format::Obj, "fuzz.obj.gz"), "fuzz.obj.gz");
        }
        Err(e) => {
            let message = e.to_string();
            assert!(message.starts_with("fuzz.obj.gz"), "{message}");
            assert!(message.contains("byte offset") || message.contains("limit"), "{message}");
        }
    }
}

fn f32_at(data: &[u8], at: usize) -> Option<f32> {
    data.get(at..at + 4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Input layout: light (4 x f32 LE), vertex count byte, positions (3 x f32 LE each),
/// then one byte per triangle corner, taken modulo (vertex count + 1) so that one index
/// in range + 1 is out of range (weld must drop it).
#[allow(dead_code)]
pub fn fuzz_geometry(data: &[u8]) {
    if data.len() < 17 {
        return;
    }
    let light = [0, 1, 2, 3].map(|k| f32_at(data, 4 * k).unwrap_or(0.0));
    let wanted = usize::from(data[16]) % 48 + 1;
    let rest = &data[17..];
    let vertices = wanted.min(rest.len() / 12);
    let positions: Vec<[f32; 3]> =
        (0..vertices).map(|v| [0, 1, 2].map(|k| f32_at(rest, 12 * v + 4 * k).unwrap_or(0.0))).collect();
    let corners = &rest[12 * vertices..];
    let modulus = vertices as u32 + 1;
    let triangles: Vec<[u32; 3]> =
        corners.chunks_exact(3).map(|c| [0, 1, 2].map(|k| u32::from(c[k]) % modulus)).collect();
    let mesh = Mesh { positions, triangles, normals: None };

    let welded = WeldedMesh::from_mesh(&mesh);
    assert_eq!(welded.triangles.len() + welded.degenerate_triangles, mesh.triangles.len());
    assert_eq!(welded.source_triangle.len(), welded.triangles.len());
    let n = welded.positions.len();
    for t in &welded.triangles {
        assert!(t.iter().all(|&i| (i as usize) < n), "welded index out of range");
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "welded triangle repeats a vertex");
    }
    // welded positions are pairwise distinct bit patterns (-0.0 folded into +0.0)
    let mut keys: Vec<[u32; 3]> =
        welded.positions.iter().map(|p| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })).collect();
    keys.sort_unstable();
    assert!(keys.windows(2).all(|w| w[0] != w[1]), "two welded vertices share a position");

    let adj = EdgeAdjacency::build(&welded);
    assert_eq!(adj.opposites.len(), 3 * welded.triangles.len());
    assert_eq!(adj.opposite_start.len(), adj.len() + 1);
    let has_nan = |i: u32| welded.positions[i as usize].iter().any(|c| c.is_nan());
    for e in 0..adj.len() {
        let [a, b] = adj.edges[e];
        assert!(a != b && (a as usize) < n && (b as usize) < n);
        let ops = adj.opposites(e);
        assert!(!ops.is_empty());
        let m = multiplicity::edge_multiplicity(&welded.positions, [a, b], ops, light);
        assert!(m.unsigned_abs() as usize <= ops.len());
        if !has_nan(a) && !has_nan(b) {
            assert!(order::less(welded.positions[a as usize], welded.positions[b as usize]), "edge not ordered A < B");
            if ops.iter().all(|&o| !has_nan(o)) {
                let sum: i32 =
                    ops.iter().map(|&o| multiplicity::triangle_orientation(&welded.positions, [a, b, o], light)).sum();
                assert_eq!(m, sum, "edge {e}: multiplicity disagrees with its triangles' orientations");
            }
        }
    }
}
