//! The allocator policy of `fogsim diagnose`, whose stages each allocate and free
//! vectors of one value per row (MBs each). glibc raises its mmap threshold whenever a
//! mapped block is freed, after which such vectors come from the heap, and a freed block
//! in the heap's middle stays resident: on the 316,800-row campaign the process kept
//! 81.5 MB resident after the diagnosis, 45 MB with this policy. A fixed threshold gives
//! every block of 128 KiB or more its own mapping, returned to the system when freed,
//! so the peak RSS follows the live data (docs/record/diagnose.md, "Memory"). Allocation only:
//! results are the same bytes.

/// Blocks of at least this many bytes get their own mapping.
const MMAP_THRESHOLD_BYTES: i32 = 128 * 1024;

/// Sets the fixed mmap threshold (glibc on Linux; elsewhere nothing to do).
pub fn return_large_blocks_to_the_system() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a malloc tuning parameter; it is thread-safe in glibc.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES);
    }
}
