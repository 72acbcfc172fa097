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
//! union ([`crate::Clearance::union`]), which [`umbra_union_free`] frees.
//!
//! `ray-bvh` in a page: [`umbra_ray_bvh_build`] and its accessors (`ray_bvh.rs`).

use std::alloc::{alloc, dealloc, Layout};

mod caster;
mod prepare;
mod ray_bvh;
mod receivers;
mod union;

pub use caster::*;
pub use prepare::*;
pub use ray_bvh::*;
pub use receivers::*;
pub use union::*;

/// Version of this interface; the JavaScript module refuses any other.
pub const ABI_VERSION: u32 = 5;

/// Alignment of every [`umbra_alloc`] block (enough for f32, u32 and f64).
const ALIGN: usize = 8;

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

/// [`Clearance::near_winding`](crate::Clearance::near_winding) of `c` asked through the
/// exports: `points_len` f64 at `points` (x, y, z per point), the light as 4 f32 at `light`.
/// `W0`, or -1 when it is unknown, above `i32::MAX`, or the input is malformed.
///
/// # Safety
/// `points` points to `points_len` initialised, aligned f64 and `light` to 4 f32.
unsafe fn near_winding(c: &crate::Clearance, points: *const f64, points_len: usize, light: *const f32) -> i32 {
    // SAFETY: guaranteed by the caller.
    let (flat, light) = unsafe { (slice(points, points_len), slice(light, 4)) };
    let (Ok(light), 0) = (<[f32; 4]>::try_from(light), flat.len() % 3) else { return -1 };
    let points: Vec<[f64; 3]> = flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    c.near_winding(&points, light).and_then(|w| i32::try_from(w).ok()).unwrap_or(-1)
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
