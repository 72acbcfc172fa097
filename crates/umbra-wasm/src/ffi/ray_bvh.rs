//! `ray-bvh` for a page: the BVH of umbra-three's WebGPU path ([`umbra_geom::ray_bvh::build`],
//! the very hierarchy native `ray-bvh` walks), over the page's world triangles, with what the
//! shared WGSL walk (umbra-wgpu's `shaders/ray_bvh.wgsl`) is prepended with and reads: its
//! constants ([`umbra_geom::ray_bvh::wgsl_constants`]) and the reference's eps
//! ([`umbra_geom::ray_bvh::segment_epsilon`]).
//!
//! [`umbra_ray_bvh_build`] takes world positions (f32, x y z per vertex) and 3 vertex indices
//! per triangle, the triangles numbered as the page's depth pass numbers them (the id each
//! sample's shadow ray skips). It never traps on bad input: the handle then holds an error
//! message ([`umbra_ray_bvh_error_len`] > 0) and no hierarchy. The buffers are read through
//! [`umbra_ray_bvh_buffer_ptr`] (0 nodes, 1 triangle records: f32 vec4s; 2 the constants:
//! UTF-8) and the handle freed with [`umbra_ray_bvh_free`].

use umbra_geom::ray_bvh::{self, RayBvh};

use super::slice;

/// What [`umbra_ray_bvh_build`] returns.
pub struct PageBvh {
    result: Result<Built, String>,
    constants: String,
}

struct Built {
    bvh: RayBvh,
    eps: f32,
}

/// The BVH of `positions` (x y z per vertex) and `indices` (3 per triangle), or why not.
pub fn build_page_bvh(positions: &[f32], indices: &[u32]) -> Result<(RayBvh, f32), String> {
    if !positions.len().is_multiple_of(3) {
        return Err(format!("ray-bvh: {} position floats, not a multiple of 3", positions.len()));
    }
    if !indices.len().is_multiple_of(3) {
        return Err(format!("ray-bvh: {} indices, not a multiple of 3", indices.len()));
    }
    let vertices: Vec<[f32; 3]> = positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    if let Some(i) = vertices.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        return Err(format!("ray-bvh: vertex {i} is not finite ({:?})", vertices[i]));
    }
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    if let Some(k) = indices.iter().position(|&i| i as usize >= vertices.len()) {
        return Err(format!(
            "ray-bvh: index {k} (triangle {}) is {}, but there are {} vertices",
            k / 3,
            indices[k],
            vertices.len()
        ));
    }
    let bvh = ray_bvh::build(&vertices, &triangles);
    let eps = ray_bvh::segment_epsilon(&vertices) as f32;
    Ok((bvh, eps))
}

/// The BVH of the `positions_len` f32 at `positions` and the `indices_len` u32 at `indices`; a
/// handle for the accessors below, which [`umbra_ray_bvh_free`] frees. Null only when out of
/// memory.
///
/// # Safety
/// `positions` points to `positions_len` initialised, aligned f32 and `indices` to
/// `indices_len` u32 (either may be anything when its length is 0).
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_build(
    positions: *const f32,
    positions_len: usize,
    indices: *const u32,
    indices_len: usize,
) -> *mut PageBvh {
    // SAFETY: guaranteed by the caller.
    let (positions, indices) = unsafe { (slice(positions, positions_len), slice(indices, indices_len)) };
    let result = build_page_bvh(positions, indices).map(|(bvh, eps)| Built { bvh, eps });
    Box::into_raw(Box::new(PageBvh { result, constants: ray_bvh::wgsl_constants() }))
}

/// Bytes of the handle's error message (UTF-8), 0 when the hierarchy was built.
///
/// # Safety
/// `b` is a live handle of [`umbra_ray_bvh_build`].
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_error_len(b: *const PageBvh) -> usize {
    (*b).result.as_ref().err().map_or(0, String::len)
}

/// The error message's first byte (see [`umbra_ray_bvh_error_len`]).
///
/// # Safety
/// `b` is a live handle of [`umbra_ray_bvh_build`].
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_error_ptr(b: *const PageBvh) -> *const u8 {
    (*b).result.as_ref().err().map_or(std::ptr::null(), |e| e.as_ptr())
}

fn buffer(b: &PageBvh, which: u32) -> &[u8] {
    match (which, &b.result) {
        (0, Ok(built)) => bytemuck_f32(&built.bvh.nodes),
        (1, Ok(built)) => bytemuck_f32(&built.bvh.triangles),
        (2, _) => b.constants.as_bytes(),
        _ => &[],
    }
}

fn bytemuck_f32(v: &[[f32; 4]]) -> &[u8] {
    // SAFETY: [f32; 4] has no padding and u8 has alignment 1.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Buffer `which`'s first byte: 0 the nodes, 1 the triangle records (vec4s of f32, as
/// [`RayBvh`] lays them out), 2 the WGSL constants (UTF-8).
///
/// # Safety
/// `b` is a live handle of [`umbra_ray_bvh_build`].
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_buffer_ptr(b: *const PageBvh, which: u32) -> *const u8 {
    buffer(&*b, which).as_ptr()
}

/// Buffer `which`'s length in bytes (see [`umbra_ray_bvh_buffer_ptr`]).
///
/// # Safety
/// `b` is a live handle of [`umbra_ray_bvh_build`].
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_buffer_len(b: *const PageBvh, which: u32) -> usize {
    buffer(&*b, which).len()
}

/// Figure `which` of the hierarchy: 0 its nodes, 1 its depth, 2 the reference's eps as f32 bits
/// (0 without a hierarchy).
///
/// # Safety
/// `b` is a live handle of [`umbra_ray_bvh_build`].
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_figure(b: *const PageBvh, which: u32) -> u32 {
    match (&(*b).result, which) {
        (Ok(built), 0) => built.bvh.node_count() as u32,
        (Ok(built), 1) => built.bvh.depth as u32,
        (Ok(built), 2) => built.eps.to_bits(),
        _ => 0,
    }
}

/// Frees a handle of [`umbra_ray_bvh_build`].
///
/// # Safety
/// `b` is a handle of [`umbra_ray_bvh_build`] not freed yet, or null.
#[no_mangle]
pub unsafe extern "C" fn umbra_ray_bvh_free(b: *mut PageBvh) {
    if !b.is_null() {
        drop(Box::from_raw(b));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_the_native_hierarchy() {
        // Two triangles; the same BVH as umbra_geom builds from the same input.
        let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0f32];
        let indices = [0, 1, 2, 0, 1, 3u32];
        let (bvh, eps) = build_page_bvh(&positions, &indices).unwrap();
        let native = ray_bvh::build(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 1, 2], [0, 1, 3]],
        );
        // Bit for bit (the w components are u32 words: a parent of u32::MAX reads as a NaN).
        let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&bvh.nodes), bits(&native.nodes));
        assert_eq!(bits(&bvh.triangles), bits(&native.triangles));
        assert!(eps > 0.0);
    }

    #[test]
    fn bad_input_is_an_error_naming_the_element() {
        let e = build_page_bvh(&[0.0, 0.0, 0.0, 1.0, 0.0], &[]).unwrap_err();
        assert!(e.contains("5 position floats"), "{e}");
        let e = build_page_bvh(&[0.0; 9], &[0, 1]).unwrap_err();
        assert!(e.contains("2 indices"), "{e}");
        let e = build_page_bvh(&[0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0], &[0, 1, 2]).unwrap_err();
        assert!(e.contains("vertex 1 is not finite"), "{e}");
        let e = build_page_bvh(&[0.0; 9], &[0, 1, 3]).unwrap_err();
        assert!(e.contains("index 2 (triangle 0) is 3, but there are 3 vertices"), "{e}");
    }

    #[test]
    fn through_the_exports() {
        let positions = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0f32];
        let indices = [0, 1, 2u32];
        unsafe {
            let h = umbra_ray_bvh_build(positions.as_ptr(), 9, indices.as_ptr(), 3);
            assert_eq!(umbra_ray_bvh_error_len(h), 0);
            assert_eq!(umbra_ray_bvh_figure(h, 0), 1, "one leaf");
            assert_eq!(umbra_ray_bvh_buffer_len(h, 1), 16 * ray_bvh::TRIANGLE_VEC4S);
            let constants = std::str::from_utf8(std::slice::from_raw_parts(
                umbra_ray_bvh_buffer_ptr(h, 2),
                umbra_ray_bvh_buffer_len(h, 2),
            ))
            .unwrap();
            assert!(constants.contains("const BUDGET: u32 = 12000u;"), "{constants}");
            umbra_ray_bvh_free(h);
            let bad = umbra_ray_bvh_build(positions.as_ptr(), 9, indices.as_ptr(), 2);
            assert!(umbra_ray_bvh_error_len(bad) > 0);
            assert_eq!(umbra_ray_bvh_buffer_len(bad, 0), 0);
            umbra_ray_bvh_free(bad);
        }
    }
}
