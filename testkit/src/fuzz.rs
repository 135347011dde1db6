//! What the fuzz harnesses (`fuzz/harness.rs` for the core's readers, `relight/fuzz/harness.rs`
//! for the relighting's) share: a scratch directory per input, and the stable replay of every
//! committed input that the crates' `tests/fuzz_corpus.rs` run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

/// A fresh directory for one input, under the system's temporary directory.
///
/// ```
/// let (a, b) = (haarshift_testkit::fuzz::scratch(), haarshift_testkit::fuzz::scratch());
/// assert!(a.is_dir() && a != b);
/// # std::fs::remove_dir_all(a).unwrap();
/// # std::fs::remove_dir_all(b).unwrap();
/// ```
pub fn scratch() -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("haarshift-fuzz-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `bytes` to `dir/name` and returns the path.
///
/// ```
/// let dir = haarshift_testkit::fuzz::scratch();
/// let path = haarshift_testkit::fuzz::put(&dir, "in.txt", b"seed");
/// assert_eq!(std::fs::read(path).unwrap(), b"seed");
/// # std::fs::remove_dir_all(dir).unwrap();
/// ```
pub fn put(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Replays every file of `fuzz/corpus/TARGET/` and `fuzz/artifacts/TARGET/` (where a run
/// left a crash) through `run`, on every core; panics naming the inputs that panic, and when a
/// target has no seed.
pub fn replay(fuzz: &Path, targets: &[&str], run: fn(&str, &[u8])) {
    let mut inputs: Vec<(&str, PathBuf)> = Vec::new();
    for &target in targets {
        let mut seeds = 0;
        for kind in ["corpus", "artifacts"] {
            let Ok(entries) = std::fs::read_dir(fuzz.join(kind).join(target)) else {
                continue;
            };
            for entry in entries {
                inputs.push((target, entry.unwrap().path()));
                seeds += usize::from(kind == "corpus");
            }
        }
        assert!(seeds > 0, "{target} has no seed corpus");
    }
    let panics: Vec<String> = inputs
        .par_iter()
        .filter_map(|(target, path)| {
            let bytes = std::fs::read(path).unwrap();
            std::panic::catch_unwind(|| run(target, &bytes))
                .is_err()
                .then(|| format!("{target}: {}", path.display()))
        })
        .collect();
    assert!(panics.is_empty(), "these inputs panic: {panics:?}");
}
