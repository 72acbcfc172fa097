//! GPU allocations the driver may refuse: buffer stores and texture storage checked with
//! `glGetError` right after the call, so a `GL_OUT_OF_MEMORY` becomes THIS call's typed
//! [`GlError::OutOfMemory`] (naming what was allocated and its size) instead of an empty
//! object counted as ready, or an error that the next frame reports as its own.
//!
//! Not from the papers: a buffer the driver refuses is a clear error and the process stays
//! usable. The pattern is the one of
//! `glNamedBufferData`/`glTextureStorage*` error handling in the OpenGL 4.5 core spec,
//! Section 2.3.1 (errors are recorded, the command has no other effect, `glGetError`
//! returns and clears them).
//!
//! GL state touched: `DEBUG_OUTPUT` is switched off around the allocating call and restored
//! (reason at [`checked_allocation`]); [`buffer_with_data`] with [`BufferApi::Bind`] leaves the
//! new buffer bound to the target, exactly as `glBindBuffer` + `glBufferData` would.

use glow::HasContext;

use crate::error::{drain_get_error, GlError};

/// `bytes` as glow's `i32` size; more than 2 GiB is `InvalidParams`, before any GL call.
pub(crate) fn checked_size(bytes: usize, what: &'static str) -> Result<i32, GlError> {
    i32::try_from(bytes).map_err(|_| {
        GlError::InvalidParams(format!("{what} needs {bytes} bytes, more than 2 GiB (GL size limit through glow)"))
    })
}

/// How a buffer's store is specified.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BufferApi {
    /// Direct state access (`glNamedBufferData`, GL 4.5): no binding changes.
    Dsa,
    /// Bind-to-edit (`glBindBuffer(target)` + `glBufferData`, GL ES 3.0): the buffer stays
    /// bound to `target` afterwards (for `ELEMENT_ARRAY_BUFFER` that is the bound vertex
    /// array's state: the caller chooses the target knowingly, as with raw GL).
    Bind(u32),
}

/// What a buffer's new store holds.
#[derive(Clone, Copy, Debug)]
pub(crate) enum BufferData<'a> {
    /// A copy of these bytes.
    Bytes(&'a [u8]),
    /// This many bytes, contents undefined (filled by the GPU or later sub-data uploads).
    Size(usize),
}

impl BufferData<'_> {
    /// Size of the store in bytes.
    pub(crate) fn len(&self) -> usize {
        match self {
            BufferData::Bytes(b) => b.len(),
            BufferData::Size(n) => *n,
        }
    }
}

/// Whether `DEBUG_OUTPUT` exists on this context (GL 4.3+, GL ES 3.2+ or KHR_debug): querying
/// it elsewhere would itself be a `GL_INVALID_ENUM`.
fn has_debug_output(gl: &glow::Context) -> bool {
    let v = gl.version();
    let core = if v.is_embedded { (v.major, v.minor) >= (3, 2) } else { (v.major, v.minor) >= (4, 3) };
    core || gl.supported_extensions().contains("GL_KHR_debug")
}

/// Runs `allocate` (GL calls that allocate `bytes` bytes of storage for `what`) and checks
/// `glGetError` right after it: `GL_OUT_OF_MEMORY` is [`GlError::OutOfMemory`], any other
/// error [`GlError::Gl`] (messages prefixed with `what`). Errors already pending before the
/// call are not ours: they are returned as they are (`during` "before a GPU allocation")
/// and `allocate` is not run. On `Err` the caller deletes what it created; nothing of the
/// error is left pending, in `glGetError` or in a [`crate::GlErrorLog`].
pub(crate) fn checked_allocation(
    gl: &glow::Context,
    what: &str,
    bytes: usize,
    allocate: impl FnOnce(),
) -> Result<(), GlError> {
    let earlier = drain_get_error(gl);
    if !earlier.is_empty() {
        return Err(GlError::Gl { during: "before a GPU allocation", messages: earlier });
    }
    let debug_output = has_debug_output(gl)
        // SAFETY: DEBUG_OUTPUT is a valid capability on this context (checked just above).
        && unsafe { gl.is_enabled(glow::DEBUG_OUTPUT) };
    if debug_output {
        // Reason: the refusal is returned as this call's typed error; with DEBUG_OUTPUT on, a
        // KHR_debug callback (GlErrorLog) would record it a second time and the next frame
        // would report it as its own failure. Restored right after the call.
        // SAFETY: capability toggle on the current context.
        unsafe { gl.disable(glow::DEBUG_OUTPUT) };
    }
    allocate();
    let errors = drain_get_error(gl);
    if debug_output {
        // Reason: restores the caller's DEBUG_OUTPUT (switched off just above).
        // SAFETY: capability toggle on the current context.
        unsafe { gl.enable(glow::DEBUG_OUTPUT) };
    }
    if errors.is_empty() {
        Ok(())
    } else if errors.iter().any(|m| m.contains("GL_OUT_OF_MEMORY")) {
        Err(GlError::OutOfMemory { what: what.to_string(), bytes, messages: errors })
    } else {
        Err(GlError::Gl {
            during: "a GPU allocation",
            messages: errors.into_iter().map(|m| format!("{what}: {m}")).collect(),
        })
    }
}

/// Specifies a new store of `buffer` holding `data` with `usage` (e.g. `STATIC_DRAW`), checked
/// as [`checked_allocation`] does. More than 2 GiB is `InvalidParams` before any GL call
/// (glow passes sizes as `i32`). On `Err` the buffer still exists (the caller owns it) with
/// no usable store: GL leaves a refused store empty, so treat its size as 0.
pub(crate) fn buffer_store(
    gl: &glow::Context,
    buffer: glow::Buffer,
    api: BufferApi,
    data: BufferData<'_>,
    usage: u32,
    what: &'static str,
) -> Result<(), GlError> {
    let size = checked_size(data.len(), what)?;
    checked_allocation(gl, what, data.len(), || {
        // SAFETY: `buffer` is a live buffer of the current context; a Bytes slice outlives the
        // call, which copies it; a Size store has exactly `size` bytes.
        unsafe {
            match (api, data) {
                (BufferApi::Dsa, BufferData::Bytes(b)) => gl.named_buffer_data_u8_slice(buffer, b, usage),
                (BufferApi::Dsa, BufferData::Size(_)) => gl.named_buffer_data_size(buffer, size, usage),
                (BufferApi::Bind(target), BufferData::Bytes(b)) => {
                    gl.bind_buffer(target, Some(buffer));
                    gl.buffer_data_u8_slice(target, b, usage);
                }
                (BufferApi::Bind(target), BufferData::Size(_)) => {
                    gl.bind_buffer(target, Some(buffer));
                    gl.buffer_data_size(target, size, usage);
                }
            }
        }
    })
}

/// Creates a buffer (`glCreateBuffers` for [`BufferApi::Dsa`], `glGenBuffers` for
/// [`BufferApi::Bind`]) whose store holds `data`, checked as [`buffer_store`]; on `Err`
/// nothing is left behind (the buffer is deleted, no GL error stays pending).
pub(crate) fn buffer_with_data(
    gl: &glow::Context,
    api: BufferApi,
    data: BufferData<'_>,
    usage: u32,
    what: &'static str,
) -> Result<glow::Buffer, GlError> {
    checked_size(data.len(), what)?;
    // SAFETY: object creation on the current context; deleted below on every error path.
    let created = unsafe {
        match api {
            BufferApi::Dsa => gl.create_named_buffer(),
            BufferApi::Bind(_) => gl.create_buffer(),
        }
    };
    let buffer = created.map_err(|detail| GlError::Create { what, detail })?;
    match buffer_store(gl, buffer, api, data, usage, what) {
        Ok(()) => Ok(buffer),
        Err(e) => {
            // SAFETY: our own buffer, never handed out; deleting a bound buffer unbinds it.
            unsafe { gl.delete_buffer(buffer) };
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    //! Through a real headless context: the refusal itself is provoked for real by
    //! `tests/gl_failures.rs` (through `SceneGpu::upload` and ts-silhouette's `prepare`, which
    //! use [`buffer_store`]); here
    //! the classification, the cleanup and the bind-to-edit path.

    use super::*;
    use crate::{ContextOptions, GlApi, HeadlessContext};

    fn context() -> HeadlessContext {
        HeadlessContext::with_options(ContextOptions { api: GlApi::Gl45Core, debug: true })
            .unwrap_or_else(|e| panic!("no headless GL 4.5 context: {e}"))
    }

    /// Size and first `N` bytes of `buffer`'s store (through COPY_READ_BUFFER, a binding
    /// only copies use; unbound again afterwards).
    fn read_back<const N: usize>(gl: &glow::Context, buffer: glow::Buffer) -> (i32, [u8; N]) {
        let mut out = [0u8; N];
        // SAFETY: a live buffer of the current context; reads N bytes into an N-byte slice
        // only when the store holds at least N.
        unsafe {
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(buffer));
            let size = gl.get_buffer_parameter_i32(glow::COPY_READ_BUFFER, glow::BUFFER_SIZE);
            if size as usize >= N {
                gl.get_buffer_sub_data(glow::COPY_READ_BUFFER, 0, &mut out);
            }
            gl.bind_buffer(glow::COPY_READ_BUFFER, None);
            (size, out)
        }
    }

    #[test]
    fn dsa_and_bind_to_edit_give_stores_of_the_right_size() {
        let ctx = context();
        let gl = ctx.gl();
        let bytes = [7u8; 40];
        let a = buffer_with_data(gl, BufferApi::Dsa, BufferData::Bytes(&bytes), glow::STATIC_DRAW, "a").expect("a");
        let b = buffer_with_data(gl, BufferApi::Bind(glow::ARRAY_BUFFER), BufferData::Size(24), glow::STREAM_DRAW, "b")
            .expect("b");
        assert_eq!(read_back::<40>(gl, a), (40, bytes));
        assert_eq!(read_back::<0>(gl, b).0, 24);
        // SAFETY: integer query; bind-to-edit leaves the buffer bound, as documented.
        let bound = unsafe { gl.get_parameter_i32(glow::ARRAY_BUFFER_BINDING) } as u32;
        assert_eq!(bound, b.0.get());
        buffer_store(gl, a, BufferApi::Dsa, BufferData::Size(0), glow::STATIC_DRAW, "a again").expect("empty store");
        assert_eq!(read_back::<0>(gl, a).0, 0);
        // SAFETY: our own buffers.
        unsafe {
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            gl.delete_buffer(a);
            gl.delete_buffer(b);
        }
        assert!(ctx.take_gl_errors().is_empty());
    }

    #[test]
    fn an_error_pending_before_the_allocation_is_reported_as_earlier_and_nothing_runs() {
        let ctx = context();
        let gl = ctx.gl();
        // SAFETY: a deliberately invalid enum (GL_INVALID_ENUM), nothing else.
        unsafe { gl.enable(0x1234_5678) };
        let mut ran = false;
        match checked_allocation(gl, "x", 1, || ran = true) {
            Err(GlError::Gl { during, messages }) => {
                assert_eq!(during, "before a GPU allocation");
                assert!(messages.iter().any(|m| m.contains("GL_INVALID_ENUM")), "{messages:?}");
            }
            other => panic!("expected the earlier error, got {other:?}"),
        }
        assert!(!ran, "the allocation ran on top of someone else's error");
        ctx.take_gl_errors(); // the debug callback's copy of the deliberate error
        assert!(ctx.take_gl_errors().is_empty());
    }

    #[test]
    fn a_non_memory_error_is_a_gl_error_naming_the_allocation_and_leaves_nothing_pending() {
        let ctx = context();
        let gl = ctx.gl();
        // An invalid usage enum: GL_INVALID_ENUM from glNamedBufferData, not out of memory.
        match buffer_with_data(gl, BufferApi::Dsa, BufferData::Size(16), 0x1234, "the bad-usage buffer") {
            Err(GlError::Gl { during, messages }) => {
                assert_eq!(during, "a GPU allocation");
                assert!(
                    messages.iter().all(|m| m.starts_with("the bad-usage buffer: ")) && !messages.is_empty(),
                    "{messages:?}"
                );
                assert!(messages.iter().any(|m| m.contains("GL_INVALID_ENUM")), "{messages:?}");
            }
            other => panic!("expected a GL error, got {other:?}"),
        }
        assert!(ctx.take_gl_errors().is_empty(), "the checked error was recorded a second time");
        // SAFETY: capability query on a 4.5 context.
        assert!(unsafe { gl.is_enabled(glow::DEBUG_OUTPUT) }, "DEBUG_OUTPUT not restored");
    }

    #[test]
    fn more_than_2_gib_is_invalid_params_before_any_gl_call() {
        let ctx = context();
        let gl = ctx.gl();
        match buffer_with_data(gl, BufferApi::Dsa, BufferData::Size(1 << 31), glow::STATIC_DRAW, "the huge buffer") {
            Err(GlError::InvalidParams(m)) => assert!(m.contains("the huge buffer") && m.contains("2 GiB"), "{m}"),
            other => panic!("expected InvalidParams, got {other:?}"),
        }
        assert!(ctx.take_gl_errors().is_empty());
    }
}
