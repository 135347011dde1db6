//! `haarshift sphere rotate` and `haarshift experiment sphere` end to end on the test map: the
//! binary must give exactly what the library gives, write what it says, and fail in one line.

use std::path::Path;

use crate::common::strs;
use crate::common::{
    fails_cleanly, fails_cleanly_in, p, succeeds, text, usage_error, usage_error_in,
};

use haarshift::io::{CoefficientFile, WriteOptions, read_image, write_image};
use haarshift::sphere::map_error::{self, STANDARD_ROTATIONS};
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
use haarshift::{Channels, PlanarImage, SampleDepth};
use ndarray::Array3;

const MAP_NAME: &str = "rooitou_park_256x128";

/// The test map (see testdata/envmaps/SOURCES.md).
const MAP: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../testdata/envmaps/rooitou_park_256x128.npy"
);

fn test_map() -> LatLongMap<f32> {
    LatLongMap::from_image(&read_image::<f32>(MAP).unwrap()).unwrap()
}

/// `sphere rotate INPUT -o OUTPUT FLAGS...`
fn sphere_rotate_args(input: &str, output: &Path, flags: &[&str]) -> Vec<String> {
    ["sphere", "rotate", input, "-o", p(output)]
        .iter()
        .chain(flags)
        .map(|s| s.to_string())
        .collect()
}

/// The map in a pixel file written by the CLI.
fn read_map(path: &Path) -> LatLongMap<f32> {
    LatLongMap::from_image(&read_image::<f32>(path).unwrap()).unwrap()
}

#[test]
fn every_method_gives_exactly_what_the_library_gives() {
    let dir = tempfile::tempdir().unwrap();
    let map = test_map();
    let cases: [(Method, Option<usize>, &str); 5] = [
        (Method::Haar, None, "npy"),
        (Method::Haar, Some(4), "npy"),
        (Method::Bilinear, None, "exr"),
        (Method::Bicubic, None, "npy"),
        (Method::Reference, None, "npy"),
    ];
    let (yaw, pitch, roll) = (40.0, -25.0, 60.0);
    let rotation = SphereRotation::from_degrees(yaw, pitch, roll).unwrap();
    for (method, level, ext) in cases {
        let out = dir.path().join(format!("{method}-{level:?}.{ext}"));
        let mut args = sphere_rotate_args(
            MAP,
            &out,
            &[
                "--yaw",
                "40",
                "--pitch",
                "-25",
                "--roll",
                "60",
                "--samples",
                "2",
            ],
        );
        args.extend(["--method".into(), method.to_string()]);
        args.extend(level.map(|l| format!("--level={l}")));
        let stdout = text(&succeeds(&strs(&args)).stdout);
        assert!(stdout.contains("256 x 128"), "{stdout}");
        let options = SphereOptions {
            method,
            level,
            reference_samples: 2,
        };
        let want = rotate_map(&map, &rotation, &options).unwrap().map;
        let got = read_map(&out);
        assert_eq!(got, want, "{method} {level:?}");
        // A rotation moves the map: the test would notice a command that copied its input.
        assert_ne!(got, map);
    }
}

#[test]
fn identity_and_whole_column_yaw_return_the_input_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let map = test_map();
    for &method in Method::ALL {
        let out = dir.path().join(format!("identity-{method}.npy"));
        let flags = ["--method", method.name(), "--samples", "2"];
        succeeds(&strs(&sphere_rotate_args(MAP, &out, &flags)));
        assert_eq!(read_map(&out), map, "{method}");
        // 45 degrees is 32 of 256 columns: g(theta, phi) = f(theta, phi + 45 degrees).
        let out = dir.path().join(format!("yaw-{method}.npy"));
        succeeds(&strs(&sphere_rotate_args(
            MAP,
            &out,
            &["--method", method.name(), "--yaw", "45"],
        )));
        assert_eq!(read_map(&out), map.roll_columns(32), "{method}");
    }
}

#[test]
fn coefficients_are_a_readable_npy_with_sidecar_that_inverts_to_the_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let coeffs = dir.path().join("rotated.npy");
    let pixels = dir.path().join("rotated.exr");
    let flags = ["--pitch", "30", "--level", "5"];
    let mut args = sphere_rotate_args(MAP, &coeffs, &flags);
    args.push("--coefficients".into());
    succeeds(&strs(&args));
    succeeds(&strs(&sphere_rotate_args(MAP, &pixels, &flags)));

    let file = CoefficientFile::read(&coeffs).unwrap();
    let meta = file.metadata();
    assert_eq!(meta.channels, Channels::Rgb);
    assert_eq!(meta.depth, SampleDepth::F32);
    assert_eq!(meta.transform.levels, [7, 7]);
    assert_eq!(meta.transform.original_shape, [128, 256]);
    let options = SphereOptions {
        level: Some(5),
        ..Default::default()
    };
    let rotation = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
    let want = rotate_map(&test_map(), &rotation, &options)
        .unwrap()
        .coefficients;
    for (k, plane) in file.planes().iter().enumerate() {
        let want = want
            .as_array()
            .index_axis(ndarray::Axis(0), k)
            .mapv(f64::from);
        assert_eq!(plane.as_array(), want, "channel {k}");
    }
    // Level 6 (the finest) was not computed: its details are zero.
    let fine = file.planes()[0]
        .band(haarshift::transform::Band::Diagonal, 6)
        .unwrap();
    assert!(fine.iter().all(|&v| v == 0.0));

    let restored = dir.path().join("restored.npy");
    succeeds(&["inverse", p(&coeffs), "-o", p(&restored)]);
    let (a, b) = (read_map(&restored), read_map(&pixels));
    let worst = (&a.as_array() - &b.as_array())
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs()));
    // Measured 1.2e-4 (2^-13: one f32 ulp of the largest values); bound 4x.
    assert!(worst < 5e-4, "inverse differs from the pixels by {worst}");
}

#[test]
fn bad_inputs_fail_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let exr = dir.path().join("c.exr");
    let odd = dir.path().join("odd.npy");
    // 2:1 but not a power of two.
    let image = PlanarImage::new(
        Array3::<f32>::ones((1, 6, 12)),
        Channels::Gray,
        SampleDepth::F32,
    );
    write_image(&image.unwrap(), &odd, WriteOptions::default()).unwrap();
    let square = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/camera.png");
    let cases = [
        (
            sphere_rotate_args(square, &out, &["--pitch", "10"]),
            vec!["camera.png", "twice as wide", "512 x 512"],
        ),
        (
            sphere_rotate_args("no-such-map.hdr", &out, &[]),
            vec!["no-such-map.hdr"],
        ),
        (
            sphere_rotate_args(MAP, &out, &["--yaw", "NaN"]),
            vec!["yaw", "NaN"],
        ),
        (
            sphere_rotate_args(MAP, &out, &["--pitch", "NaN"]),
            vec!["pitch", "NaN"],
        ),
        (
            sphere_rotate_args(MAP, &out, &["--roll=-inf"]),
            vec!["roll", "-inf"],
        ),
        (
            sphere_rotate_args(p(&odd), &out, &["--pitch", "10"]),
            vec!["odd.npy", "power of two"],
        ),
        (
            sphere_rotate_args(MAP, &out, &["--pitch", "1", "--level", "7"]),
            vec!["level", "0..=6"],
        ),
        (
            sphere_rotate_args(
                MAP,
                &out,
                &["--pitch", "1", "--method", "reference", "--samples", "0"],
            ),
            vec!["samples"],
        ),
        (
            sphere_rotate_args(MAP, &exr, &["--coefficients"]),
            vec!["c.exr", ".npy"],
        ),
        (
            sphere_rotate_args(MAP, Path::new(MAP), &["--force"]),
            vec!["input"],
        ),
    ];
    for (args, needles) in &cases {
        fails_cleanly(&strs(args), needles);
    }
    succeeds(&strs(&sphere_rotate_args(MAP, &out, &[])));
    fails_cleanly(
        &strs(&sphere_rotate_args(MAP, &out, &[])),
        &["out.npy", "--force"],
    );
    succeeds(&strs(&sphere_rotate_args(MAP, &out, &["--force"])));
    // Usage errors are clap's: exit code 2.
    usage_error(
        &strs(&sphere_rotate_args(MAP, &out, &["--method", "fft"])),
        &["--method", "fft"],
    );
}

#[test]
fn experiment_writes_csv_json_and_plot_with_the_library_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("results");
    let records = dir.path().join("records.json");
    let args = [
        "experiment",
        "sphere",
        MAP,
        "--methods",
        "bilinear,haar",
        "--levels",
        "full,full-2",
        "--samples",
        "2",
        "--out-dir",
        p(&out_dir),
        "--json",
        p(&records),
    ];
    let stdout = text(&succeeds(&args).stdout);
    // One table row per rotation for the reference and each method at each level.
    let rows = stdout
        .lines()
        .filter(|l| l.starts_with(&format!("| {MAP_NAME}")))
        .count();
    assert_eq!(rows, STANDARD_ROTATIONS.len() * 5, "{stdout}");

    let csv = std::fs::read_to_string(out_dir.join("sphere.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("map,method,yaw,pitch,roll,level,thesis_level,rms,"),
        "{header}"
    );
    assert!(
        header.contains("energy_error") && header.ends_with("seconds"),
        "{header}"
    );
    assert_eq!(csv.lines().count(), 1 + rows);
    let plot = read_image::<f32>(out_dir.join("sphere-rms.png")).unwrap();
    assert_eq!((plot.width(), plot.height()), (1100, 700));

    let parse = |path: &Path| -> Vec<serde_json::Value> {
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let got = parse(&records);
    assert_eq!(got, parse(&out_dir.join("sphere.json")));
    let want = map_error::run(
        MAP_NAME,
        &test_map(),
        &STANDARD_ROTATIONS,
        &[
            (Method::Bilinear, None),
            (Method::Bilinear, Some(4)),
            (Method::Haar, None),
            (Method::Haar, Some(4)),
        ],
        2,
    )
    .unwrap();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        let w = serde_json::to_value(w).unwrap();
        for field in ["map", "method", "yaw", "pitch", "roll", "level"] {
            assert_eq!(g[field], w[field], "{field}: {g} vs {w}");
        }
        for field in [
            "rms",
            "relative_rms",
            "rms_at_level",
            "coefficient_rms",
            "energy_error",
        ] {
            let (a, b) = (g[field].as_f64().unwrap(), w[field].as_f64().unwrap());
            assert!((a - b).abs() <= 1e-12 * b.abs(), "{field}: {a} vs {b}");
        }
        assert!(g["seconds"].as_f64().unwrap() > 0.0);
    }
    // The Haar rows really differ from the bilinear ones (pitch 30, full depth).
    assert_eq!(
        (&got[6]["method"], &got[8]["method"]),
        (&"bilinear".into(), &"haar".into())
    );
    assert_ne!(got[6]["rms"], got[8]["rms"]);

    // Nothing is overwritten without --force, and the refusal comes before the work.
    fails_cleanly(&args, &["sphere-rms.png", "already exists", "--force"]);
    assert_eq!(parse(&records), got);
}

#[test]
fn experiment_without_maps_runs_the_embedded_map_from_any_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_haarshift"))
        .args([
            "experiment",
            "sphere",
            "--methods",
            "bilinear",
            "--levels",
            "full",
        ])
        .args(["--samples", "1"])
        .current_dir(dir.path())
        .env("TMPDIR", dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let rows = stdout
        .lines()
        .filter(|l| l.starts_with(&format!("| {MAP_NAME}")))
        .count();
    assert_eq!(rows, STANDARD_ROTATIONS.len() * 2, "{stdout}");
    // The reports went to the scratch directory under TMPDIR, whose csv has those rows.
    let csv = dir.path().join("haarshift/sphere/sphere.csv");
    assert_eq!(
        std::fs::read_to_string(csv).unwrap().lines().count(),
        1 + rows
    );
}

#[test]
fn experiment_refuses_bad_levels() {
    let dir = tempfile::tempdir().unwrap();
    fails_cleanly_in(
        Some(dir.path()),
        &["experiment", "sphere", MAP, "--levels", "full-9"],
        &["full-9", "0..=6"],
    );
    usage_error_in(
        Some(dir.path()),
        &["experiment", "sphere", "--levels", "fine"],
        &["--levels", "fine"],
    );
}

#[test]
fn help_states_the_conventions_and_explains_every_flag() {
    let rotate_needles = [
        "R = Rz(roll) Ry(yaw) Rx(pitch)",
        "g(p) = f(R p)",
        "Y up",
        "theta from +Y",
        "haarshift sphere rotate park.hdr",
        "--output",
        "--yaw",
        "--pitch",
        "--roll",
        "--method",
        "--level",
        "--samples",
        "--coefficients",
        "[possible values: reference, bilinear, bicubic, haar, haar-cubic]",
        "--method haar-cubic",
    ];
    let experiment_needles = [
        "haarshift experiment sphere",
        "--json",
        "--out-dir",
        "--methods",
        "--levels",
        "--samples",
        "pitch 5, 30, 60 and 90",
    ];
    for (command, needles) in [
        (["sphere", "rotate", "--help"], &rotate_needles[..]),
        (["experiment", "sphere", "--help"], &experiment_needles[..]),
    ] {
        // Help is wrapped to the terminal: compare with whitespace collapsed.
        let help = text(&succeeds(&command).stdout);
        let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
        for needle in needles.iter().chain(&["Examples:", "--force"]) {
            assert!(
                help.contains(needle),
                "{command:?} lacks {needle:?}: {help}"
            );
        }
    }
}
