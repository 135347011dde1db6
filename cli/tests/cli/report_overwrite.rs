//! Every experiment refuses to overwrite a report of an earlier run in `--out-dir` without
//! `--force` (exit code 1, one line naming the file, the file untouched) and replaces it with
//! `--force`.

use std::path::Path;

use crate::common::{fails_cleanly, p, succeeds, testdata};

use haarshift::io::{WriteOptions, write_image};
use haarshift::{PlanarImage, SampleDepth};
use ndarray::Array2;

/// What a stale report holds before the run.
const STALE: &str = "a report of an earlier run\n";

/// Runs `args` (an experiment writing `<out>/<stem>.csv`) with a stale `<stem>.csv` in `out`:
/// refused without `--force`, the stale file kept; replaced by a CSV with `--force`.
fn refuses_then_replaces(args: &[&str], out: &Path, stem: &str) {
    std::fs::create_dir_all(out).unwrap();
    let csv = out.join(format!("{stem}.csv"));
    std::fs::write(&csv, STALE).unwrap();
    let name = format!("{stem}.csv");
    fails_cleanly(args, &[&name, "already exists", "--force"]);
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), STALE, "{stem}");
    let mut forced = args.to_vec();
    forced.push("--force");
    succeeds(&forced);
    let written = std::fs::read_to_string(&csv).unwrap();
    assert_ne!(written, STALE, "{stem}: not replaced");
    assert!(written.lines().count() > 1, "{stem}: {written}");
}

#[test]
fn every_experiment_refuses_without_force_and_replaces_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("small.png");
    let plane = Array2::from_shape_fn((24, 40), |(i, j)| ((i * 7 + j * 13) % 256) as f32);
    let gray = PlanarImage::from_gray(plane, SampleDepth::U8).unwrap();
    write_image(&gray, &image, WriteOptions::default()).unwrap();
    let image = p(&image);
    let out = dir.path().join("reports");
    let o = p(&out);
    let camera = testdata("camera.png");
    let map = testdata("envmaps/rooitou_park_256x128.npy");
    let runs: [(&str, Vec<&str>); 5] = [
        (
            "rotation-cycle",
            vec!["--methods", "nearest", "--steps", "4", image],
        ),
        (
            "shift-chain",
            vec!["--methods", "haar", "--dx", "8", "--steps", "2", image],
        ),
        (
            "tradeoff",
            vec![
                "--methods",
                "linear",
                "--max-supersample",
                "0",
                "--steps",
                "2",
                image,
            ],
        ),
        ("stability", vec!["--quick", "--image", p(&camera)]),
        (
            "sphere",
            vec![
                p(&map),
                "--methods",
                "bilinear",
                "--levels",
                "full",
                "--samples",
                "1",
            ],
        ),
    ];
    for (experiment, flags) in runs {
        let mut args = vec!["experiment", experiment, "--out-dir", o];
        args.extend(flags);
        refuses_then_replaces(&args, &out, experiment);
    }
}
