//! Replays every committed fuzz input of the core's readers (`fuzz/corpus/TARGET/*`, and
//! `fuzz/artifacts/TARGET/*` where a run found a crash) through the same harness as the
//! libFuzzer targets, on the stable toolchain, so that CI guards them; see `fuzz/README.md`.

#[path = "../fuzz/harness.rs"]
mod harness;

#[test]
fn every_corpus_input_and_crash_replays_without_a_panic() {
    let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    haarshift_testkit::fuzz::replay(&fuzz, &harness::TARGETS, harness::run);
}
