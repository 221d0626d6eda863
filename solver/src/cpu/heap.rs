//! The allocator's settings for the CPU backend's threads.
//!
//! The passes of a step allocate and free scratch on the pool's threads. glibc hands a thread
//! heap's free top back to the kernel past 128 kB and serves blocks past that size with fresh
//! `mmap`s, so the next step faults the same pages in again: a profile of the weir's
//! clear-water run put 37 % of it in the kernel (19.5 % page faults, 5.7 % `madvise`). Keeping
//! freed memory in the process removes that; the heap then stays at its largest step's size.

/// Tells glibc to keep freed memory in the process, once per process.
pub(super) fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        ONCE.call_once(|| {
            // SAFETY: mallopt only sets allocator parameters; any value is defined behaviour.
            let trim = unsafe { libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX) };
            // SAFETY: as above.
            let mmap = unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20) };
            if trim == 0 || mmap == 0 {
                log::warn!(
                    "glibc refused to keep freed memory (mallopt: trim {trim}, mmap {mmap}): \
                     the CPU backend runs, with page faults on every step"
                );
            }
        });
    }
}
