//! Huge-page advice for a batch's large result buffer.

/// Asks the kernel to back a large buffer not yet touched with huge pages (Linux's transparent
/// huge pages, "madvise" mode): a batch's result is written once, and faulting it in 4 KiB pages
/// costs more than computing it (a 10 000-state Talos derivative batch writes 600 MB). Advice
/// only: where it is not taken, nothing changes.
pub(super) fn advise_huge_pages(buffer: &mut [f64]) {
    const LARGE: usize = 1 << 21;
    const PAGE: usize = 4096;
    #[cfg(target_os = "linux")]
    if std::mem::size_of_val(buffer) >= LARGE {
        // madvise takes a page-aligned start: from the buffer's first whole page
        let start = buffer.as_mut_ptr() as usize;
        let offset = start.next_multiple_of(PAGE) - start;
        // SAFETY: the range lies within the buffer's own memory; MADV_HUGEPAGE changes how it is
        // backed, never its contents.
        unsafe {
            libc::madvise(
                (start + offset) as *mut libc::c_void,
                std::mem::size_of_val(buffer) - offset,
                libc::MADV_HUGEPAGE,
            );
        }
    }
}
