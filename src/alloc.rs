//! The process's memory allocator, tuned once at start-up.
//!
//! Detection allocates a handful of large buffers per cloud (at 12k points
//! about 4 MB: neighbour lists, planes, verdicts). glibc serves any block
//! above 128 kB with a fresh `mmap` and unmaps it on free, and trims the
//! heap's free top, so the next cloud touches new pages again, each a page
//! fault that the kernel answers by zeroing a page. Measured on the 12k
//! benchmark sheet (2 threads, 20 detections in one process): 17,350 page
//! faults, about 830 per detection, and 6 % of the time in the kernel
//! (perf, cpu-clock samples); with the thresholds below, 1,390 faults in
//! all and the detection 5 % faster (min 14.4 → 13.6 ms, median 14.7 →
//! 13.8 ms, 10 interleaved rounds). `meshtrim batch` detects many clouds
//! in one process and gains the same way; a single run still touches its
//! pages once.

/// Keeps freed blocks for reuse: blocks up to 32 MiB come from the heap
/// rather than their own mappings, and the heap keeps up to 1 GiB of free
/// memory instead of returning it. Blocks above 32 MiB (a cloud of some
/// 250k points and more) are mapped as before. Call it first in `main`,
/// before any other thread exists. Elsewhere than glibc on Linux it does
/// nothing. No unit test: the thresholds are process-wide, and glibc's
/// own threshold moves with what the process has freed before, so a test
/// in the test binary cannot tell the settings' effect from the default's;
/// `bench/bpd.sh` and the page-fault counts in `docs/bpd.md` ("Speed") measure it.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only sets glibc's allocation thresholds; it takes
    // the allocator's lock, and no allocation is in flight on another
    // thread because none has been started yet.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}
