//! How the process's allocator treats the memory it frees.

/// Keeps freed memory in the process. The simulated roll-outs make and
/// free a few hundred kB each (the plan and its checked joint path), on
/// every core's thread; glibc's malloc hands blocks that size back to the
/// kernel when they are freed (it trims the thread's arena, or maps them
/// anew), so each roll-out faulted its pages in again: 7 % of `primo
/// experiment power`'s CPU time went to the kernel. Fixed thresholds
/// (instead of glibc's sliding ones) keep them for the next roll-out.
pub fn keep_freed_blocks() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets malloc's parameters, and runs first in
    // main, before any other thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 64 << 20);
    }
}
