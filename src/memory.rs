//! The process's peak resident memory, for the reports of long computations.
//!
//! One place reads it: on Linux the `VmHWM` line of `/proc/self/status` (the high-water mark
//! of the resident set, what `/usr/bin/time -v` calls "Maximum resident set size"); elsewhere
//! there is no figure and [`peak_resident_bytes`] returns `None`, so a report says "unknown"
//! rather than a guess.

/// The most resident memory this process has held so far, in bytes (`VmHWM`), or `None` where
/// the system does not say.
///
/// ```
/// use haarshift::memory::peak_resident_bytes;
/// if let Some(peak) = peak_resident_bytes() {
///     let block = std::hint::black_box(vec![1u8; 64 << 20]); // touched, so resident
///     assert!(peak_resident_bytes().unwrap() >= peak.max(block.len() as u64));
/// }
/// ```
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_vm_hwm(&status)
}

/// The `VmHWM:  1234 kB` line of a `/proc/<pid>/status` text, in bytes.
fn parse_vm_hwm(status: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let mut words = line["VmHWM:".len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    match words.next()? {
        "kB" => value.checked_mul(1024),
        _ => None,
    }
}

#[cfg(test)]
#[path = "memory_tests.rs"]
mod tests;
