//! The heap's free pages handed back to the operating system after large
//! work (what `AppState::trim_soon` calls once no large work runs).

/// Hands the heap's free pages back to the operating system (glibc's
/// `malloc_trim`): after a large request its buffers are free but glibc
/// keeps them mapped, so the process would stay at its peak size. Costs a
/// walk of the free lists (milliseconds); the state calls it a few times
/// in the seconds after large work, once none runs
/// (`AppState::trim_soon`), when the answers have been written too.
pub(crate) fn trim() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free memory of the allocator's arenas.
    unsafe {
        libc::malloc_trim(0);
    }
}
