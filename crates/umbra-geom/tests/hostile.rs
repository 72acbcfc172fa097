//! Hostile sizes: headers that claim billions of elements over a tiny
//! body, a gzip bomb, a glTF whose nodes instance one mesh thousands of times, millions of
//! triangles on one vertex, and one edge shared by 100,000 triangles.
//!
//! "Before any large allocation" is measured, not assumed: this test binary counts every
//! allocation (`stats_alloc`), and each loader call must allocate in total (an upper bound
//! on its peak) no more than a small multiple of its input. The tests share one lock so a
//! measurement never sees another test's allocations.

use stats_alloc::{Region, StatsAlloc, INSTRUMENTED_SYSTEM};
use std::alloc::System;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Mutex;
use umbra_geom::load::{self, Format, LoadError, LoadOptions, Location};
use umbra_geom::multiplicity::{edge_multiplicity, triangle_orientation};
use umbra_geom::{EdgeAdjacency, Mesh, WeldedMesh};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// Serialises the tests: allocation counts are process-wide.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn lock() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs `f`, returning its result and the bytes it allocated in total (growth included).
fn allocated<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let region = Region::new(GLOBAL);
    let out = f();
    (out, region.change().bytes_allocated)
}

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("umbra-hostile");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Small inputs may allocate this much (error strings, header structures), nothing more.
const SMALL: usize = 64 << 10;

#[test]
fn ply_header_claiming_billions_fails_before_allocating() {
    let _guard = lock();
    let vertex = "element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n";
    let face = "element face {f}\nproperty list uchar int vertex_indices\n";
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        for (n, f, bad_line) in [
            ("4000000000", "0", 3),
            ("18446744073709551615", "0", 3), // u64::MAX: count x size overflows
            ("3", "3000000000", 7),
        ] {
            let mut bytes =
                format!("ply\nformat {format} 1.0\n{}{}end_header\n", vertex.replace("{n}", n), face.replace("{f}", f))
                    .into_bytes();
            bytes.extend([b'0'; 48]); // a tiny body
            let (result, bytes_allocated) = allocated(|| load::load_bytes(&bytes, Format::Ply, "huge.ply"));
            let err = result.unwrap_err();
            assert!(matches!(err, LoadError::TooManyElements { .. }), "{format} {n} {f}: {err:?}");
            assert_eq!(err.location(), Some(&Location::Line(bad_line)), "{format} {n} {f}: {err}");
            assert!(err.to_string().starts_with("huge.ply: line"), "{err}");
            assert!(bytes_allocated < SMALL, "{format} {n} {f}: allocated {bytes_allocated} bytes");
        }
    }
}

#[test]
fn ply_list_length_claiming_billions_fails_at_the_end_of_the_body() {
    let _guard = lock();
    // one face whose u32 list length says 4 billion indices, then 12 bytes
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n".to_vec();
    let body_start = bytes.len() as u64;
    bytes.extend([0u8; 36]); // three vertices at the origin
    bytes.extend(4_000_000_000u32.to_le_bytes());
    bytes.extend([0u8; 12]);
    let (result, bytes_allocated) = allocated(|| load::load_bytes(&bytes, Format::Ply, "list.ply"));
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::Truncated { .. }), "{err:?}");
    assert_eq!(err.location(), Some(&Location::Byte(body_start + 36 + 4 + 12)), "{err}");
    assert!(bytes_allocated < SMALL, "allocated {bytes_allocated} bytes");
}

#[test]
fn binary_stl_claiming_billions_fails_before_allocating() {
    let _guard = lock();
    for count in [u32::MAX, 1_000_000_000, 3] {
        let mut bytes = vec![b' '; 80];
        bytes.extend(count.to_le_bytes());
        bytes.extend([0u8; 100]); // two facets' worth
        let (result, bytes_allocated) = allocated(|| load::load_bytes(&bytes, Format::Stl, "huge.stl"));
        let err = result.unwrap_err();
        match err {
            LoadError::TooManyElements { claimed, max_possible: 2, location: Location::Byte(80), .. } => {
                assert_eq!(claimed, u64::from(count))
            }
            ref other => panic!("{count}: {other:?}"),
        }
        assert!(bytes_allocated < SMALL, "{count}: allocated {bytes_allocated} bytes");
    }
}

#[test]
fn glb_and_gltf_claiming_billions_fail_before_allocating() {
    let _guard = lock();
    // a GLB whose JSON chunk claims 4 GiB
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(40u32.to_le_bytes());
    glb.extend(u32::MAX.to_le_bytes());
    glb.extend(0x4E4F_534Au32.to_le_bytes());
    glb.extend(b"{\"asset\":{\"version\":\"2.0\"}}"[..20].iter());
    let (result, bytes_allocated) = allocated(|| load::load_bytes(&glb, Format::Glb, "huge.glb"));
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::Truncated { location: Location::Byte(_), .. }), "{err:?}");
    assert!(bytes_allocated < SMALL, "glb: allocated {bytes_allocated} bytes");

    // accessors claiming 2^60 elements, with and without a buffer view
    for accessor in [
        r#"{"componentType": 5126, "count": 1152921504606846976, "type": "VEC3"}"#,
        r#"{"bufferView": 0, "componentType": 5126, "count": 1152921504606846976, "type": "VEC3"}"#,
        r#"{"bufferView": 0, "componentType": 5126, "count": 4294967296, "type": "VEC3", "byteOffset": 0}"#,
    ] {
        let doc = format!(
            r#"{{"asset": {{"version": "2.0"}},
                "buffers": [{{"byteLength": 36, "uri": "data:application/octet-stream;base64,{}"}}],
                "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
                "accessors": [{accessor}],
                "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
                "nodes": [{{"mesh": 0}}]}}"#,
            "A".repeat(48)
        );
        let (result, bytes_allocated) = allocated(|| load::load_bytes(doc.as_bytes(), Format::Gltf, "huge.gltf"));
        let err = result.unwrap_err();
        assert!(matches!(err, LoadError::TooManyElements { .. }), "{accessor}: {err:?}");
        assert_eq!(err.location(), Some(&Location::Json("accessors[0].count".into())), "{err}");
        assert!(bytes_allocated < SMALL, "{accessor}: allocated {bytes_allocated} bytes");
    }
}

#[test]
fn gzip_bomb_stops_at_the_limit() {
    let _guard = lock();
    // 256 MiB of spaces (a valid, empty OBJ) compress to about 256 KiB
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    let block = vec![b' '; 1 << 20];
    for _ in 0..256 {
        enc.write_all(&block).unwrap();
    }
    let bomb = enc.finish().unwrap();
    assert!(bomb.len() < 1 << 20, "{}", bomb.len());
    let path = tmp("bomb.obj.gz");
    std::fs::write(&path, &bomb).unwrap();
    drop(block);
    let limit = 4u64 << 20;
    let (result, bytes_allocated) = allocated(|| load::load_path_with(&path, &LoadOptions { max_input_bytes: limit }));
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::InputTooLarge { limit: l, .. } if l == limit), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("bomb.obj.gz") && message.contains("4194304"), "{message}");
    // the decompressed buffer grows by doubling up to the limit; decoder state is small
    assert!(bytes_allocated < 3 * limit as usize, "allocated {bytes_allocated} bytes for a {limit}-byte limit");
    eprintln!(
        "gzip bomb ({} compressed bytes): stopped after allocating {bytes_allocated} bytes (limit {limit})",
        bomb.len()
    );

    // a bomb of many gzip members (MultiGzDecoder keeps reading) stops at the limit too
    let mut members = Vec::new();
    for _ in 0..64 {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        enc.write_all(&vec![b'\n'; 1 << 20]).unwrap();
        members.extend(enc.finish().unwrap());
    }
    let path = tmp("members.ply.gz");
    std::fs::write(&path, &members).unwrap();
    let (result, bytes_allocated) = allocated(|| load::load_path_with(&path, &LoadOptions { max_input_bytes: limit }));
    let err = result.unwrap_err();
    assert!(matches!(err, LoadError::InputTooLarge { .. }), "{err:?}");
    assert!(bytes_allocated < 3 * limit as usize, "members: allocated {bytes_allocated} bytes");
}

/// Base64 without padding concerns (the input length is a multiple of 3 here).
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    assert_eq!(bytes.len() % 3, 0);
    bytes
        .chunks(3)
        .flat_map(|c| {
            let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
            (0..4).map(move |k| A[(n >> (18 - 6 * k)) as usize & 63] as char)
        })
        .collect()
}

/// A glTF of one 1000-triangle mesh (strip of 1002 vertices) instanced by `nodes` nodes.
fn instancing_doc(nodes: usize) -> String {
    let positions: Vec<u8> =
        (0..1002u32).flat_map(|i| [(i / 2) as f32, (i % 2) as f32, 0.0]).flat_map(f32::to_le_bytes).collect();
    let node_list: Vec<String> = (0..nodes).map(|i| format!(r#"{{"mesh": 0, "translation": [0, 0, {i}]}}"#)).collect();
    let roots: Vec<String> = (0..nodes).map(|i| i.to_string()).collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}},
            "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{data}"}}],
            "bufferViews": [{{"buffer": 0, "byteLength": {len}}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 1002, "type": "VEC3"}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": 5}}]}}],
            "scenes": [{{"nodes": [{roots}]}}],
            "nodes": [{nodes}]}}"#,
        len = positions.len(),
        data = base64(&positions),
        roots = roots.join(","),
        nodes = node_list.join(",")
    )
}

#[test]
fn gltf_instancing_bomb_stops_at_the_limit() {
    let _guard = lock();
    // 3000 instances of 1002 vertices + 1000 triangles: 3000 * 24 KiB = 72 MB of output
    // from a 100 KB document
    let doc = instancing_doc(3000);
    assert!(doc.len() < 200_000, "{}", doc.len());
    let path = tmp("instances.gltf");
    std::fs::write(&path, &doc).unwrap();
    let limit = 8u64 << 20;
    let (result, bytes_allocated) = allocated(|| load::load_path_with(&path, &LoadOptions { max_input_bytes: limit }));
    let err = result.unwrap_err();
    match &err {
        LoadError::OutputTooLarge { bytes, limit: l, location: Location::Json(p), .. } => {
            assert_eq!(*l, limit);
            assert!(*bytes > limit, "{err}");
            assert_eq!(p, "meshes[0].primitives[0]");
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("instances.gltf"), "{err}");
    // the output grows to the limit (doubling) and each instance decodes its accessor
    // again; without the bound this load allocates over 250 MB
    assert!(bytes_allocated < 8 * limit as usize, "allocated {bytes_allocated} bytes for a {limit}-byte limit");
    eprintln!("instancing bomb: stopped after allocating {bytes_allocated} bytes (limit {limit})");
    // with a limit above its 72 MB output the same document loads, every instance a copy
    let (mesh, unbounded) =
        allocated(|| load::load_path_with(&path, &LoadOptions { max_input_bytes: 1 << 30 }).unwrap());
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (3000 * 1002, 3000 * 1000));
    assert!(unbounded > 16 * limit as usize, "{unbounded}");
    eprintln!("instancing bomb: loads with a 1 GiB limit after allocating {unbounded} bytes");
}

/// Weld + adjacency, checking the adjacency's invariants.
fn weld_and_adjacency(mesh: &Mesh) -> (WeldedMesh, EdgeAdjacency) {
    let welded = WeldedMesh::from_mesh(mesh);
    let adj = EdgeAdjacency::build(&welded);
    assert_eq!(adj.opposite_start.len(), adj.len() + 1);
    assert_eq!(adj.opposites.len(), 3 * welded.triangles.len());
    (welded, adj)
}

#[test]
fn millions_of_triangles_on_one_vertex() {
    let _guard = lock();
    // a fan of 2 million triangles around vertex 0 (rim vertices on a circle), plus 1 million
    // triangles that are one vertex three times and 1 million over three copies of one position
    let rim = 2_000_000u32;
    let mut positions = vec![[0.0f32, 0.0, 0.0]];
    for i in 0..rim {
        let a = i as f64 / f64::from(rim) * std::f64::consts::TAU;
        positions.push([a.cos() as f32, a.sin() as f32, 0.0]);
    }
    positions.extend([[0.0, 0.0, 0.0]; 2]); // copies of vertex 0
    let copies = [rim + 1, rim + 2];
    let mut triangles: Vec<[u32; 3]> = (0..rim).map(|i| [0, 1 + i, 1 + (i + 1) % rim]).collect();
    triangles.extend(std::iter::repeat_n([0, 0, 0], 1_000_000));
    triangles.extend(std::iter::repeat_n([0, copies[0], copies[1]], 1_000_000));
    let mesh = Mesh { positions, triangles, normals: None };
    let (welded, adj) = weld_and_adjacency(&mesh);
    assert_eq!(welded.degenerate_triangles, 2_000_000);
    assert_eq!(welded.triangles.len(), rim as usize);
    assert_eq!(welded.positions.len(), rim as usize + 1);
    // spokes (shared by two fan triangles) and rim edges (open)
    assert_eq!(adj.len(), 2 * rim as usize);
    assert_eq!(adj.max_opposites(), 2);
    assert_eq!(adj.open_edges(), rim as usize);
    assert_eq!(adj.opposites.len(), 3 * rim as usize);
    // light above the fan: every triangle faces it, spokes cancel (m = 0) and every rim
    // edge is a silhouette (|m| = 1)
    let light = [0.1, 0.2, 5.0, 1.0];
    for e in 0..adj.len() {
        let ops = adj.opposites(e);
        let m = edge_multiplicity(&welded.positions, adj.edges[e], ops, light);
        assert_eq!(m.abs(), if ops.len() == 1 { 1 } else { 0 }, "edge {e} {:?}", adj.edges[e]);
    }
}

#[test]
fn one_edge_shared_by_100k_triangles() {
    let _guard = lock();
    // edge A = (0,0,0), B = (1,0,0); opposite vertices on circles around it; the light below
    // the edge at (0.5, 0, -10). Triangle A -> B -> O with O = (0.5, cos t, sin t) has normal
    // (0, -sin t, cos t), so it faces the light iff cos t < 0.
    let n = 100_000u32;
    let build = |angle: &dyn Fn(u32) -> f64| {
        let mut positions = vec![[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0]];
        positions.extend((0..n).map(|i| {
            let t = angle(i);
            [0.5, t.cos() as f32, t.sin() as f32]
        }));
        let triangles = (0..n).map(|i| [0, 1, 2 + i]).collect();
        Mesh { positions, triangles, normals: None }
    };
    let light = [0.5, 0.0, -10.0, 1.0];
    let quarter = std::f64::consts::FRAC_PI_2;
    // all in the quarter (0, pi/2): each faces away, m = -100000; alternating halves: m = 0
    let cases: [(&dyn Fn(u32) -> f64, i32); 2] = [
        (&|i| quarter * (f64::from(i) + 0.5) / f64::from(n), -(n as i32)),
        (&|i| quarter * (0.1 + 0.8 * f64::from(i) / f64::from(n)) + if i % 2 == 0 { 0.0 } else { quarter }, 0),
    ];
    for (angle, expected) in cases {
        let mesh = build(angle);
        let (welded, adj) = weld_and_adjacency(&mesh);
        assert_eq!(welded.triangles.len(), n as usize);
        assert_eq!(adj.max_opposites(), n as usize);
        assert_eq!(adj.nonmanifold_edges(), 1);
        // the shared edge, ordered A < B
        let shared = (0..adj.len()).find(|&e| adj.opposites(e).len() == n as usize).unwrap();
        let edge = adj.edges[shared];
        assert_eq!(
            [welded.positions[edge[0] as usize], welded.positions[edge[1] as usize]],
            [[0.0; 3], [1.0, 0.0, 0.0]]
        );
        let m = edge_multiplicity(&welded.positions, edge, adj.opposites(shared), light);
        assert_eq!(m, expected);
        // and it agrees with each triangle's own (cap) orientation, summed
        let sum: i32 = adj
            .opposites(shared)
            .iter()
            .map(|&o| triangle_orientation(&welded.positions, [edge[0], edge[1], o], light))
            .sum();
        assert_eq!(m, sum);
        // every other edge (A-O, B-O) is open with multiplicity +-1
        assert_eq!(adj.open_edges(), 2 * n as usize);
    }
}
