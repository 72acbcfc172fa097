//! umbra-wasm: the buffers paper 003's browser client draws from, computed inside the browser.
//!
//! The same builder as `umbra export` ([`umbra_geom::export_buffers::build_export_buffers`],
//! after [`umbra_geom::weld::weld`]), compiled to `wasm32-unknown-unknown`, so that a page can
//! prepare any three.js `BufferGeometry` (a position attribute and an optional index) itself:
//! for the same welded mesh every buffer is byte-identical to the files `umbra export` writes.
//!
//! The interface is plain `extern "C"` functions ([`ffi`]) and a small allocator, called by the
//! hand-written ES module `web/umbra-geom-wasm/index.js`; no binding generator is needed.
//! [`prepare`] is the same entry point for Rust callers (and the tests).
//!
//! Bad input is an error that names the mesh and the element, never a panic: no positions,
//! a position count that is not a multiple of 3, a NaN or infinite coordinate, an index count
//! that is not a multiple of 3, an index out of range. Zero-area, open, non-manifold and
//! unwelded meshes are normal input; triangles whose welded vertices coincide are dropped and
//! counted ([`Prepared::degenerate_triangles`]).
//!
//! Build: `cargo build --release --target wasm32-unknown-unknown -p umbra-wasm` (or
//! `node web/build-wasm.mjs`, which also copies the module next to its JavaScript).

use std::fmt;

use umbra_geom::export_buffers::{build_export_buffers, ExportBuffers};
use umbra_geom::weld::weld;
use umbra_geom::{Mesh, WeldedMesh};

mod clearance;
pub mod cull;
pub mod ffi;
mod silhouette;

pub use clearance::Clearance;
pub use cull::{CasterCull, Receivers};
pub use silhouette::Silhouette;

/// Why a geometry could not be prepared; the message starts with the mesh's name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PrepareError(pub String);

impl fmt::Display for PrepareError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PrepareError {}

/// A prepared geometry: the export buffers and what welding dropped.
#[derive(Clone, Debug, PartialEq)]
pub struct Prepared {
    /// Every buffer of `umbra export` ([`umbra_geom::export_buffers`]).
    pub buffers: ExportBuffers,
    /// Triangles of the input.
    pub input_triangles: usize,
    /// Input triangles dropped because two of their welded vertices coincide.
    pub degenerate_triangles: usize,
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Checks a geometry and builds its mesh: vertex `i` at `positions[3i..3i + 3]`, triangles
/// from `index` (three entries each) or, without an index, vertices `3t, 3t + 1, 3t + 2`.
pub fn mesh_from_geometry(name: &str, positions: &[f32], index: Option<&[u32]>) -> Result<Mesh, PrepareError> {
    let err = |message: String| Err(PrepareError(format!("{name}: {message}")));
    if positions.is_empty() {
        return err("no positions: the position attribute is empty".into());
    }
    if !positions.len().is_multiple_of(3) {
        return err(format!("positions: {} floats, not a multiple of 3 (x, y, z per vertex)", positions.len()));
    }
    if let Some(i) = positions.iter().position(|v| !v.is_finite()) {
        let v = positions[i];
        let what = if v.is_nan() { "NaN".to_string() } else { format!("{v}") };
        return err(format!(
            "positions[{i}] (vertex {}, {}) is {what}: coordinates must be finite",
            i / 3,
            AXES[i % 3]
        ));
    }
    let vertices = positions.len() / 3;
    if u32::try_from(vertices).is_err() {
        return err(format!("{vertices} vertices: at most {} can be indexed", u32::MAX));
    }
    let triangles: Vec<[u32; 3]> = match index {
        Some(index) => {
            if !index.len().is_multiple_of(3) {
                return err(format!("index: {} entries, not a multiple of 3 (three per triangle)", index.len()));
            }
            if let Some(k) = index.iter().position(|&v| v as usize >= vertices) {
                return err(format!(
                    "index[{k}] = {} (triangle {}) is out of range: the geometry has {vertices} vertices",
                    index[k],
                    k / 3
                ));
            }
            index.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        None => {
            if !vertices.is_multiple_of(3) {
                return err(format!(
                    "no index and {vertices} vertices, not a multiple of 3 (three per triangle without an index)"
                ));
            }
            (0..vertices as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect()
        }
    };
    Ok(Mesh { positions: positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(), triangles, normals: None })
}

/// Checks, welds and prepares a geometry (see the crate documentation); `name` starts every
/// error message.
pub fn prepare(name: &str, positions: &[f32], index: Option<&[u32]>) -> Result<Prepared, PrepareError> {
    prepare_welded(name, positions, index).map(|(p, _)| p)
}

/// [`prepare`], and the welded mesh the buffers were built from (what [`Clearance::new`]
/// takes).
pub fn prepare_welded(
    name: &str,
    positions: &[f32],
    index: Option<&[u32]>,
) -> Result<(Prepared, WeldedMesh), PrepareError> {
    let mesh = mesh_from_geometry(name, positions, index)?;
    let welded = weld(&mesh);
    let buffers = build_export_buffers(&welded).map_err(|e| PrepareError(format!("{name}: {e}")))?;
    let prepared =
        Prepared { buffers, input_triangles: mesh.triangles.len(), degenerate_triangles: welded.degenerate_triangles };
    Ok((prepared, welded))
}

#[cfg(test)]
mod tests {
    use super::*;
    use umbra_geom::scene::load_scene;

    fn flat(mesh: &Mesh) -> Vec<f32> {
        mesh.positions.iter().flatten().copied().collect()
    }

    fn message(r: Result<Prepared, PrepareError>) -> String {
        r.expect_err("bad input").0
    }

    #[test]
    fn indexed_and_soup_give_the_export_buffers() {
        let mesh = load_scene("default").expect("default scene");
        let expected = build_export_buffers(&weld(&mesh)).expect("buffers");
        let index: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let indexed = prepare("default", &flat(&mesh), Some(&index)).expect("indexed");
        assert_eq!(indexed.buffers, expected);
        assert_eq!(indexed.input_triangles, mesh.triangles.len());
        let soup: Vec<f32> = index.iter().flat_map(|&i| mesh.positions[i as usize]).collect();
        let unindexed = prepare("default", &soup, None).expect("soup");
        assert_eq!(unindexed.buffers, expected);
    }

    #[test]
    fn degenerate_open_and_nonmanifold_input_is_normal() {
        // A fan of three triangles on one edge, one triangle with a repeated vertex.
        let p = [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, -1.0, 0.0, 0.0];
        let r = prepare("fan", &p, Some(&[0, 1, 2, 0, 1, 3, 0, 1, 4, 2, 2, 3])).expect("fan");
        assert_eq!((r.buffers.triangles, r.degenerate_triangles, r.input_triangles), (3, 1, 4));
        assert_eq!((r.buffers.edges, r.buffers.max_mult), (7, 3));
        let only_degenerate = prepare("line", &p[..9], Some(&[0, 0, 1])).expect("degenerate");
        assert_eq!((only_degenerate.buffers.triangles, only_degenerate.buffers.bounds), (0, None));
    }

    #[test]
    fn bad_input_names_the_mesh_and_the_element() {
        assert_eq!(message(prepare("m", &[], None)), "m: no positions: the position attribute is empty");
        assert_eq!(
            message(prepare("m", &[0.0; 4], None)),
            "m: positions: 4 floats, not a multiple of 3 (x, y, z per vertex)"
        );
        let mut p = [0.0f32; 9];
        p[4] = f32::NAN;
        assert_eq!(message(prepare("m", &p, None)), "m: positions[4] (vertex 1, y) is NaN: coordinates must be finite");
        p[4] = 0.0;
        p[8] = f32::NEG_INFINITY;
        assert_eq!(
            message(prepare("m", &p, None)),
            "m: positions[8] (vertex 2, z) is -inf: coordinates must be finite"
        );
        p[8] = 1.0;
        assert_eq!(
            message(prepare("m", &p, Some(&[0, 1]))),
            "m: index: 2 entries, not a multiple of 3 (three per triangle)"
        );
        assert_eq!(
            message(prepare("m", &p, Some(&[0, 1, 2, 0, 3, 1]))),
            "m: index[4] = 3 (triangle 1) is out of range: the geometry has 3 vertices"
        );
        assert_eq!(
            message(prepare("m", &p[..6], None)),
            "m: no index and 2 vertices, not a multiple of 3 (three per triangle without an index)"
        );
    }
}
