//! GL entry points that glow 0.18's `HasContext` does not expose, loaded by name.
//!
//! glClipControl (GL 4.5 / ARB_clip_control), glMultiDrawArraysIndirect and
//! glMultiDrawElementsIndirect (GL 4.3), and the `*IndirectCount` variants (GL 4.6 or
//! ARB_indirect_parameters), and glGetQueryiv (GL 1.5; glow 0.18 has no binding for it). Each
//! is `None` when the driver does not offer it.

use std::ffi::c_void;

type ClipControlFn = unsafe extern "system" fn(origin: u32, depth: u32);
type MultiDrawArraysIndirectFn =
    unsafe extern "system" fn(mode: u32, indirect: *const c_void, drawcount: i32, stride: i32);
type MultiDrawElementsIndirectFn =
    unsafe extern "system" fn(mode: u32, ty: u32, indirect: *const c_void, drawcount: i32, stride: i32);
type MultiDrawArraysIndirectCountFn =
    unsafe extern "system" fn(mode: u32, indirect: *const c_void, drawcount: isize, maxdrawcount: i32, stride: i32);
type MultiDrawElementsIndirectCountFn = unsafe extern "system" fn(
    mode: u32,
    ty: u32,
    indirect: *const c_void,
    drawcount: isize,
    maxdrawcount: i32,
    stride: i32,
);
type GetQueryivFn = unsafe extern "system" fn(target: u32, pname: u32, params: *mut i32);

/// Function pointers for entry points glow lacks; load with [`GlExtra::load`] while the
/// context is current. Calling them requires that same context to be current.
#[derive(Clone, Copy, Debug, Default)]
pub struct GlExtra {
    clip_control: Option<ClipControlFn>,
    multi_draw_arrays_indirect: Option<MultiDrawArraysIndirectFn>,
    multi_draw_elements_indirect: Option<MultiDrawElementsIndirectFn>,
    multi_draw_arrays_indirect_count: Option<MultiDrawArraysIndirectCountFn>,
    multi_draw_elements_indirect_count: Option<MultiDrawElementsIndirectCountFn>,
    get_query_iv: Option<GetQueryivFn>,
}

impl GlExtra {
    /// Loads the entry points through `loader` (eglGetProcAddress, glXGetProcAddress, ...).
    /// The `*IndirectCount` entries are tried under their GL 4.6 name, then with the ARB suffix.
    pub fn load(mut loader: impl FnMut(&str) -> *const c_void) -> Self {
        let mut get = |names: &[&str]| names.iter().map(|n| loader(n)).find(|p| !p.is_null());
        // SAFETY (all transmutes below): each pointer was returned by the GL loader for exactly
        // the named entry point, whose C signature the target type spells out.
        unsafe {
            Self {
                clip_control: get(&["glClipControl"]).map(|p| std::mem::transmute::<*const c_void, ClipControlFn>(p)),
                multi_draw_arrays_indirect: get(&["glMultiDrawArraysIndirect"])
                    .map(|p| std::mem::transmute::<*const c_void, MultiDrawArraysIndirectFn>(p)),
                multi_draw_elements_indirect: get(&["glMultiDrawElementsIndirect"])
                    .map(|p| std::mem::transmute::<*const c_void, MultiDrawElementsIndirectFn>(p)),
                multi_draw_arrays_indirect_count: get(&[
                    "glMultiDrawArraysIndirectCount",
                    "glMultiDrawArraysIndirectCountARB",
                ])
                .map(|p| std::mem::transmute::<*const c_void, MultiDrawArraysIndirectCountFn>(p)),
                multi_draw_elements_indirect_count: get(&[
                    "glMultiDrawElementsIndirectCount",
                    "glMultiDrawElementsIndirectCountARB",
                ])
                .map(|p| std::mem::transmute::<*const c_void, MultiDrawElementsIndirectCountFn>(p)),
                get_query_iv: get(&["glGetQueryiv"]).map(|p| std::mem::transmute::<*const c_void, GetQueryivFn>(p)),
            }
        }
    }

    /// Whether glClipControl was loaded (needed for [`crate::DepthConvention::ReversedZ`]).
    pub fn has_clip_control(&self) -> bool {
        self.clip_control.is_some()
    }
    /// Whether glMultiDrawArraysIndirect and glMultiDrawElementsIndirect were loaded.
    pub fn has_multi_draw_indirect(&self) -> bool {
        self.multi_draw_arrays_indirect.is_some() && self.multi_draw_elements_indirect.is_some()
    }
    /// Whether the `*IndirectCount` variants (GL 4.6 / ARB_indirect_parameters) were loaded.
    pub fn has_multi_draw_indirect_count(&self) -> bool {
        self.multi_draw_arrays_indirect_count.is_some() && self.multi_draw_elements_indirect_count.is_some()
    }

    /// glGetQueryiv(target, GL_CURRENT_QUERY): the name of the query active on `target` (0:
    /// none), or `None` when glGetQueryiv was not loaded.
    ///
    /// # Safety
    /// The context this was loaded from must be current; `target` a query target it knows.
    pub unsafe fn current_query(&self, target: u32) -> Option<u32> {
        self.get_query_iv.map(|f| {
            let mut name = 0i32;
            // SAFETY: caller's contract; one GLint written through a valid pointer.
            unsafe { f(target, glow::CURRENT_QUERY, &mut name) };
            name as u32
        })
    }

    /// glClipControl(origin, depth). Returns false (and does nothing) when unavailable.
    ///
    /// # Safety
    /// The context this was loaded from must be current on this thread.
    pub unsafe fn clip_control(&self, origin: u32, depth: u32) -> bool {
        match self.clip_control {
            // SAFETY: caller guarantees a current context; arguments are plain enums.
            Some(f) => unsafe {
                f(origin, depth);
                true
            },
            None => false,
        }
    }

    /// glMultiDrawArraysIndirect with the indirect buffer bound to DRAW_INDIRECT_BUFFER;
    /// `offset` is a byte offset into it.
    ///
    /// # Safety
    /// Current context; a DRAW_INDIRECT_BUFFER holding `drawcount` commands at `offset`.
    pub unsafe fn multi_draw_arrays_indirect(&self, mode: u32, offset: usize, drawcount: i32, stride: i32) -> bool {
        match self.multi_draw_arrays_indirect {
            // SAFETY: caller's contract; with a bound indirect buffer the pointer is an offset.
            Some(f) => unsafe {
                f(mode, offset as *const c_void, drawcount, stride);
                true
            },
            None => false,
        }
    }

    /// glMultiDrawElementsIndirect, indirect buffer bound, byte `offset`.
    ///
    /// # Safety
    /// Current context; DRAW_INDIRECT_BUFFER and ELEMENT_ARRAY_BUFFER (in the VAO) bound.
    pub unsafe fn multi_draw_elements_indirect(
        &self,
        mode: u32,
        ty: u32,
        offset: usize,
        drawcount: i32,
        stride: i32,
    ) -> bool {
        match self.multi_draw_elements_indirect {
            // SAFETY: caller's contract.
            Some(f) => unsafe {
                f(mode, ty, offset as *const c_void, drawcount, stride);
                true
            },
            None => false,
        }
    }

    /// glMultiDrawArraysIndirectCount: the draw count is read from PARAMETER_BUFFER at
    /// byte `count_offset`.
    ///
    /// # Safety
    /// Current context; DRAW_INDIRECT_BUFFER and PARAMETER_BUFFER bound.
    pub unsafe fn multi_draw_arrays_indirect_count(
        &self,
        mode: u32,
        offset: usize,
        count_offset: usize,
        max_draw_count: i32,
        stride: i32,
    ) -> bool {
        match self.multi_draw_arrays_indirect_count {
            // SAFETY: caller's contract.
            Some(f) => unsafe {
                f(mode, offset as *const c_void, count_offset as isize, max_draw_count, stride);
                true
            },
            None => false,
        }
    }

    /// glMultiDrawElementsIndirectCount, as above with an element type.
    ///
    /// # Safety
    /// Current context; DRAW_INDIRECT_BUFFER, PARAMETER_BUFFER and an element buffer bound.
    pub unsafe fn multi_draw_elements_indirect_count(
        &self,
        mode: u32,
        ty: u32,
        offset: usize,
        count_offset: usize,
        max_draw_count: i32,
        stride: i32,
    ) -> bool {
        match self.multi_draw_elements_indirect_count {
            // SAFETY: caller's contract.
            Some(f) => unsafe {
                f(mode, ty, offset as *const c_void, count_offset as isize, max_draw_count, stride);
                true
            },
            None => false,
        }
    }
}
