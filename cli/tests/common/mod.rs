//! Helpers shared by the CLI integration tests: running the built binary and naming files.
// Each test crate compiles this module and uses only some of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A file in the repository's `testdata/`.
pub fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../testdata")
        .join(name)
}

/// Runs the `haarshift` binary with `args`, in `dir` when given.
pub fn run_in(dir: Option<&Path>, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_haarshift"));
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    command.args(args).output().expect("the binary runs")
}

/// Runs the `haarshift` binary with `args`.
pub fn haarshift(args: &[&str]) -> Output {
    run_in(None, args)
}

/// Output bytes as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A path as a command-line argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}
