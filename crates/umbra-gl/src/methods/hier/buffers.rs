//! The hier methods' buffer helpers: checked allocation of several buffers at once (a refused
//! one is the typed error and nothing is left behind) and read-back of state words (a stall:
//! tests, statistics, work counts and hier-triangle's resumed traversal on llvmpipe).

use glow::HasContext;

use crate::error::GlError;
use crate::gpu_buffer::{buffer_store, BufferApi, BufferData};

/// `count` u32 words of `buffer` from word `first`, read back (a stall; tests and statistics).
pub fn read_words(gl: &glow::Context, buffer: glow::Buffer, first: usize, count: usize) -> Vec<u32> {
    let mut bytes = vec![0u8; 4 * count];
    // SAFETY: reading a range the caller knows to lie within the buffer, through
    // COPY_READ_BUFFER, unbound again afterwards.
    unsafe {
        // Reason: the shaders' writes must be visible to the read.
        gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
        gl.bind_buffer(glow::COPY_READ_BUFFER, Some(buffer));
        gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, (4 * first) as i32, &mut bytes);
        gl.bind_buffer(glow::COPY_READ_BUFFER, None);
    }
    bytes.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Buffers of `sizes` bytes (DYNAMIC_COPY: written and read by the GPU every frame), named by
/// `names` in errors; on any failure the ones made are deleted and the typed error returned.
pub fn allocate_buffers(
    gl: &glow::Context,
    sizes: &[usize],
    names: &[&'static str],
) -> Result<Vec<glow::Buffer>, GlError> {
    let mut made = Vec::with_capacity(sizes.len());
    let mut failure = None;
    for (&bytes, &what) in sizes.iter().zip(names) {
        // SAFETY: creating a buffer name on the current context (deleted on error below).
        match unsafe { gl.create_named_buffer() } {
            Ok(b) => {
                made.push(b);
                // Checked: a refused store is this call's typed error, never an empty buffer
                // counted as ready.
                if let Err(e) = buffer_store(gl, b, BufferApi::Dsa, BufferData::Size(bytes), glow::DYNAMIC_COPY, what) {
                    failure = Some(e);
                    break;
                }
            }
            Err(detail) => {
                failure = Some(GlError::Create { what, detail });
                break;
            }
        }
    }
    if let Some(e) = failure {
        // SAFETY: our own buffers, never handed out.
        unsafe {
            for b in made {
                gl.delete_buffer(b);
            }
        }
        return Err(e);
    }
    Ok(made)
}
