//! A caster handle ([`umbra_result_caster`], freed by [`umbra_caster_free`]): its z-pass test,
//! its silhouette per frame and light, and its receiver cull and clamps.

use umbra_geom::sides_data::record_ranges;

use super::{near_winding, slice, PrepareResult};
use crate::cull::Screen;
use crate::{CasterCull, Clearance, Receivers, Silhouette};

/// What a caster handle holds: its z-pass test, its silhouette and its receiver cull.
pub struct Caster {
    pub(super) clearance: Clearance,
    pub(super) silhouette: Silhouette,
    pub(super) cull: CasterCull,
    pub(super) max_mult: usize,
    /// The welded vertices (A, B) of every edge record, built on first use.
    pub(super) record_vertices: Option<Vec<u32>>,
    /// Whether the last cull kept its volume clamped.
    pub(super) clamped: bool,
}

/// The caster handle of a prepared result ([`crate::Clearance`] and [`crate::Silhouette`] of its
/// welded mesh and buffers), which [`umbra_caster_free`] frees; it stays valid after
/// [`umbra_result_free`](super::umbra_result_free). Null for an error result or a second call on
/// the same result.
///
/// # Safety
/// `r` is a live result of [`umbra_prepare`](super::umbra_prepare).
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
/// `c` is a live handle of [`umbra_result_caster`]; `points` points to `points_len` initialised,
/// aligned f64 and `light` to 4 f32 (blocks of [`umbra_alloc`](super::umbra_alloc) do).
#[no_mangle]
pub unsafe extern "C" fn umbra_caster_near_winding(
    c: *const Caster,
    points: *const f64,
    points_len: usize,
    light: *const f32,
) -> i32 {
    // SAFETY: guaranteed by the caller.
    unsafe { near_winding(&(*c).clearance, points, points_len, light) }
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
/// `c` is a live handle of [`umbra_result_caster`], `r` of
/// [`umbra_receivers_new`](super::umbra_receivers_new); `params` points to `params_len` f64 and
/// `light` to 4 f32.
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
