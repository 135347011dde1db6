//! Replays every committed fuzz input of the relighting's readers (`relight/fuzz/corpus/TARGET/*`, and
//! `relight/fuzz/artifacts/TARGET/*` where a run found a crash) through the same harness as the
//! libFuzzer targets, on the stable toolchain, so that CI guards them; see `fuzz/README.md` at the top.

#[path = "../fuzz/harness.rs"]
mod harness;

#[test]
fn every_corpus_input_and_crash_replays_without_a_panic() {
    let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    haarshift_testkit::fuzz::replay(&fuzz, &harness::TARGETS, harness::run);
}
