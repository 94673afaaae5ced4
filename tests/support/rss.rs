//! The process's resident memory, for the tests that hold it flat (`tests/memory.rs`,
//! `tests/soak.rs`).

/// Resident memory of this process, bytes; panics where /proc cannot say (a test of memory that
/// measures nothing must not pass).
pub fn rss_bytes() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm")
        .unwrap_or_else(|e| panic!("memory is measured through /proc/self/statm: {e}"));
    let pages: u64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no resident page count in /proc/self/statm: {statm:?}"));
    assert!(
        pages > 0,
        "/proc/self/statm says no resident pages: {statm:?}"
    );
    pages * 4096
}

// Only tests/memory.rs asks for the live figure; tests/soak.rs, which samples often, the plain one.
#[allow(dead_code)]
unsafe extern "C" {
    /// glibc: hands the free pages of every malloc arena back to the system.
    fn malloc_trim(pad: usize) -> i32;
}

/// Resident memory after the allocator has returned what is free: what the process holds, not
/// what its arenas keep from earlier peaks (which step up by 10-20 MB at times that vary from
/// run to run, as worker threads touch arenas of their own).
#[allow(dead_code)]
pub fn live_rss_bytes() -> u64 {
    // SAFETY: malloc_trim takes no pointers and is safe to call from any thread at any time.
    unsafe {
        malloc_trim(0);
    }
    rss_bytes()
}
