//! `haarshift experiment relight` checks its inputs and outputs before the work (the numbers
//! are the library's, tested in `experiments::relight`).

use crate::common::{fails_cleanly, p, succeeds_with_stdout, testdata, usage_error};

#[test]
fn it_refuses_stale_reports_and_bad_inputs_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reports");
    std::fs::create_dir_all(&out).unwrap();
    let stale = out.join("relight.csv");
    std::fs::write(&stale, "an earlier run\n").unwrap();
    let scene = testdata("scenes/bunny.json");
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let args = [
        "experiment",
        "relight",
        "--scene",
        p(&scene),
        "--env",
        p(&env),
    ];
    let mut stale_args = args.to_vec();
    stale_args.extend(["--out-dir", p(&out)]);
    fails_cleanly(&stale_args, &["relight.csv", "already exists", "--force"]);
    assert_eq!(std::fs::read_to_string(&stale).unwrap(), "an earlier run\n");
    let fresh = dir.path().join("fresh");
    let missing = dir.path().join("no such scene.json");
    fails_cleanly(
        &[
            "experiment",
            "relight",
            "--scene",
            p(&missing),
            "--env",
            p(&env),
            "--out-dir",
            p(&fresh),
        ],
        &["no such scene.json"],
    );
    let corrupt = dir.path().join("corrupt.hdr");
    std::fs::write(&corrupt, "#?RADIANCE\nnot a map").unwrap();
    fails_cleanly(
        &[
            "experiment",
            "relight",
            "--scene",
            p(&scene),
            "--env",
            p(&corrupt),
            "--out-dir",
            p(&fresh),
        ],
        &["corrupt.hdr"],
    );
    // Nothing was written: every refusal came before the work.
    assert!(!fresh.join("relight.csv").exists());
}

#[test]
fn its_help_states_the_protocols_and_the_axes() {
    let help = succeeds_with_stdout(&["experiment", "relight", "--help"]);
    for needle in [
        "Examples:",
        "--quick",
        "--full",
        "rotation",
        "coefficients",
        "resolution",
        "depth",
        "harmonics",
        "stand-ins",
        "512 x 1024",
    ] {
        assert!(help.contains(needle), "{needle}: {help}");
    }
}

#[test]
fn quick_is_the_default_and_cannot_be_asked_for_with_full() {
    for command in ["relight", "dynamic"] {
        usage_error(
            &["experiment", command, "--quick", "--full"],
            &["--quick", "--full"],
        );
    }
}
