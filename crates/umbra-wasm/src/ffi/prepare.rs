//! Preparing a geometry: [`umbra_prepare`] and its result's accessors ([`umbra_result_free`]
//! frees it). The buffer and count numbers are listed in [`super`].

use umbra_geom::WeldedMesh;

use super::slice;
use crate::{prepare_welded, PrepareError, Prepared};

/// What [`umbra_prepare`] returns: the prepared geometry or its error.
pub struct PrepareResult {
    pub(super) result: Result<Prepared, PrepareError>,
    pub(super) bounds: [f32; 6],
    /// The welded mesh of a prepared geometry, until
    /// [`umbra_result_caster`](super::umbra_result_caster) takes it.
    pub(super) welded: Option<WeldedMesh>,
}

/// Prepares a geometry ([`crate::prepare`]): `positions_len` f32 at `positions`, and
/// `index_len` u32 at `index` when `has_index` is not 0; `name_len` bytes of UTF-8 at `name`
/// (invalid sequences replaced). Returns a result for the accessors below, which
/// [`umbra_result_free`] frees; null only when out of memory.
///
/// # Safety
/// Each pointer with a non-zero length points to that many initialised, aligned elements
/// (blocks of [`umbra_alloc`](super::umbra_alloc) do), not written during the call.
#[no_mangle]
pub unsafe extern "C" fn umbra_prepare(
    name: *const u8,
    name_len: usize,
    positions: *const f32,
    positions_len: usize,
    index: *const u32,
    index_len: usize,
    has_index: u32,
) -> *mut PrepareResult {
    // SAFETY: guaranteed by the caller.
    let (name, positions, index) =
        unsafe { (slice(name, name_len), slice(positions, positions_len), slice(index, index_len)) };
    let name = String::from_utf8_lossy(name);
    let (result, welded) = match prepare_welded(&name, positions, (has_index != 0).then_some(index)) {
        Ok((p, w)) => (Ok(p), Some(w)),
        Err(e) => (Err(e), None),
    };
    let bounds = match &result {
        Ok(Prepared { buffers: b, .. }) => b.bounds.map(|b| [b.min, b.max]).unwrap_or([[0.0; 3]; 2]),
        Err(_) => [[0.0; 3]; 2],
    };
    let bounds = [bounds[0][0], bounds[0][1], bounds[0][2], bounds[1][0], bounds[1][1], bounds[1][2]];
    Box::into_raw(Box::new(PrepareResult { result, bounds, welded }))
}

/// The result behind a handle.
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
unsafe fn get<'a>(r: *const PrepareResult) -> &'a PrepareResult {
    // SAFETY: guaranteed by the caller.
    unsafe { &*r }
}

/// Frees a result of [`umbra_prepare`] (every pointer read from it becomes invalid).
///
/// # Safety
/// `r` is a result of [`umbra_prepare`] not freed yet, or null.
#[no_mangle]
pub unsafe extern "C" fn umbra_result_free(r: *mut PrepareResult) {
    if !r.is_null() {
        // SAFETY: it came from Box::into_raw in umbra_prepare.
        drop(unsafe { Box::from_raw(r) });
    }
}

/// Bytes of the error message; 0 when the geometry was prepared.
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_error_len(r: *const PrepareResult) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { get(r) }.result.as_ref().err().map_or(0, |e| e.0.len())
}

/// The error message (UTF-8, [`umbra_result_error_len`] bytes).
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_error_ptr(r: *const PrepareResult) -> *const u8 {
    // SAFETY: guaranteed by the caller.
    unsafe { get(r) }.result.as_ref().err().map_or(std::ptr::null(), |e| e.0.as_ptr())
}

/// Start and length in elements of buffer `which` (see the module documentation).
fn buffer(r: &PrepareResult, which: u32) -> (*const u8, usize) {
    let Ok(p) = &r.result else { return (std::ptr::null(), 0) };
    let b = &p.buffers;
    match which {
        0 => (b.positions.as_ptr().cast(), b.positions.len()),
        1 => (b.normals.as_ptr().cast(), b.normals.len()),
        2 => (b.indices.as_ptr().cast(), b.indices.len()),
        3 => (b.sides_data.as_ptr().cast(), b.sides_data.len()),
        4 => (b.caps_data.as_ptr().cast(), b.caps_data.len()),
        5 => (b.edge_triangles.as_ptr().cast(), b.edge_triangles.len()),
        _ => (std::ptr::null(), 0),
    }
}

/// Where buffer `which` starts (4-byte elements, little-endian).
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_buffer_ptr(r: *const PrepareResult, which: u32) -> *const u8 {
    // SAFETY: guaranteed by the caller.
    buffer(unsafe { get(r) }, which).0
}

/// Elements of buffer `which` (0 for an unknown number or an error).
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_buffer_len(r: *const PrepareResult, which: u32) -> usize {
    // SAFETY: guaranteed by the caller.
    buffer(unsafe { get(r) }, which).1
}

/// Count `which` (see the module documentation); 0 for an unknown number or an error.
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_count(r: *const PrepareResult, which: u32) -> usize {
    // SAFETY: guaranteed by the caller.
    let Ok(p) = &unsafe { get(r) }.result else { return 0 };
    let b = &p.buffers;
    match which {
        0 => b.vertices,
        1 => b.triangles,
        2 => b.edges,
        3 => b.records,
        4 => p.input_triangles,
        5 => p.degenerate_triangles,
        _ => 0,
    }
}

/// `maxMult`: opposite slots per edge record (0 for an error).
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_max_mult(r: *const PrepareResult) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { get(r) }.result.as_ref().map_or(0, |p| p.buffers.max_mult)
}

/// Six f32, min x y z then max x y z, of the vertices the triangles use; null when there are
/// no triangles (or for an error).
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_bounds(r: *const PrepareResult) -> *const f32 {
    // SAFETY: guaranteed by the caller.
    let r = unsafe { get(r) };
    match &r.result {
        Ok(p) if p.buffers.bounds.is_some() => r.bounds.as_ptr(),
        _ => std::ptr::null(),
    }
}
