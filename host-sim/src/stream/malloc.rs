//! The process's malloc settings for streaming: one glibc arena for all stream threads.

/// Asks glibc's malloc for one arena before the stream starts its threads (the command-line
/// tool calls it first thing; a library user such as a Python process keeps its own malloc
/// settings). With an arena
/// per thread (reader, decoder, core, window) each thread's heap keeps its own freed
/// batches and section buffers: 11 MB more peak memory on a 3.9 M-point street, for no
/// measurable CPU (docs/benchmarks.md). Buffers of 1 MiB and more are mapped and unmapped
/// whole, so the window's columns and a section's index go back to the system when freed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn one_arena() {
    // SAFETY: `mallopt` only sets malloc's parameters; these two are documented for any
    // time, and later allocations follow them.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn one_arena() {}
