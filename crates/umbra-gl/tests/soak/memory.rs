//! Resident memory in use: `VmRSS` after `malloc_trim`, with glibc's mmap threshold fixed,
//! and malloc's own count of the bytes it has handed out.

use crate::common;

/// `VmRSS` of this process in KiB.
pub(crate) fn rss_kib() -> u64 {
    common::child::status_kib("VmRSS")
}

extern "C" {
    /// glibc's `mallopt` (see [`fix_mmap_threshold`]).
    pub(crate) fn mallopt(param: i32, value: i32) -> i32;
    /// glibc's `malloc_trim` (see [`resident_in_use_kib`]).
    pub(crate) fn malloc_trim(pad: usize) -> i32;
    /// glibc's `mallinfo2` (see [`malloc_in_use_kib`]).
    pub(crate) fn mallinfo2() -> MallInfo2;
}

/// glibc's `struct mallinfo2` (glibc 2.33 and later).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MallInfo2 {
    pub(crate) arena: usize,
    pub(crate) ordblks: usize,
    pub(crate) smblks: usize,
    pub(crate) hblks: usize,
    pub(crate) hblkhd: usize,
    pub(crate) usmblks: usize,
    pub(crate) fsmblks: usize,
    pub(crate) uordblks: usize,
    pub(crate) fordblks: usize,
    pub(crate) keepcost: usize,
}

/// Bytes malloc has handed out and not got back, over all arenas, in KiB: the allocated
/// chunks (`uordblks`) plus the separately mapped blocks (`hblkhd`).
pub(crate) fn malloc_in_use_kib() -> u64 {
    // SAFETY: glibc's mallinfo2 only reads allocator statistics.
    let m = unsafe { mallinfo2() };
    ((m.uordblks + m.hblkhd) / 1024) as u64
}

/// `VmRSS` after glibc has given back the free pages of every arena (`malloc_trim(0)`
/// releases whole free pages inside the heaps too, not only at their top): what the process
/// holds in use, not what glibc keeps at hand. llvmpipe allocates from several threads, so
/// freed blocks sit in several arenas, and without the trim a window's minimum moved by
/// ±17 MB from one block to the next (measured).
pub(crate) fn resident_in_use_kib() -> u64 {
    // SAFETY: glibc's malloc_trim may be called at any time; it only returns free memory.
    unsafe { malloc_trim(0) };
    rss_kib()
}

/// glibc's `M_MMAP_THRESHOLD`.
pub(crate) const M_MMAP_THRESHOLD: i32 = -3;

/// Fixes glibc's mmap threshold at its default, 128 KiB, for the rest of the process: every
/// block from 128 KiB up (llvmpipe's textures and buffer stores) gets a mapping of its own
/// and is unmapped when freed. By default glibc raises the threshold to the size of any
/// mapped block that is freed (up to 32 MiB), so after the first 24 MiB cube map of
/// `shadow-map-cube:1024` is freed, its successors land inside malloc arenas, and VmRSS then
/// swings by ±10 % with where they land (measured, see `docs/robustness.md`), which would
/// hide a leak of that size as well as fake one. Same as
/// `GLIBC_TUNABLES=glibc.malloc.mmap_threshold=131072`.
pub(crate) fn fix_mmap_threshold() {
    // SAFETY: glibc's mallopt may be called at any time; it only changes allocator tuning.
    let ok = unsafe { mallopt(M_MMAP_THRESHOLD, 128 * 1024) };
    assert_eq!(ok, 1, "mallopt(M_MMAP_THRESHOLD) failed");
}
