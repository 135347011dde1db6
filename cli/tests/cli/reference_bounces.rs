//! `haarshift relight reference --bounces B` and `--path-trace N` end to end on a small open
//! box: bounces add light, paths repeat bit for bit, and bad requests fail in one line.

use std::path::{Path, PathBuf};

use crate::common::read_vertices;
use crate::common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata};

/// A scene file in `dir`: an open box, 2 x 2 cells a face (45 vertices).
fn open_box(dir: &Path) -> PathBuf {
    let path = dir.join("box.json");
    std::fs::write(
        &path,
        r#"{"objects": [{"generator": {"box": {"cells": 2}}}]}"#,
    )
    .unwrap();
    path
}

#[test]
fn bounces_light_the_box_and_paths_repeat_with_their_standard_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = open_box(dir.path());
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    let base = [
        "relight",
        "reference",
        p(&scene),
        "--env",
        p(&env),
        "--resolution",
        "8",
    ];
    let out = |name: &str| dir.path().join(name);
    let (direct, bounced) = (out("direct.npy"), out("bounced.npy"));
    let mut args = base.to_vec();
    args.extend(["--vertices", p(&direct)]);
    succeeds(&args);
    let mut args = base.to_vec();
    args.extend(["--bounces", "2", "--vertices", p(&bounced)]);
    let stdout = succeeds_with_stdout(&args);
    assert!(stdout.contains("2 bounces"), "{stdout}");
    let (direct, bounced) = (read_vertices(&direct), read_vertices(&bounced));
    assert_eq!(direct.dim(), (45, 3));
    // Every inside vertex sees another face's light: none darker, the floor's centre brighter.
    assert!(direct.iter().zip(&bounced).all(|(d, b)| b >= d));
    assert!(
        bounced[[4, 0]] > 1.05 * direct[[4, 0]],
        "{} {}",
        bounced[[4, 0]],
        direct[[4, 0]]
    );
    let (a, b, se) = (out("a.npy"), out("b.npy"), out("se.npy"));
    for v in [&a, &b] {
        let mut args = base.to_vec();
        args.extend(["--bounces", "1", "--path-trace", "16", "--seed", "4"]);
        args.extend(["--stderr", p(&se), "--force", "--vertices", p(v)]);
        let stdout = succeeds_with_stdout(&args);
        assert!(stdout.contains("RMS standard error"), "{stdout}");
    }
    assert_eq!(read_vertices(&a), read_vertices(&b));
    assert!(read_vertices(&se).iter().any(|&x| x > 0.0));
    let fresh = out("fresh.npy");
    for (flags, needles) in [
        (&["--bounces", "9"][..], &["bounces", "0 to 8"][..]),
        (
            &["--bounces", "1", "--brdf", "phong:10"],
            &["phong", "Lambertian"],
        ),
        (&["--path-trace", "1"], &["paths", "2 to"]),
    ] {
        let mut args = base.to_vec();
        args.extend(["--vertices", p(&fresh)]);
        args.extend(flags);
        fails_cleanly(&args, needles);
        assert!(!fresh.exists());
    }
}
