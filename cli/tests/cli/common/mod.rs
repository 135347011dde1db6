//! Helpers shared by the CLI integration tests: running the built binary, requiring success or
//! a clean failure, and naming files.

pub mod maps;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A file in the repository's `testdata/`.
pub fn testdata(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../testdata")
        .join(name)
}

/// The repository's root.
pub fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Runs the example program `name` (built by `cargo test` beside the binaries) with `args`
/// from the repository's root and requires success; returns its standard output.
pub fn run_example<S: AsRef<std::ffi::OsStr>>(name: &str, args: &[S]) -> String {
    let program = Path::new(env!("CARGO_BIN_EXE_haarshift"))
        .parent()
        .unwrap()
        .join("examples")
        .join(name);
    assert!(program.exists(), "{}: not built", program.display());
    let out = Command::new(&program)
        .args(args)
        .current_dir(repository())
        .output()
        .expect("the example runs");
    assert!(
        out.status.success(),
        "example {name}: {}",
        text(&out.stderr)
    );
    text(&out.stdout)
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

/// Runs `haarshift ARGS` in `dir` (when given) and requires success; returns the output.
pub fn succeeds_in(dir: Option<&Path>, args: &[&str]) -> Output {
    let out = run_in(dir, args);
    assert!(
        out.status.success(),
        "{args:?} failed ({:?}): {}",
        out.status.code(),
        text(&out.stderr)
    );
    out
}

/// Runs `haarshift ARGS` and requires success; returns the output.
pub fn succeeds(args: &[&str]) -> Output {
    succeeds_in(None, args)
}

/// Runs `haarshift ARGS`, requires success and returns standard output as text.
pub fn succeeds_with_stdout(args: &[&str]) -> String {
    text(&succeeds(args).stdout)
}

/// Runs `haarshift ARGS` in `dir` (when given) and requires a clean failure of the program
/// (exit code 1): exactly one line on stderr, `haarshift: ...`, containing every needle (the
/// file or flag at fault and the problem), no panic, nothing on stdout. Returns the line.
pub fn fails_cleanly_in(dir: Option<&Path>, args: &[&str], needles: &[&str]) -> String {
    failure(run_in(dir, args), args, 1, "haarshift: ", needles)
}

/// [`fails_cleanly_in`] in the current directory.
pub fn fails_cleanly(args: &[&str], needles: &[&str]) -> String {
    fails_cleanly_in(None, args, needles)
}

/// Runs `haarshift ARGS` and requires a usage error from the argument parser (exit code 2):
/// its `error: ...` message first on stderr, containing every needle (the argument at fault),
/// no panic, nothing on stdout. Returns the message (clap lists missing arguments on the lines
/// after `error:`).
pub fn usage_error_in(dir: Option<&Path>, args: &[&str], needles: &[&str]) -> String {
    failure(run_in(dir, args), args, 2, "error: ", needles)
}

/// [`fails_cleanly`] of a command that serves when it does not fail (`relight view`): killed,
/// and the test failed, when it still runs after `limit`.
pub fn fails_cleanly_within(limit: Duration, args: &[&str], needles: &[&str]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_haarshift"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    while child
        .try_wait()
        .expect("the binary is waited for")
        .is_none()
    {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still runs after {limit:?}: it should have failed");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child
        .wait_with_output()
        .expect("the binary's output is read");
    failure(out, args, 1, "haarshift: ", needles)
}

/// [`usage_error_in`] in the current directory.
pub fn usage_error(args: &[&str], needles: &[&str]) -> String {
    usage_error_in(None, args, needles)
}

/// The variables a scheduler sets that `--shard auto` reads.
const SCHEDULER_VARIABLES: [&str; 6] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_STEP",
    "SLURM_ARRAY_TASK_COUNT",
    "JOB_COMPLETION_INDEX",
];

/// Runs `haarshift ARGS` as a scheduler's task with the variables `vars` and no other of
/// [`SCHEDULER_VARIABLES`] (whatever the test itself runs under).
pub fn run_scheduled(vars: &[(&str, &str)], args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_haarshift"));
    for name in SCHEDULER_VARIABLES {
        command.env_remove(name);
    }
    command
        .envs(vars.iter().copied())
        .args(args)
        .output()
        .expect("the binary runs")
}

/// [`fails_cleanly`] for [`run_scheduled`].
pub fn fails_cleanly_scheduled(vars: &[(&str, &str)], args: &[&str], needles: &[&str]) -> String {
    failure(run_scheduled(vars, args), args, 1, "haarshift: ", needles)
}

/// The checks behind [`fails_cleanly_in`] and [`usage_error_in`] of the run of `args` that
/// gave `out`: exit `code` (a panic exits with 101), no panic text, the error first on stderr
/// starting with `prefix` and holding every needle; exactly one line in all for the program's
/// own errors (code 1).
fn failure(out: Output, args: &[&str], code: i32, prefix: &str, needles: &[&str]) -> String {
    assert!(
        !needles.is_empty() && needles.iter().all(|n| !n.trim().is_empty()),
        "an empty needle checks nothing: {needles:?}"
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    for bad in ["panicked", "internal error", "RUST_BACKTRACE"] {
        assert!(!err.contains(bad), "{args:?} panicked: {err}");
    }
    assert!(
        out.stdout.is_empty(),
        "{args:?} wrote to stdout: {}",
        text(&out.stdout)
    );
    let message = if code == 1 {
        assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err:?}");
        err.trim_end().to_owned()
    } else {
        // clap: the message, then a blank line and the usage or the hint about --help.
        err.split("\n\n").next().unwrap_or_default().to_owned()
    };
    assert!(
        message.starts_with(prefix),
        "{args:?}: {message:?} is not `{prefix}...`"
    );
    for needle in needles {
        assert!(
            message.contains(needle),
            "{args:?}: {message:?} lacks {needle:?}"
        );
    }
    message
}

/// Output bytes as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A path as a command-line argument.
pub fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// The `(V, 3)` f32 array of a `.npy` file (radiance per vertex, or a frame).
pub fn read_vertices(path: &Path) -> ndarray::Array2<f32> {
    ndarray_npy::read_npy(path).unwrap()
}

/// The relative RMS difference of two `(V, 3)` arrays over all vertices and channels: the
/// library's [`haarshift::metrics::relative_rms_error`].
pub fn relative_rms(a: &ndarray::Array2<f32>, b: &ndarray::Array2<f32>) -> f64 {
    haarshift::metrics::relative_rms_error(a.view(), b.view()).unwrap()
}

/// The arguments as the `&str`s the runners take.
pub fn strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

/// `haarshift COMMAND INPUT -o OUT FLAGS...`, required to succeed; returns the output read back.
pub fn run(command: &str, input: &Path, out: &Path, flags: &[&str]) -> haarshift::PlanarImage<f64> {
    let mut args = vec![command, p(input), "-o", p(out)];
    args.extend_from_slice(flags);
    succeeds(&args);
    haarshift::io::read_image::<f64>(out).unwrap()
}
