//! The bytes of the scene caches that `relight precompute` and `relight merge` write, pinned:
//! every cache of `testdata/cache_hashes.args` is written again, in order, from the
//! repository's root, and its SHA-256 compared with its line of
//! `testdata/cache_hashes.sha256`. `scripts/cache_hashes.sh` writes the same caches from the
//! same table and says when and how the hashes are made again.

use std::path::Path;

use sha2::{Digest, Sha256};

use crate::common::{succeeds_in, testdata};

/// One line of the table: the cache's file name and the arguments after `haarshift` that
/// write it (`{out}` the output folder; `-o {out}/NAME` is appended).
struct Cache {
    name: String,
    args: Vec<String>,
}

/// The table `testdata/cache_hashes.args`, in order: blank lines and `#` comments skipped,
/// each line split on whitespace.
fn caches() -> Vec<Cache> {
    let path = testdata("cache_hashes.args");
    let table = std::fs::read_to_string(&path).unwrap();
    table
        .lines()
        .map(str::trim)
        .filter(|line| !line.is_empty() && !line.starts_with('#'))
        .map(|line| {
            let mut words = line.split_whitespace().map(str::to_owned);
            let name = words.next().unwrap();
            let args: Vec<String> = words.collect();
            assert!(
                !args.is_empty(),
                "{}: {name} has no arguments",
                path.display()
            );
            Cache { name, args }
        })
        .collect()
}

/// `testdata/cache_hashes.sha256`, in order: (name, hash) from sha256sum's `HASH  NAME`.
fn pinned() -> Vec<(String, String)> {
    let path = testdata("cache_hashes.sha256");
    let text = std::fs::read_to_string(&path).unwrap();
    text.lines()
        .map(|line| {
            let (hash, name) = line
                .split_once(' ')
                .unwrap_or_else(|| panic!("{}: {line:?} is not `HASH  NAME`", path.display()));
            (
                name.trim_start_matches([' ', '*']).to_owned(),
                hash.to_owned(),
            )
        })
        .collect()
}

fn sha256_hex(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap();
    Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn every_cache_is_written_with_its_pinned_bytes() {
    let caches = caches();
    let pinned = pinned();
    let names: Vec<&str> = caches.iter().map(|c| c.name.as_str()).collect();
    let pinned_names: Vec<&str> = pinned.iter().map(|(name, _)| name.as_str()).collect();
    assert_eq!(
        names, pinned_names,
        "testdata/cache_hashes.args and testdata/cache_hashes.sha256 name other caches: \
         regenerate the hashes with scripts/cache_hashes.sh"
    );
    // The table names testdata/ from the root: a scene file's environment is recorded by the
    // path it was reached by.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let mut changed = Vec::new();
    for (cache, (_, want)) in caches.iter().zip(&pinned) {
        let mut args: Vec<String> = cache.args.iter().map(|a| a.replace("{out}", out)).collect();
        args.extend(["-o".to_owned(), format!("{out}/{}", cache.name)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        succeeds_in(Some(root), &args);
        let got = sha256_hex(&dir.path().join(&cache.name));
        if &got != want {
            changed.push(format!(
                "{} (haarshift {}): pinned {want}, written {got}",
                cache.name,
                args.join(" ")
            ));
        }
    }
    assert!(
        changed.is_empty(),
        "{} of {} scene caches changed their bytes (if meant, regenerate \
         testdata/cache_hashes.sha256 with scripts/cache_hashes.sh and say why in \
         CHANGELOG.md):\n{}",
        changed.len(),
        caches.len(),
        changed.join("\n")
    );
}
