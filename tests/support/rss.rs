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
