//! What every fuzz target of the core's readers runs on one input, shared by the libFuzzer
//! targets (`fuzz_targets/`) and the stable replay test (`tests/fuzz_corpus.rs` in the core
//! crate), so that CI guards every corpus file and every crash without a nightly toolchain. The
//! relighting's readers have theirs in `relight/fuzz/`.
//!
//! Each reader takes a path, so the input is written to a file of the target's extension in
//! a directory of its own and read back; any `Result` is fine, a panic is the finding.
// Each fuzz target uses only `run`.
#![allow(dead_code)]

use haarshift_testkit::fuzz::{put, scratch};

use haarshift::io::{CoefficientFile, read_image};

/// The fuzz targets: one per reader.
pub const TARGETS: [&str; 7] = ["png", "jpeg", "tiff", "exr", "hdr", "npy", "coefficients"];

/// Runs `target` on `bytes`: panics only if the code under test does.
pub fn run(target: &str, bytes: &[u8]) {
    let dir = scratch();
    match target {
        "png" | "jpeg" | "tiff" | "exr" | "hdr" | "npy" => {
            let ext = match target {
                "jpeg" => "jpg",
                "tiff" => "tif",
                other => other,
            };
            let _ = read_image::<f32>(put(&dir, &format!("in.{ext}"), bytes));
        }
        "coefficients" => {
            // A valid 2 x 2 coefficient array; the input is its sidecar.
            let array = dir.join("c.npy");
            let coefficients = ndarray::array![[4.0f64, -1.0], [-2.0, 0.0]];
            ndarray_npy::write_npy(&array, &coefficients).unwrap();
            put(&dir, "c.npy.json", bytes);
            let _ = CoefficientFile::read(&array);
        }
        other => panic!("no fuzz target {other}"),
    }
    let _ = std::fs::remove_dir_all(dir);
}
