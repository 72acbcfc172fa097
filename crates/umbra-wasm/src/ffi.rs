//! The functions the WebAssembly module exports (`web/umbra-geom-wasm/index.js` calls them).
//!
//! Memory: the caller allocates input with [`umbra_alloc`], writes positions (f32), the index
//! (u32) and the mesh name (UTF-8) into it, calls [`umbra_prepare`], reads every output buffer
//! through the result's accessors (pointer and length in elements of 4 bytes, little-endian),
//! then frees the result ([`umbra_result_free`]) and its input ([`umbra_free`]).
//! [`umbra_prepare`] never traps on bad input: the result then holds an error message
//! ([`umbra_result_error_len`] > 0) and no buffers.
//!
//! Buffer numbers ([`umbra_result_buffer_ptr`]): 0 positions (f32), 1 normals (f32), 2 indices
//! (u32), 3 sides-data (f32), 4 caps-data (f32), 5 edge triangles (i32). Count numbers
//! ([`umbra_result_count`]): 0 welded vertices, 1 triangles, 2 edges, 3 edge records, 4 input
//! triangles, 5 degenerate (dropped) triangles.
//!
//! Per frame: [`umbra_result_caster`] turns a prepared result's welded mesh and buffers into a
//! caster handle (before the result is freed; the handle outlives it), which answers the
//! z-pass test ([`crate::Clearance`], [`umbra_caster_near_winding`]) and computes the
//! silhouette ([`crate::Silhouette`], [`umbra_caster_silhouette`]) once per frame and light;
//! [`umbra_caster_free`] frees it.
//!
//! Receiver cull ([`crate::cull`]): a receivers handle ([`umbra_receivers_new`]) per light holds
//! the light's grid ([`umbra_receivers_set_grid`], whose parameters the page's scatter reads),
//! the cells the page writes into its memory ([`umbra_receivers_cells_ptr`]) and the map built
//! from them ([`umbra_receivers_build`], [`umbra_receivers_raise_hull`]); then
//! [`umbra_caster_cull`] culls and clamps a caster against it and computes the silhouette of
//! the kept triangles, with the kept triangles ([`umbra_caster_kept_ptr`]) and every vertex's
//! far end ([`umbra_caster_far_ptr`]) beside it.
//!
//! z-pass for casters that share a world matrix: [`umbra_union_new`] asks the test of their
//! union ([`Clearance::union`]), which [`umbra_union_free`] frees.
//!
//! `ray-bvh` in a page: [`crate::ray_bvh`]'s `umbra_ray_bvh_*` functions.

use std::alloc::{alloc, dealloc, Layout};

use umbra_geom::WeldedMesh;

use umbra_geom::sides_data::record_ranges;
use umbra_geom::Aabb;

use crate::cull::Screen;
use crate::{prepare_welded, CasterCull, Clearance, PrepareError, Prepared, Receivers, Silhouette};

/// Version of this interface; the JavaScript module refuses any other.
pub const ABI_VERSION: u32 = 4;

/// Alignment of every [`umbra_alloc`] block (enough for f32, u32 and f64).
const ALIGN: usize = 8;

/// What [`umbra_prepare`] returns: the prepared geometry or its error.
pub struct PrepareResult {
    result: Result<Prepared, PrepareError>,
    bounds: [f32; 6],
    /// The welded mesh of a prepared geometry, until [`umbra_result_caster`] takes it.
    welded: Option<WeldedMesh>,
}

/// [`ABI_VERSION`].
#[no_mangle]
pub extern "C" fn umbra_abi_version() -> u32 {
    ABI_VERSION
}

/// Allocates `len` bytes aligned to 8; null when out of memory. `len` 0 gives a dangling,
/// aligned, non-null pointer that [`umbra_free`] accepts.
#[no_mangle]
pub extern "C" fn umbra_alloc(len: usize) -> *mut u8 {
    if len == 0 {
        return ALIGN as *mut u8;
    }
    match Layout::from_size_align(len, ALIGN) {
        // SAFETY: the layout has a non-zero size.
        Ok(layout) => unsafe { alloc(layout) },
        Err(_) => std::ptr::null_mut(),
    }
}

/// Frees a block of [`umbra_alloc`].
///
/// # Safety
/// `ptr` and `len` must be those of one [`umbra_alloc`] call not freed yet (or `ptr` null).
#[no_mangle]
pub unsafe extern "C" fn umbra_free(ptr: *mut u8, len: usize) {
    if ptr.is_null() || len == 0 {
        return;
    }
    if let Ok(layout) = Layout::from_size_align(len, ALIGN) {
        // SAFETY: the caller passes a block of umbra_alloc(len), which used this layout.
        unsafe { dealloc(ptr, layout) }
    }
}

/// A slice of `len` elements at `ptr`; empty for `len` 0, whatever `ptr` is.
///
/// # Safety
/// For `len` > 0, `ptr` points to `len` initialised, aligned elements.
unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if len == 0 || ptr.is_null() {
        &[]
    } else {
        // SAFETY: guaranteed by the caller.
        unsafe { std::slice::from_raw_parts(ptr, len) }
    }
}

/// Prepares a geometry ([`crate::prepare`]): `positions_len` f32 at `positions`, and
/// `index_len` u32 at `index` when `has_index` is not 0; `name_len` bytes of UTF-8 at `name`
/// (invalid sequences replaced). Returns a result for the accessors below, which
/// [`umbra_result_free`] frees; null only when out of memory.
///
/// # Safety
/// Each pointer with a non-zero length points to that many initialised, aligned elements
/// (blocks of [`umbra_alloc`] do), not written during the call.
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

/// What a caster handle holds: its z-pass test, its silhouette and its receiver cull.
pub struct Caster {
    clearance: Clearance,
    silhouette: Silhouette,
    cull: CasterCull,
    max_mult: usize,
    /// The welded vertices (A, B) of every edge record, built on first use.
    record_vertices: Option<Vec<u32>>,
    /// Whether the last cull kept its volume clamped.
    clamped: bool,
}

/// The caster handle of a prepared result ([`crate::Clearance`] and [`crate::Silhouette`] of
/// its welded mesh and buffers), which [`umbra_caster_free`] frees; it stays valid after
/// [`umbra_result_free`]. Null for an error result or a second call on the same result.
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`].
#[no_mangle]
pub unsafe extern "C" fn umbra_result_caster(r: *mut PrepareResult) -> *mut Caster {
    // SAFETY: guaranteed by the caller.
    let r = unsafe { &mut *r };
    match (r.welded.take(), &r.result) {
        (Some(welded), Ok(p)) => {
            let b = &p.buffers;
            let silhouette = Silhouette::new(&welded, &b.sides_data, &b.edge_triangles, b.max_mult);
            let caster = Caster {
                clearance: Clearance::new(welded),
                silhouette,
                cull: CasterCull::default(),
                max_mult: b.max_mult,
                record_vertices: None,
                clamped: false,
            };
            Box::into_raw(Box::new(caster))
        }
        _ => std::ptr::null_mut(),
    }
}

/// [`crate::Clearance::near_winding`]: `points_len` f64 at `points` (x, y, z per point: the
/// eye and the near-plane corners, the geometry's own space), the light as 4 f32 at `light`
/// (w = 0 directional). Returns `W0`, or -1 when it is unknown (z-fail) or above `i32::MAX`.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`]; `points` points to `points_len`
/// initialised, aligned f64 and `light` to 4 f32 (blocks of [`umbra_alloc`] do).
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_near_winding(
    c: *const Caster,
    points: *const f64,
    points_len: usize,
    light: *const f32,
) -> i32 {
    // SAFETY: guaranteed by the caller.
    let (c, flat, light) = unsafe { (&*c, slice(points, points_len), slice(light, 4)) };
    let (Ok(light), 0) = (<[f32; 4]>::try_from(light), flat.len() % 3) else { return -1 };
    let points: Vec<[f64; 3]> = flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    c.clearance.near_winding(&points, light).and_then(|w| i32::try_from(w).ok()).unwrap_or(-1)
}

/// [`crate::Silhouette::compute`] towards the light at `light` (4 f32, the geometry's own
/// space): returns how many records have a nonzero multiplicity; then
/// [`umbra_caster_orientation_ptr`] (one i8 per triangle) and [`umbra_caster_records_ptr`]
/// (that many i32) point at the results until the next call.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`], `light` points to 4 f32.
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_silhouette(c: *mut Caster, light: *const f32) -> usize {
    // SAFETY: guaranteed by the caller.
    let (c, light) = unsafe { (&mut *c, slice(light, 4)) };
    match <[f32; 4]>::try_from(light) {
        Ok(light) => c.silhouette.compute(light, None),
        Err(_) => 0,
    }
}

/// Floats of [`umbra_caster_cull`]'s parameters.
pub const CULL_PARAMS: usize = 53;

/// [`crate::CasterCull::cull`] against the map of `r`, [`crate::Silhouette::compute`] of the
/// kept triangles towards `light` (4 f32, the geometry's own space, as its volumes are drawn),
/// then [`crate::CasterCull::choose_clamp`]. `params`: [`CULL_PARAMS`] f64, the caster's world
/// matrix, its inverse and its clip-from-object matrix (column-major, 16 each), the viewport's
/// width and height in pixels, 1 for z-fail (light and dark caps drawn) or 0 for z-pass, what a
/// polygon costs in pixels ([`crate::cull::Screen`]), and the clamp: 0 where it pays
/// ([`crate::CasterCull::choose_clamp`]), 1 always, 2 never (far ends at infinity).
/// Returns how many records have a nonzero multiplicity (as [`umbra_caster_silhouette`], whose
/// accessors then read this silhouette), or -1 when nothing was culled (no map, a matrix that
/// is not affine, a light that is not finite, parameters of another length): then call
/// [`umbra_caster_silhouette`].
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`], `r` of [`umbra_receivers_new`];
/// `params` points to `params_len` f64 and `light` to 4 f32.
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_cull(
    c: *mut Caster,
    r: *const Receivers,
    params: *const f64,
    params_len: usize,
    light: *const f32,
) -> i32 {
    // SAFETY: guaranteed by the caller.
    let (c, r, p, light) = unsafe { (&mut *c, &*r, slice(params, params_len), slice(light, 4)) };
    let (Ok(light), CULL_PARAMS) = (<[f32; 4]>::try_from(light), p.len()) else { return -1 };
    let matrix = |at: usize| -> [f64; 16] { std::array::from_fn(|i| p[at + i]) };
    let (world, inverse) = (matrix(0), matrix(16));
    let screen = Screen { clip_from_object: matrix(32), width: p[48], height: p[49], polygon_pixels: p[51] };
    let (caps, mode) = (p[50] != 0.0, p[52]);
    record_vertices(c);
    let Caster { clearance, silhouette, cull, record_vertices: rv, clamped, .. } = c;
    let Some(keep) = cull.cull(clearance.mesh(), clearance.adjacency(), r, &world, &inverse, light) else {
        return -1;
    };
    let n = silhouette.compute(light, Some(keep));
    *clamped = if mode == 1.0 {
        true
    } else {
        // "Never": no pixel is worth a far cap.
        let screen = if mode == 2.0 { Screen { polygon_pixels: f64::INFINITY, ..screen } } else { screen };
        cull.choose_clamp(silhouette, rv.as_deref().unwrap_or(&[]), light, &screen, caps)
    };
    i32::try_from(n).unwrap_or(-1)
}

/// Floats of [`umbra_caster_clamp_box`]'s parameters.
pub const CLAMP_BOX_PARAMS: usize = 42;

/// [`crate::CasterCull::clamp_beyond_box`] (an orthographic view: every volume closed at finite
/// far ends beyond the world box), then [`crate::Silhouette::compute`] of the kept triangles
/// towards `light` (4 f32, the geometry's own space, as its volumes are drawn). `params`:
/// [`CLAMP_BOX_PARAMS`] f64, the caster's world matrix and its inverse (column-major, 16
/// each), the world box (min x y z, max x y z) and the world light (x y z w). Returns how many
/// records have a nonzero multiplicity (the accessors of [`umbra_caster_cull`] then read this
/// silhouette, its kept triangles and far vertices, [`umbra_caster_clamped`] 1), -1 when the
/// matrices are not affine and finite, a light is not finite or the parameters are of another
/// length, -2 when a far end does not fit in an f32 (a triangle too close to the light).
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`]; `params` points to `params_len` f64 and
/// `light` to 4 f32.
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_clamp_box(
    c: *mut Caster,
    params: *const f64,
    params_len: usize,
    light: *const f32,
) -> i32 {
    // SAFETY: guaranteed by the caller.
    let (c, p, light) = unsafe { (&mut *c, slice(params, params_len), slice(light, 4)) };
    let (Ok(light), CLAMP_BOX_PARAMS) = (<[f32; 4]>::try_from(light), p.len()) else { return -1 };
    let matrix = |at: usize| -> [f64; 16] { std::array::from_fn(|i| p[at + i]) };
    let (world, inverse) = (matrix(0), matrix(16));
    // Rounded outwards to f32: the box must hold every sample.
    let down = |x: f64| {
        let f = x as f32;
        if f64::from(f) > x {
            f.next_down()
        } else {
            f
        }
    };
    let up = |x: f64| {
        let f = x as f32;
        if f64::from(f) < x {
            f.next_up()
        } else {
            f
        }
    };
    let bounds =
        umbra_geom::Aabb { min: [down(p[32]), down(p[33]), down(p[34])], max: [up(p[35]), up(p[36]), up(p[37])] };
    let light_world: [f32; 4] = [p[38] as f32, p[39] as f32, p[40] as f32, p[41] as f32];
    let Caster { clearance, silhouette, cull, clamped, .. } = c;
    let keep = match cull.clamp_beyond_box(clearance.mesh(), &world, &inverse, bounds, light_world, light) {
        Ok(Some(keep)) => keep,
        Ok(None) => return -1,
        Err(_) => return -2,
    };
    let n = silhouette.compute(light, Some(keep));
    *clamped = true;
    i32::try_from(n).unwrap_or(-1)
}

/// Whether the last [`umbra_caster_cull`] kept its volume clamped (1; its far caps are then
/// drawn in both counts) or put every far end at infinity (0: no far caps under z-pass).
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_clamped(c: *const Caster) -> u32 {
    // SAFETY: guaranteed by the caller.
    u32::from(unsafe { &*c }.clamped)
}

/// The kept triangles of nonzero orientation of the last [`umbra_caster_cull`] (i32,
/// [`umbra_caster_kept_len`] of them).
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_kept_ptr(c: *const Caster) -> *const i32 {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.silhouette.kept_triangles().as_ptr()
}

/// How many kept triangles of nonzero orientation the last [`umbra_caster_cull`] listed.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_kept_len(c: *const Caster) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.silhouette.kept_triangles().len()
}

/// Triangles the last [`umbra_caster_cull`] kept (of any orientation).
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_cull_kept(c: *const Caster) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.cull.stats().kept
}

/// The far vertex of every welded vertex of the last [`umbra_caster_cull`]: 4 f32 each
/// (homogeneous, the geometry's own space), as many as the welded vertices.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_far_ptr(c: *const Caster) -> *const f32 {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.cull.far().as_ptr().cast()
}

/// Elements (f32) at [`umbra_caster_far_ptr`]: 4 per welded vertex after a cull, else 0.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_far_len(c: *const Caster) -> usize {
    // SAFETY: guaranteed by the caller.
    4 * unsafe { &*c }.cull.far().len()
}

/// The welded vertices `A, B` of every edge record (u32, 2 per record, in sides-data's order:
/// the record's A and B), what the drawer reads a side's far vertices by; built on first call.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_record_vertices_ptr(c: *mut Caster) -> *const u32 {
    // SAFETY: guaranteed by the caller.
    record_vertices(unsafe { &mut *c }).as_ptr()
}

/// Elements (u32) at [`umbra_caster_record_vertices_ptr`]: 2 per edge record.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_record_vertices_len(c: *mut Caster) -> usize {
    // SAFETY: guaranteed by the caller.
    record_vertices(unsafe { &mut *c }).len()
}

fn record_vertices(c: &mut Caster) -> &[u32] {
    let (adj, max_mult) = (c.clearance.adjacency(), c.max_mult);
    c.record_vertices.get_or_insert_with(|| record_ranges(adj, max_mult).flat_map(|r| adj.edges[r.edge]).collect())
}

/// The z-pass test of the union of `n` casters that share one space ([`Clearance::union`]):
/// `casters` points to `n` live caster handles. A handle for [`umbra_union_near_winding`],
/// which [`umbra_union_free`] frees; it does not refer to the casters after the call.
///
/// # Safety
/// `casters` points to `n` live handles of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_union_new(casters: *const *const Caster, n: usize) -> *mut Clearance {
    // SAFETY: guaranteed by the caller.
    let handles = unsafe { slice(casters, n) };
    // SAFETY: each is a live caster handle.
    let meshes = handles.iter().map(|&c| unsafe { &*c }.clearance.mesh());
    Box::into_raw(Box::new(Clearance::union(meshes)))
}

/// [`umbra_caster_near_winding`] asked of a union of [`umbra_union_new`].
///
/// # Safety
/// `u` is a live handle of [`umbra_union_new`]; `points` points to `points_len` f64 and
/// `light` to 4 f32.
#[no_mangle]
pub unsafe extern "C" fn umbra_union_near_winding(
    u: *const Clearance,
    points: *const f64,
    points_len: usize,
    light: *const f32,
) -> i32 {
    // SAFETY: guaranteed by the caller.
    let (u, flat, light) = unsafe { (&*u, slice(points, points_len), slice(light, 4)) };
    let (Ok(light), 0) = (<[f32; 4]>::try_from(light), flat.len() % 3) else { return -1 };
    let points: Vec<[f64; 3]> = flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    u.near_winding(&points, light).and_then(|w| i32::try_from(w).ok()).unwrap_or(-1)
}

/// Frees a handle of [`umbra_union_new`].
///
/// # Safety
/// `u` is a handle of [`umbra_union_new`] not freed yet, or null.
#[no_mangle]
pub unsafe extern "C" fn umbra_union_free(u: *mut Clearance) {
    if !u.is_null() {
        // SAFETY: it came from Box::into_raw in umbra_union_new.
        drop(unsafe { Box::from_raw(u) });
    }
}

/// A new receivers handle without a grid ([`crate::Receivers`]); [`umbra_receivers_free`]
/// frees it.
#[no_mangle]
pub extern "C" fn umbra_receivers_new() -> *mut Receivers {
    Box::into_raw(Box::new(Receivers::new()))
}

/// Frees a handle of [`umbra_receivers_new`].
///
/// # Safety
/// `r` is a handle of [`umbra_receivers_new`] not freed yet, or null.
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_free(r: *mut Receivers) {
    if !r.is_null() {
        // SAFETY: it came from Box::into_raw in umbra_receivers_new.
        drop(unsafe { Box::from_raw(r) });
    }
}

/// [`crate::Receivers::set_grid`]: the world-space light (4 f32), the world box of every
/// sample (6 f32, min then max) and `side` cells a side. Returns 1, or 0 for bad input (no
/// grid; the cells are then empty).
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`]; `light` points to 4 f32, `bounds` to 6.
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_set_grid(
    r: *mut Receivers,
    light: *const f32,
    bounds: *const f32,
    side: u32,
) -> u32 {
    // SAFETY: guaranteed by the caller.
    let (r, light, b) = unsafe { (&mut *r, slice(light, 4), slice(bounds, 6)) };
    let (Ok(light), true) = (<[f32; 4]>::try_from(light), b.len() == 6) else { return 0 };
    let bounds = Aabb { min: [b[0], b[1], b[2]], max: [b[3], b[4], b[5]] };
    u32::from(r.set_grid(light, bounds, side))
}

/// The grid's parameters ([`crate::Receivers::params`], [`crate::cull::GRID_PARAMS`] f32).
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`].
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_params_ptr(r: *const Receivers) -> *const f32 {
    // SAFETY: guaranteed by the caller.
    unsafe { &*r }.params().as_ptr()
}

/// Where the page writes the cells (f32, [`umbra_receivers_cells_len`] of them) before
/// [`umbra_receivers_build`]; valid until the next [`umbra_receivers_set_grid`].
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`].
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_cells_ptr(r: *mut Receivers) -> *mut f32 {
    // SAFETY: guaranteed by the caller.
    unsafe { &mut *r }.cells_mut().as_mut_ptr()
}

/// Cells of the grid (0 without one).
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`].
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_cells_len(r: *mut Receivers) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { &mut *r }.cells_mut().len()
}

/// [`crate::Receivers::build`]: 1, or 0 without a grid.
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`].
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_build(r: *mut Receivers) -> u32 {
    // SAFETY: guaranteed by the caller.
    u32::from(unsafe { &mut *r }.build())
}

/// [`crate::Receivers::build_from_samples`]: `samples_len` f32 at `samples` (x, y, z, w per
/// pixel, the page's position target), the samples with bit `light_bit` of `w` left out. 1, or
/// 0 without a grid.
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`]; `samples` points to `samples_len` f32.
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_build_from_samples(
    r: *mut Receivers,
    samples: *const f32,
    samples_len: usize,
    light_bit: u32,
) -> u32 {
    // SAFETY: guaranteed by the caller.
    let (r, samples) = unsafe { (&mut *r, slice(samples, samples_len)) };
    u32::from(r.build_from_samples(samples, light_bit))
}

/// [`crate::Receivers::raise_hull`] with `points_len` f64 at `points` (x, y, z per point, world
/// space): 1, or 0 when the map cannot bound them (the map is then dropped: nothing is culled).
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`]; `points` points to `points_len` f64.
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_raise_hull(r: *mut Receivers, points: *const f64, points_len: usize) -> u32 {
    // SAFETY: guaranteed by the caller.
    let (r, flat) = unsafe { (&mut *r, slice(points, points_len)) };
    if flat.is_empty() || flat.len() % 3 != 0 {
        return u32::from(r.raise_hull(&[[f64::NAN; 3]]));
    }
    let points: Vec<[f64; 3]> = flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    u32::from(r.raise_hull(&points))
}

/// The orientations of the last [`umbra_caster_silhouette`], one i8 per triangle.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_orientation_ptr(c: *const Caster) -> *const i8 {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.silhouette.orientation().as_ptr()
}

/// The records of nonzero multiplicity of the last [`umbra_caster_silhouette`] (i32).
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_records_ptr(c: *const Caster) -> *const i32 {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.silhouette.records().as_ptr()
}

/// How many of the records of the last [`umbra_caster_silhouette`] (the first ones) have
/// multiplicity ±1.
///
/// # Safety
/// `c` is a live handle of [`umbra_result_caster`].
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_single_records(c: *const Caster) -> usize {
    // SAFETY: guaranteed by the caller.
    unsafe { &*c }.silhouette.single()
}

/// Frees a handle of [`umbra_result_caster`].
///
/// # Safety
/// `c` is a handle of [`umbra_result_caster`] not freed yet, or null.
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_free(c: *mut Caster) {
    if !c.is_null() {
        // SAFETY: it came from Box::into_raw in umbra_result_caster.
        drop(unsafe { Box::from_raw(c) });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare;

    fn read<T: Copy>(ptr: *const u8, len: usize) -> Vec<T> {
        // SAFETY: a live buffer of the result.
        unsafe { slice(ptr.cast::<T>(), len) }.to_vec()
    }

    #[test]
    fn round_trip_through_the_exports() {
        let name = b"quad";
        let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
        let index = [0u32, 1, 2, 0, 2, 3];
        // SAFETY: the slices are live for the call, the result is freed once.
        unsafe {
            let r = umbra_prepare(name.as_ptr(), 4, positions.as_ptr(), 12, index.as_ptr(), 6, 1);
            assert_eq!(umbra_result_error_len(r), 0);
            assert_eq!((umbra_result_count(r, 0), umbra_result_count(r, 1), umbra_result_count(r, 2)), (4, 2, 5));
            assert_eq!(umbra_result_max_mult(r), 2);
            let expected = prepare("quad", &positions, Some(&index)).expect("quad").buffers;
            assert_eq!(read::<f32>(umbra_result_buffer_ptr(r, 3), umbra_result_buffer_len(r, 3)), expected.sides_data);
            assert_eq!(
                read::<i32>(umbra_result_buffer_ptr(r, 5), umbra_result_buffer_len(r, 5)),
                expected.edge_triangles
            );
            assert_eq!(read::<f32>(umbra_result_bounds(r).cast(), 6), vec![0.0, 0.0, 0.0, 1.0, 1.0, 0.0]);
            umbra_result_free(r);

            let r = umbra_prepare(name.as_ptr(), 4, positions.as_ptr(), 12, index.as_ptr(), 5, 1);
            let message = String::from_utf8(read::<u8>(umbra_result_error_ptr(r), umbra_result_error_len(r)));
            assert_eq!(message.expect("utf-8"), "quad: index: 5 entries, not a multiple of 3 (three per triangle)");
            assert_eq!((umbra_result_buffer_len(r, 0), umbra_result_max_mult(r)), (0, 0));
            assert!(umbra_result_bounds(r).is_null());
            umbra_result_free(r);
        }
    }

    #[test]
    fn caster_through_the_exports() {
        // The unit square at z = 1, the light above it; the eye's pyramid below it (W0 = 1),
        // beside it (0) and cut by it (unknown).
        let positions = [0.0f32, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0];
        let index = [0u32, 1, 2, 0, 2, 3];
        let light = [0.5f32, 0.5, 3.0, 1.0];
        let pyramid = |x: f64, y: f64, z: f64| -> Vec<f64> {
            let mut p = vec![x, y, z];
            for (dx, dy) in [(-0.01, -0.01), (0.01, -0.01), (0.01, 0.01), (-0.01, 0.01)] {
                p.extend([x + dx, y + dy, z - 0.1]);
            }
            p
        };
        // SAFETY: the slices are live for the calls; the result and the handle are freed once.
        unsafe {
            let r = umbra_prepare(b"sq".as_ptr(), 2, positions.as_ptr(), 12, index.as_ptr(), 6, 1);
            let c = umbra_result_caster(r);
            assert!(!c.is_null());
            assert!(umbra_result_caster(r).is_null(), "the welded mesh is taken once");
            umbra_result_free(r);
            let ask = |p: &[f64]| umbra_caster_near_winding(c, p.as_ptr(), p.len(), light.as_ptr());
            assert_eq!(ask(&pyramid(0.3, 0.6, 0.5)), 1);
            assert_eq!(ask(&pyramid(3.0, 0.5, 0.5)), 0);
            assert_eq!(ask(&pyramid(0.5, 0.5, 1.05)), -1);
            // The union of the caster with itself: every triangle twice, W0 doubled.
            let both = [c as *const Caster, c as *const Caster];
            let u = umbra_union_new(both.as_ptr(), 2);
            let p = pyramid(0.3, 0.6, 0.5);
            assert_eq!(umbra_union_near_winding(u, p.as_ptr(), p.len(), light.as_ptr()), 2);
            umbra_union_free(u);
            assert_eq!(ask(&pyramid(0.3, 0.6, 0.5)[..14]), -1, "not whole points");
            // The light above the square: both triangles face it, its 4 border edges are the
            // silhouette, the diagonal (multiplicity 0) is not.
            assert_eq!(umbra_caster_silhouette(c, light.as_ptr()), 4);
            assert_eq!(slice(umbra_caster_orientation_ptr(c), 2), &[1, 1]);
            assert_eq!(slice(umbra_caster_records_ptr(c), 4).len(), 4);
            assert_eq!(umbra_caster_single_records(c), 4);
            umbra_caster_free(c);

            let r = umbra_prepare(b"sq".as_ptr(), 2, positions.as_ptr(), 12, index.as_ptr(), 5, 1);
            assert!(umbra_result_caster(r).is_null(), "an error result has none");
            umbra_result_free(r);
        }
    }

    #[test]
    fn alloc_and_free() {
        let p = umbra_alloc(100);
        assert!(!p.is_null() && (p as usize).is_multiple_of(ALIGN));
        // SAFETY: a block of umbra_alloc(100), freed once.
        unsafe { umbra_free(p, 100) };
        let empty = umbra_alloc(0);
        // SAFETY: len 0 is accepted.
        unsafe { umbra_free(empty, 0) };
    }
}
