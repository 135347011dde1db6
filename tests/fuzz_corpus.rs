//! Replays every committed fuzz input (`fuzz/corpus/TARGET/*`, and `fuzz/artifacts/TARGET/*`
//! where a run found a crash) through the same harness as the libFuzzer targets, on the stable
//! toolchain, so that CI guards them; see `fuzz/README.md`.

#[path = "../fuzz/harness.rs"]
mod harness;

use std::path::Path;

#[test]
fn every_corpus_input_and_crash_replays_without_a_panic() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut total = 0;
    for target in harness::TARGETS {
        let mut seeds = 0;
        for kind in ["corpus", "artifacts"] {
            let Ok(entries) = std::fs::read_dir(fuzz.join(kind).join(target)) else {
                continue;
            };
            for entry in entries {
                let path = entry.unwrap().path();
                let bytes = std::fs::read(&path).unwrap();
                let replay = std::panic::catch_unwind(|| harness::run(target, &bytes));
                assert!(replay.is_ok(), "{target}: {} panics", path.display());
                seeds += usize::from(kind == "corpus");
                total += 1;
            }
        }
        assert!(seeds > 0, "{target} has no seed corpus");
    }
    assert!(total >= harness::TARGETS.len());
}
