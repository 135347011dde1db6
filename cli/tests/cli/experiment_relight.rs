//! `haarshift experiment relight` checks its inputs and outputs before the work (the numbers
//! are the library's, tested in `experiments::relight`).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::strs;
use crate::common::{
    fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, text, usage_error,
};

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

/// The records of `dir/relight.csv` without the columns that depend on the machine.
fn measured_records(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("relight.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let machine = ["precompute_seconds", "relight_seconds", "peak_mib"];
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !machine.contains(&header[i]))
        .collect();
    assert_eq!(keep.len() + machine.len(), header.len(), "{header:?}");
    lines
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            keep.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",")
        })
        .collect()
}

#[test]
fn a_killed_or_sharded_run_resumes_to_the_records_of_an_uninterrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("ball.json");
    std::fs::write(
        &scene,
        r#"{"objects": [{"generator": {"sphere": {"cells": 4}}}],
            "camera": {"position": [0, 1, 4], "look_at": [0, 0, 0], "fov": 40}}"#,
    )
    .unwrap();
    let env = testdata("envmaps/rooitou_park_1k.hdr");
    let args = |out: &Path| -> Vec<String> {
        [
            "experiment",
            "relight",
            "--scene",
            p(&scene),
            "--env",
            p(&env),
            "--out-dir",
            p(out),
        ]
        .map(String::from)
        .to_vec()
    };
    let whole = dir.path().join("whole");
    succeeds(&strs(&args(&whole)));
    let stopped = dir.path().join("stopped");
    let mut child = Command::new(env!("CARGO_BIN_EXE_haarshift"))
        .args(args(&stopped))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Killed once the journal holds the truth, the rotation axis and the coefficient axis.
    let journal = stopped.join("relight.journal");
    while std::fs::read_to_string(&journal).map_or(0, |t| t.lines().count()) < 4 {
        assert!(child.try_wait().unwrap().is_none(), "ended before the kill");
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!stopped.join("relight.csv").exists());
    fails_cleanly(
        &strs(&args(&stopped)),
        &["relight.journal", "stopped run", "--resume", "--force"],
    );
    let mut resume = args(&stopped);
    resume.push("--resume".into());
    let out = succeeds(&strs(&resume));
    let said = text(&out.stderr);
    assert!(said.contains("resumed: "), "{said}");
    assert_eq!(measured_records(&stopped), measured_records(&whole));
    assert!(!journal.exists());
    // Three shards as separate processes into one directory, then --resume merges them: the
    // same records, measured by nobody twice, and no journal left behind.
    let sharded = dir.path().join("sharded");
    let mut records = 0;
    for i in 0..3 {
        let mut shard = args(&sharded);
        shard.extend(["--shard".into(), format!("{i}/3")]);
        let said = succeeds_with_stdout(&strs(&shard));
        assert!(said.contains(&format!("shard {i}/3: ")), "{said}");
        assert!(
            sharded
                .join(format!("relight.journal.shard-{i}-of-3"))
                .exists()
        );
        records += said
            .split(&format!("shard {i}/3: "))
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse::<usize>()
            .unwrap();
    }
    assert!(!sharded.join("relight.csv").exists());
    let mut merge = args(&sharded);
    merge.push("--resume".into());
    let out = succeeds(&strs(&merge));
    assert_eq!(measured_records(&sharded), measured_records(&whole));
    assert_eq!(
        records,
        measured_records(&whole).len(),
        "each record measured once"
    );
    let left: Vec<_> = std::fs::read_dir(&sharded)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("journal"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    assert!(text(&out.stderr).contains("resumed: "));
    // Another protocol cannot go on with a journal.
    let copy = dir.path().join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    std::fs::write(
        copy.join("relight.journal"),
        r#"{"journal":"haarshift journal 1","options":"another run"}"#.to_owned() + "\n",
    )
    .unwrap();
    let mut other = args(&copy);
    other.push("--resume".into());
    fails_cleanly(
        &strs(&other),
        &["relight.journal", "other options or inputs"],
    );
}
