//! Replays every committed fuzz input (`fuzz/corpus/TARGET/*`, and `fuzz/artifacts/TARGET/*`
//! where a run found a crash) through the same harness as the libFuzzer targets, on the stable
//! toolchain, so that CI guards them; see `fuzz/README.md`.

#[path = "../fuzz/harness.rs"]
mod harness;

use std::path::{Path, PathBuf};

use rayon::prelude::*;

#[test]
fn every_corpus_input_and_crash_replays_without_a_panic() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut inputs: Vec<(&str, PathBuf)> = Vec::new();
    for target in harness::TARGETS {
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
    assert!(inputs.len() >= harness::TARGETS.len());
    // Some 15,000 inputs of milliseconds each: replayed on every core.
    let panics: Vec<String> = inputs
        .par_iter()
        .filter_map(|(target, path)| {
            let bytes = std::fs::read(path).unwrap();
            std::panic::catch_unwind(|| harness::run(target, &bytes))
                .is_err()
                .then(|| format!("{target}: {}", path.display()))
        })
        .collect();
    assert!(panics.is_empty(), "these inputs panic: {panics:?}");
}
