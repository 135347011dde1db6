//! `haarshift experiment`: the command's figures against a computation made directly here.

use std::path::Path;

use crate::common::{fails_cleanly, haarshift, succeeds, text, usage_error};

use haarshift::io::{WriteOptions, write_image};
use haarshift::kernels::ShiftMethod;
use haarshift::rotate::{RotateOptions, rotate_plane};
use haarshift::{PlanarImage, SampleDepth};
use ndarray::{Array2, s};
use serde_json::Value;

/// Runs the binary and requires success; returns its standard output.
fn haarshift_ok(args: &[&str]) -> String {
    text(&succeeds(args).stdout)
}

/// A 40x24 gray test image with integer values (exactly representable in 8 bits).
fn small_image() -> Array2<f64> {
    Array2::from_shape_fn((24, 40), |(i, j)| ((i * 7 + j * 13) % 256) as f64)
}

fn write_small_image(path: &Path) {
    let img = PlanarImage::from_gray(small_image().mapv(|v| v as f32), SampleDepth::U8).unwrap();
    write_image(&img, path, WriteOptions::default()).unwrap();
}

fn run_json(dir: &Path, extra: &[&str]) -> Vec<Value> {
    let image = dir.join("small.png");
    if !image.exists() {
        write_small_image(&image);
    }
    let json = dir.join("out.json");
    let out_dir = dir.join("results");
    let mut args = vec![
        "experiment",
        "rotation-cycle",
        image.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        "--force",
    ];
    args.extend_from_slice(extra);
    let stdout = haarshift_ok(&args);
    assert!(stdout.contains("protocol: luma"), "{stdout}");
    assert!(out_dir.join("rotation-cycle.csv").exists());
    serde_json::from_str::<Value>(&std::fs::read_to_string(json).unwrap())
        .unwrap()
        .as_array()
        .unwrap()
        .clone()
}

#[test]
fn rotation_cycle_figure_matches_an_independent_computation() {
    let dir = tempfile::tempdir().unwrap();
    let records = run_json(dir.path(), &["--methods", "keys", "--steps", "6"]);
    assert_eq!(records.len(), 1);
    let r = &records[0];
    assert_eq!(r["image"], "small.png");
    assert_eq!(r["method"], "keys");
    for field in [
        "precision",
        "retain",
        "supersample",
        "psnr",
        "seconds",
        "peak_bytes",
    ] {
        assert!(r.get(field).is_some(), "missing {field}");
    }
    // The protocol by hand, from its definition with no experiment, chain or metrics code:
    // gray is its own luma; crop 24x24 from column 8; pad by 12; six single rotations by 60
    // degrees; RMS and largest error over the pixels whose centres lie within 24/2 - 2 = 10
    // of the canvas centre (23.5, 23.5).
    let plane = small_image();
    let mut canvas = Array2::zeros((48, 48));
    canvas
        .slice_mut(s![12..36, 12..36])
        .assign(&plane.slice(s![.., 8..32]));
    let kernel = ShiftMethod::Keys.kernel::<f64>();
    let mut result = canvas.clone();
    for _ in 0..6 {
        result = rotate_plane(
            result.view(),
            60.0,
            kernel.as_ref(),
            &RotateOptions::default(),
        )
        .unwrap();
    }
    let (mut sum_sq, mut max_error, mut count) = (0.0f64, 0.0f64, 0usize);
    for ((i, j), &want) in canvas.indexed_iter() {
        let (di, dj) = (i as f64 - 23.5, j as f64 - 23.5);
        if di * di + dj * dj <= 10.0 * 10.0 {
            let d = (result[[i, j]] - want).abs();
            sum_sq += d * d;
            max_error = max_error.max(d);
            count += 1;
        }
    }
    let rms = (sum_sq / count as f64).sqrt();
    assert!(count > 250 && rms > 1.0, "a real error to compare: {rms}");
    // Measured 0 for both; the bound leaves room for another summation order only.
    assert!((r["rms"].as_f64().unwrap() - rms).abs() < 1e-12 * rms);
    assert!((r["max_error"].as_f64().unwrap() - max_error).abs() < 1e-12 * max_error);
    assert!(r["peak_bytes"].as_u64().unwrap() > 0);
}

#[test]
fn nearest_quarter_turns_are_exact_and_haar_runs_in_both_modes() {
    let dir = tempfile::tempdir().unwrap();
    let records = run_json(dir.path(), &["--methods", "nearest,haar", "--steps", "4"]);
    let labels: Vec<_> = records
        .iter()
        .map(|r| {
            (
                r["method"].as_str().unwrap().to_owned(),
                r["retain"].clone(),
            )
        })
        .collect();
    assert_eq!(labels[0], ("nearest".into(), Value::Null));
    assert_eq!(labels[1], ("haar".into(), Value::Bool(false)));
    assert_eq!(labels[2], ("haar".into(), Value::Bool(true)));
    assert_eq!(records[2]["precision"], 1);
    // Multiples of 90 degrees are exact for every method.
    for r in &records {
        assert_eq!(r["rms"], 0.0, "{r}");
        assert_eq!(r["psnr"], Value::Null);
    }
}

#[test]
fn shift_chain_with_integer_steps_is_exact_for_haar() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("small.png");
    write_small_image(&image);
    let json = dir.path().join("chain.json");
    haarshift_ok(&[
        "experiment",
        "shift-chain",
        image.to_str().unwrap(),
        "--methods",
        "haar",
        "--dx",
        "8",
        "--dy",
        "-4",
        "--steps",
        "4",
        "--json",
        json.to_str().unwrap(),
        "--out-dir",
        dir.path().join("r").to_str().unwrap(),
    ]);
    let records: Vec<Value> =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert_eq!(records.len(), 2);
    for r in &records {
        assert_eq!(
            (r["rms"].as_f64(), r["size"].as_u64()),
            (Some(0.0), Some(16)),
            "{r}"
        );
    }
}

#[test]
fn stability_passes_every_check_and_writes_its_reports() {
    let dir = tempfile::tempdir().unwrap();
    let camera = Path::new(env!("CARGO_MANIFEST_DIR")).join("../testdata/camera.png");
    let json = dir.path().join("records.json");
    let out = haarshift(&[
        "experiment",
        "stability",
        "--quick",
        "--image",
        camera.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--out-dir",
        dir.path().to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let records: Vec<Value> =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(records.len() > 100, "{}", records.len());
    assert!(stdout.contains(&format!("{n} of {n} checks passed", n = records.len())));
    for r in &records {
        for field in ["category", "check", "figure", "tolerance", "pass", "detail"] {
            assert!(r.get(field).is_some(), "{field} missing in {r}");
        }
        assert_eq!(r["pass"], true, "{r}");
    }
    let find = |check: &str| records.iter().find(|r| r["check"] == check).unwrap();
    let chain = find("whole shifts, 8-bit, average");
    assert_eq!(chain["figure"], 0.0);
    assert_eq!(chain["shifts"], 1000);
    assert_eq!(find("NaN angle")["figure"], Value::Null);
    // The CLI meters allocation: the refusals allocated (almost) nothing.
    let refused = find("largest square within 4 GiB");
    assert!(refused["figure"].as_f64().unwrap() < 1e6, "{refused}");
    for file in ["stability.csv", "stability.json", "stability-drift.png"] {
        assert!(dir.path().join(file).exists(), "{file}");
    }
}

#[test]
fn stability_refuses_a_small_photograph() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("small.png");
    write_small_image(&image);
    fails_cleanly(
        &[
            "experiment",
            "stability",
            "--image",
            image.to_str().unwrap(),
            "--out-dir",
            dir.path().to_str().unwrap(),
        ],
        &["small.png", "at least 128x128"],
    );
}

/// `q` dominates `p` on (cost, error): no worse in both, better in one.
fn dominates(q: (f64, f64), p: (f64, f64)) -> bool {
    q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1)
}

#[test]
fn tradeoff_sweeps_every_parameter_and_flags_the_frontiers() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("small.png");
    write_small_image(&image);
    let json = dir.path().join("runs.json");
    let out_dir = dir.path().join("r");
    let stdout = haarshift_ok(&[
        "experiment",
        "tradeoff",
        image.to_str().unwrap(),
        "--methods",
        "linear,fft,haar",
        "--max-precision",
        "1",
        "--max-retained-precision",
        "1",
        "--max-supersample",
        "1",
        "--steps",
        "6",
        "--json",
        json.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
    ]);
    assert!(stdout.contains("9 configurations, 1 images"), "{stdout}");
    assert!(stdout.contains("small.png (24)"), "{stdout}");

    // Per image and configuration: the issue's fields, parameters in their own fields.
    let runs: Vec<Value> = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let configs: Vec<(String, Value, Value, u64)> = runs
        .iter()
        .map(|r| {
            for field in [
                "image",
                "rms",
                "psnr",
                "max_error",
                "seconds",
                "peak_bytes",
                "time_frontier",
                "memory_frontier",
            ] {
                assert!(r.get(field).is_some(), "missing {field} in {r}");
            }
            assert_eq!(r["image"], "small.png");
            assert_eq!(r["crop"], 24);
            (
                r["method"].as_str().unwrap().to_owned(),
                r["precision"].clone(),
                r["retain"].clone(),
                r["supersample"].as_u64().unwrap(),
            )
        })
        .collect();
    let (n, t, f) = (Value::Null, Value::Bool(true), Value::Bool(false));
    let h = |v: u32| Value::from(v);
    let want = vec![
        ("linear".into(), n.clone(), n.clone(), 0),
        ("linear".into(), n.clone(), n.clone(), 1),
        ("fft".into(), n.clone(), n.clone(), 0),
        ("fft".into(), n.clone(), n.clone(), 1),
        ("haar".into(), h(0), f.clone(), 0),
        ("haar".into(), h(0), f.clone(), 1),
        ("haar".into(), h(1), f.clone(), 0),
        ("haar".into(), h(1), f.clone(), 1),
        ("haar".into(), h(1), t.clone(), 0),
    ];
    assert_eq!(configs, want);

    // The summary: one image, so its figures are the run's; flags by brute force.
    let summary: Vec<Value> =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("tradeoff.json")).unwrap())
            .unwrap();
    assert_eq!(summary.len(), runs.len());
    let figure = |v: &Value, key: &str| v[key].as_f64().unwrap();
    let by_time: Vec<(f64, f64)> = summary
        .iter()
        .map(|p| (figure(p, "total_seconds"), figure(p, "mean_rms")))
        .collect();
    let by_memory: Vec<(f64, f64)> = summary
        .iter()
        .map(|p| (figure(p, "peak_bytes"), figure(p, "mean_rms")))
        .collect();
    for (i, (p, r)) in summary.iter().zip(&runs).enumerate() {
        assert_eq!(p["images"], 1);
        assert_eq!(figure(p, "mean_rms"), figure(r, "rms"));
        assert_eq!(figure(p, "total_seconds"), figure(r, "seconds"));
        assert_eq!(p["peak_bytes"], r["peak_bytes"]);
        for (flag, points) in [("time_frontier", &by_time), ("memory_frontier", &by_memory)] {
            let undominated = !points.iter().any(|&q| dominates(q, points[i]));
            let first = points[..i].iter().all(|&q| q != points[i]);
            assert_eq!(p[flag], Value::Bool(undominated && first), "{flag} {p}");
            assert_eq!(p[flag], r[flag], "{flag}: the run carries its point's flag");
        }
    }
    assert!(by_time.iter().all(|&(s, rms)| s > 0.0 && rms > 0.0));
    // The most accurate configuration is on both frontiers.
    let best = (0..summary.len())
        .min_by(|&a, &b| by_time[a].1.total_cmp(&by_time[b].1))
        .unwrap();
    assert_eq!(
        (
            &summary[best]["time_frontier"],
            &summary[best]["memory_frontier"]
        ),
        (&t, &t)
    );

    for file in [
        "tradeoff.csv",
        "tradeoff-runs.csv",
        "tradeoff-runs.json",
        "tradeoff-rms-time.png",
        "tradeoff-rms-memory.png",
    ] {
        let bytes = std::fs::read(out_dir.join(file)).unwrap();
        assert!(bytes.len() > 100, "{file}");
        if file.ends_with(".png") {
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{file}");
        }
    }
    let csv = std::fs::read_to_string(out_dir.join("tradeoff.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + summary.len());
}

#[test]
fn tradeoff_refuses_an_empty_grid_and_a_bad_size() {
    fails_cleanly(
        &[
            "experiment",
            "tradeoff",
            "--methods",
            "haar-retained",
            "--max-retained-precision",
            "0",
        ],
        &["methods", "--max-retained-precision 0"],
    );
    for size in ["2", "big"] {
        usage_error(
            &["experiment", "tradeoff", "--size", size],
            &["--size", size],
        );
    }
}
