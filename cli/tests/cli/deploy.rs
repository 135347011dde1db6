//! `deploy/k8s/precompute-job.yaml` as Kubernetes would run it, with no cluster: its Indexed
//! Job's command and arguments, with `$(JOB_COMPLETION_INDEX)` expanded for every completion
//! index, parsed and run by the CLI itself, then its merge Job's shell commands, on a small
//! scene in place of the `/data` volume; the merged cache must be the unsharded one, byte for
//! byte.

use std::path::Path;

use serde_norway::Value;

use crate::common::{p, run_scheduled, succeeds, text};

/// The value at `path` (mapping keys) under `v`.
fn at<'a>(v: &'a Value, path: &[&str]) -> &'a Value {
    path.iter().fold(v, |v, key| &v[*key])
}

/// A sequence of strings.
fn strings(v: &Value) -> Vec<String> {
    v.as_sequence()
        .unwrap_or_else(|| panic!("not a sequence: {v:?}"))
        .iter()
        .map(|s| s.as_str().expect("a string").to_owned())
        .collect()
}

/// Every container and init container of a Job's pod template.
fn containers(job: &Value) -> Vec<&Value> {
    let pod = at(job, &["spec", "template", "spec"]);
    ["initContainers", "containers"]
        .iter()
        .filter_map(|k| pod[*k].as_sequence())
        .flatten()
        .collect()
}

/// Runs `sh -c script` with the built `haarshift` first on PATH.
fn shell(script: &str) {
    let bin = Path::new(env!("CARGO_BIN_EXE_haarshift")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = std::process::Command::new("sh")
        .args(["-c", script])
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(out.status.success(), "{script}: {}", text(&out.stderr));
}

#[test]
fn the_indexed_job_and_its_merge_give_the_unsharded_cache() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path();
    std::fs::write(
        data.join("scene.json"),
        r#"{"objects": [{"generator": {"sphere": {"cells": 3}}}], "ground_plane": true}"#,
    )
    .unwrap();
    let manifest = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/k8s/precompute-job.yaml"),
    )
    .unwrap()
    .replace("/data", p(data));
    let jobs: Vec<Value> = serde_norway::Deserializer::from_str(&manifest)
        .map(|doc| serde::Deserialize::deserialize(doc).unwrap())
        .collect();
    assert_eq!(jobs.len(), 2);
    for job in &jobs {
        assert_eq!(job["kind"].as_str(), Some("Job"));
        for container in containers(job) {
            // The image is a parameter, filled in by envsubst.
            assert_eq!(container["image"].as_str(), Some("${IMAGE}"));
        }
    }
    let (indexed, merge) = (&jobs[0], &jobs[1]);
    assert_eq!(
        at(indexed, &["spec", "completionMode"]).as_str(),
        Some("Indexed")
    );
    let completions = at(indexed, &["spec", "completions"]).as_u64().unwrap() as usize;
    assert_eq!(completions, 8);
    let [shard] = &containers(indexed)[..] else {
        panic!("one container")
    };
    let mut argv = strings(&shard["command"]);
    argv.extend(strings(&shard["args"]));
    assert_eq!(argv[..3], ["haarshift", "relight", "precompute"]);
    let flag = |name: &str| {
        argv.iter()
            .position(|a| a == name)
            .map(|i| argv[i + 1].as_str())
    };
    assert_eq!(flag("--shard"), Some("auto"));
    assert_eq!(flag("--shards"), Some(completions.to_string().as_str()));
    for index in 0..completions {
        // Kubernetes expands $(VAR) in arguments from the container's environment.
        let i = index.to_string();
        let args: Vec<String> = argv[1..]
            .iter()
            .map(|a| a.replace("$(JOB_COMPLETION_INDEX)", &i))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_scheduled(&[("JOB_COMPLETION_INDEX", &i)], &args);
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
        assert!(text(&out.stdout).contains(&format!("(shard {index}/{completions}: ")));
    }

    // The merge Job: wait for the shards (they are all there), then merge.
    let scripts: Vec<String> = containers(merge)
        .iter()
        .map(|c| {
            let command = strings(&c["command"]);
            assert_eq!(command[..2], ["sh", "-c"]);
            command[2].clone()
        })
        .collect();
    assert_eq!(scripts.len(), 2);
    scripts.iter().for_each(|s| shell(s));

    // The same options unsharded.
    let mut whole: Vec<&str> = vec![];
    let mut skip = false;
    for a in &argv[1..] {
        if skip {
            skip = false;
        } else if ["--shard", "--shards", "-o"].contains(&a.as_str()) {
            skip = true;
        } else {
            whole.push(a);
        }
    }
    let unsharded = data.join("unsharded.hsr");
    whole.extend(["-o", p(&unsharded)]);
    succeeds(&whole);
    assert!(std::fs::read(data.join("scene.hsr")).unwrap() == std::fs::read(&unsharded).unwrap());
}
