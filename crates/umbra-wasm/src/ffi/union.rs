//! The z-pass test of the union of casters that share one space ([`umbra_union_new`]).

use super::{near_winding, slice, Caster};
use crate::Clearance;

/// The z-pass test of the union of `n` casters that share one space ([`Clearance::union`]):
/// `casters` points to `n` live caster handles. A handle for [`umbra_union_near_winding`],
/// which [`umbra_union_free`] frees; it does not refer to the casters after the call.
///
/// # Safety
/// `casters` points to `n` live handles of [`umbra_result_caster`](super::umbra_result_caster).
#[no_mangle]
pub unsafe extern "C" fn umbra_union_new(casters: *const *const Caster, n: usize) -> *mut Clearance {
    // SAFETY: guaranteed by the caller.
    let handles = unsafe { slice(casters, n) };
    // SAFETY: each is a live caster handle.
    let meshes = handles.iter().map(|&c| unsafe { &*c }.clearance.mesh());
    Box::into_raw(Box::new(Clearance::union(meshes)))
}

/// [`umbra_caster_near_winding`](super::umbra_caster_near_winding) asked of a union of
/// [`umbra_union_new`].
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
    unsafe { near_winding(&*u, points, points_len, light) }
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
