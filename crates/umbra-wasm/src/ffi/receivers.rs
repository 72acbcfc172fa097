//! A light's receiver map ([`umbra_receivers_new`]): its grid, the cells the page writes and
//! the map built from them, which [`super::umbra_caster_cull`] culls against.

use umbra_geom::Aabb;

use super::slice;
use crate::Receivers;

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

/// [`crate::Receivers::gpu_cull`]: the GPU cull's uniform for the grid
/// ([`umbra_geom::receivers::GPU_CULL_WORDS`] u32, valid until the next call on `r`), with
/// `points_len` f64 at `points` (x, y, z per point, world space: the near pyramid) raised, or
/// none raised when `points_len` is 0. Null without a grid, or when the grid cannot bound the
/// points.
///
/// # Safety
/// `r` is a live handle of [`umbra_receivers_new`]; `points` points to `points_len` f64.
#[no_mangle]
pub unsafe extern "C" fn umbra_receivers_gpu_cull(
    r: *mut Receivers,
    points: *const f64,
    points_len: usize,
) -> *const u32 {
    // SAFETY: guaranteed by the caller.
    let (r, flat) = unsafe { (&mut *r, slice(points, points_len)) };
    let points: Option<Vec<[f64; 3]>> = match (flat.len(), flat.len() % 3) {
        (0, _) => None,
        (_, 0) => Some(flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()),
        _ => return std::ptr::null(),
    };
    r.gpu_cull(points.as_deref()).map_or(std::ptr::null(), <[u32]>::as_ptr)
}
