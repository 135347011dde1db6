//! `relight precompute --refine TOL [--max-vertices N]`: what it cannot be combined with
//! refused in one line before any work, and a refined cache that renders, its ground the
//! trailing block it records.

use haarshift_relight::SceneCache;

use crate::common::{fails_cleanly, p, succeeds, succeeds_with_stdout, testdata, usage_error};

#[test]
fn refine_refuses_shards_the_direction_order_bad_tolerances_and_small_budgets_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.hsr");
    let bunny = testdata("meshes/bunny.ply");
    let head = [
        "relight",
        "precompute",
        p(&bunny),
        "--ground-plane",
        "-o",
        p(&out),
    ];
    let refused = [
        (&["--refine", "0.1", "--shard", "0/2"][..], "with --shard"),
        (
            &["--refine", "0.1", "--order", "direction"],
            "with --order direction",
        ),
        (
            &["--refine", "0.1", "--visibility-samples", "2"],
            "--visibility-samples",
        ),
        (&["--refine", "0"], "in (0, 2]"),
        (&["--refine", "3"], "in (0, 2]"),
        (
            &["--refine", "0.1", "--max-vertices", "100"],
            "100 vertices: the scene has 2928 already",
        ),
        (
            &["--refine", "0.1", "--refine-light", "missing.hdr"],
            "missing.hdr",
        ),
    ];
    for (flags, why) in refused {
        fails_cleanly(&[&head[..], flags].concat(), &[why]);
    }
    for flags in [&["--max-vertices", "5000"], &["--refine-light", "sky.hdr"]] {
        usage_error(&[&head[..], flags].concat(), &["--refine"]);
    }
    assert!(!out.exists());
}

#[test]
fn a_refined_cache_renders_and_reports_its_ground_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("ball.json");
    let json = r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}], "ground_plane": true, "ground_cells": 2}"#;
    std::fs::write(&scene, json).unwrap();
    let cache = dir.path().join("ball.hsr");
    let report = succeeds_with_stdout(&[
        "relight",
        "precompute",
        p(&scene),
        "--resolution",
        "8",
        "--ray-tracer",
        "packets",
        "--refine",
        "0.05",
        "--max-vertices",
        "80",
        "-o",
        p(&cache),
    ]);
    let read = SceneCache::read(&cache).unwrap();
    let line = format!(
        "refined 63 -> 80 vertices ({} of them the ground's) in",
        read.ground_vertices
    );
    assert!(report.contains(&line), "{report}");
    assert!(
        report.contains("stopped by --max-vertices 80 with"),
        "{report}"
    );
    assert!(
        report.contains(&format!("{}: 80 vertices", p(&cache))),
        "{report}"
    );
    assert_eq!(read.params.refine.unwrap().max_vertices, 80);
    let (image, npy) = (dir.path().join("ball.png"), dir.path().join("ball.npy"));
    let env = testdata("envmaps/rooitou_park_32x16.hdr");
    succeeds(&[
        "relight",
        "render",
        p(&cache),
        "--env",
        p(&env),
        "--brdf",
        "phong:30",
        "--width",
        "16",
        "--height",
        "12",
        "--vertices",
        p(&npy),
        "-o",
        p(&image),
    ]);
    let radiance: ndarray::Array2<f32> = ndarray_npy::read_npy(&npy).unwrap();
    assert_eq!(radiance.nrows(), 80);
}
