//! The `haarshift` binary end to end: exact round trips on the testdata photographs for every
//! layout, normalisation and padding, and one clean line of error for every kind of bad input.

use std::path::Path;

use crate::common::{fails_cleanly, p, succeeds, testdata, text, usage_error};

use haarshift::io::{WriteOptions, read_image, write_image};
use haarshift::transform::{Layout, Normalization};
use haarshift::{BoundaryMode, Channels, PlanarImage, SampleDepth};
use ndarray::Array3;

const PHOTOS: [&str; 6] = [
    "camera.png",
    "astronaut.png",
    "brick.png",
    "text.png",
    "coins.png",
    "chelsea.png",
];

/// transform -> inverse with `flags`, returning the restored image.
fn round_trip(dir: &Path, input: &Path, out_ext: &str, flags: &[&str]) -> PlanarImage<f64> {
    let stem = format!(
        "{}-{}",
        input.file_stem().unwrap().to_string_lossy(),
        flags.join("").replace('-', "")
    );
    let coeffs = dir.join(format!("{stem}.npy"));
    let restored = dir.join(format!("{stem}-restored.{out_ext}"));
    let mut args = vec!["transform", p(input), "-o", p(&coeffs)];
    args.extend_from_slice(flags);
    succeeds(&args);
    succeeds(&["inverse", p(&coeffs), "-o", p(&restored)]);
    read_image::<f64>(&restored).unwrap()
}

#[test]
fn every_photo_round_trips_bit_exactly_for_every_layout_norm_and_padding() {
    let dir = tempfile::tempdir().unwrap();
    let mut combos = Vec::new();
    for photo in PHOTOS {
        for &layout in Layout::ALL {
            for &norm in Normalization::ALL {
                for &pad in BoundaryMode::ALL {
                    combos.push((photo, layout, norm, pad));
                }
            }
        }
    }
    // The runs mostly wait for the disk: a few at a time.
    std::thread::scope(|s| {
        for chunk in combos.chunks(combos.len().div_ceil(4)) {
            let dir = dir.path();
            s.spawn(move || {
                for &(photo, layout, norm, pad) in chunk {
                    let input = testdata(photo);
                    let flags = [
                        "--layout",
                        layout.name(),
                        "--norm",
                        norm.name(),
                        "--pad",
                        pad.name(),
                    ];
                    let restored = round_trip(dir, &input, "png", &flags);
                    let original = read_image::<f64>(&input).unwrap();
                    assert_eq!(restored, original, "{photo} {flags:?}");
                }
            });
        }
    });
}

#[test]
fn partial_levels_and_other_output_formats_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let input = testdata("coins.png");
    let original = read_image::<f64>(&input).unwrap();
    for levels in ["0", "1", "3", "full"] {
        for layout in ["pyramid", "separable"] {
            let flags = ["--levels", levels, "--layout", layout];
            assert_eq!(round_trip(dir.path(), &input, "png", &flags), original);
        }
    }
    assert_eq!(round_trip(dir.path(), &input, "tif", &[]), original);
    let npy = round_trip(dir.path(), &input, "npy", &["--norm", "orthonormal"]);
    assert_eq!(npy.planes(), original.planes());
}

#[test]
fn sixteen_bit_and_float_images_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let planes = Array3::from_shape_fn((4, 37, 23), |(k, i, j)| {
        ((i * 1543 + j * 7919 + k * 104_729) % 65536) as f64
    });
    let wide = PlanarImage::new(planes.clone(), Channels::Rgba, SampleDepth::U16).unwrap();
    let png = dir.path().join("wide.png");
    write_image(&wide, &png, WriteOptions::default()).unwrap();
    let flags = ["--pad", "reflect", "--norm", "orthonormal"];
    assert_eq!(round_trip(dir.path(), &png, "png", &flags), wide);

    let float = PlanarImage::new(
        planes.mapv(|v| (v - 30000.0) / 977.0),
        Channels::Rgba,
        SampleDepth::F32,
    )
    .unwrap();
    let exr = dir.path().join("float.exr");
    write_image(&float, &exr, WriteOptions::default()).unwrap();
    let stored = read_image::<f64>(&exr).unwrap();
    let back = round_trip(dir.path(), &exr, "exr", &["--layout", "separable"]);
    assert_eq!(back.depth(), SampleDepth::F32);
    for (x, y) in back.planes().iter().zip(stored.planes().iter()) {
        // Measured 0 for every value (the round trip is exact here); bound one f32 ulp.
        assert!(
            (x - y).abs() <= f64::from(f32::EPSILON) * y.abs(),
            "{x} vs {y}"
        );
    }
}

#[test]
fn existing_outputs_need_force_and_inputs_are_never_touched() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.png");
    std::fs::copy(testdata("text.png"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let coeffs = dir.path().join("c.npy");
    succeeds(&["transform", p(&input), "-o", p(&coeffs)]);
    fails_cleanly(
        &["transform", p(&input), "-o", p(&coeffs)],
        &["c.npy", "already exists (use --force"],
    );
    succeeds(&[
        "transform",
        p(&input),
        "-o",
        p(&coeffs),
        "--force",
        "--levels",
        "2",
    ]);
    let out = dir.path().join("out.png");
    succeeds(&["inverse", p(&coeffs), "-o", p(&out)]);
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&out)],
        &["out.png", "already exists"],
    );
    succeeds(&["inverse", p(&coeffs), "-o", p(&out), "--force"]);
    let npy_input = dir.path().join("img.npy");
    write_image(
        &read_image::<f64>(&input).unwrap(),
        &npy_input,
        WriteOptions::default(),
    )
    .unwrap();
    // Output == input, even with --force and through another spelling of the path.
    let same = dir.path().join(".").join("img.npy");
    fails_cleanly(
        &["transform", p(&npy_input), "-o", p(&same), "--force"],
        &["img.npy", "is the input file"],
    );
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&coeffs), "--force"],
        &["c.npy", "is the input file"],
    );
    assert_eq!(std::fs::read(&input).unwrap(), before);
    assert_eq!(
        read_image::<f64>(&out).unwrap(),
        read_image::<f64>(&input).unwrap()
    );
}

#[test]
fn bad_inputs_fail_with_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, bytes: &[u8]| {
        let path = d.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let out = d.join("out.npy");
    let transform = |input: &Path, needle: &str| {
        let name = input.file_name().unwrap().to_str().unwrap().to_owned();
        fails_cleanly(&["transform", p(input), "-o", p(&out)], &[&name, needle]);
        fails_cleanly(&["info", p(input)], &[&name, needle]);
    };

    transform(&d.join("missing.png"), "No such file");
    transform(&write("empty.png", b""), "empty");
    transform(&write("words.png", b"not an image"), "not a valid PNG");
    transform(&write("words.jpg", b"not an image"), "not a valid JPEG");
    transform(
        &write("notes.txt", b"not an image"),
        "unsupported file format",
    );
    let mut corrupt = b"\x89PNG\r\n\x1a\n".to_vec();
    corrupt.extend_from_slice(&[0x55; 200]);
    transform(
        &write("corrupt.png", &corrupt),
        "chunk appeared before IHDR",
    );
    let photo = std::fs::read(testdata("camera.png")).unwrap();
    transform(
        &write("truncated.png", &photo[..photo.len() / 3]),
        "file is truncated",
    );
    let npy = |descr: &str, shape: &str, data: &[u8]| {
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (11 + header.len()) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend_from_slice(data);
        bytes
    };
    let mut nan = vec![0u8; 32];
    nan[24..].copy_from_slice(&f64::INFINITY.to_le_bytes());
    transform(
        &write("inf.npy", &npy("<f8", "(2, 2)", &nan)),
        "non-finite value inf",
    );
    transform(&write("zero.npy", &npy("<f4", "(0, 3)", &[])), "zero size");
    transform(
        &write("huge.npy", &npy("<f4", "(1000000, 1000000)", &[])),
        "memory limit",
    );
    transform(
        &write("short.npy", &npy("<f4", "(4, 4)", &[0; 8])),
        "truncated",
    );

    // Transform parameters that do not fit the image.
    let camera = testdata("camera.png");
    fails_cleanly(
        &["transform", p(&camera), "-o", p(&out), "--levels", "10"],
        &["camera.png", "at most 9"],
    );
    fails_cleanly(
        &["transform", p(&camera), "-o", p(&d.join("c.png"))],
        &["c.png", ".npy"],
    );

    // Coefficient files: flags that contradict the sidecar, broken sidecars, wrong outputs.
    let coeffs = d.join("coeffs.npy");
    succeeds(&["transform", p(&camera), "-o", p(&coeffs), "--levels", "4"]);
    let back = d.join("back.png");
    fails_cleanly(
        &[
            "inverse",
            p(&coeffs),
            "-o",
            p(&back),
            "--norm",
            "orthonormal",
        ],
        &["coeffs.npy", "normalisation orthonormal was requested"],
    );
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&back), "--levels", "full"],
        &["coeffs.npy", "levels"],
    );
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&d.join("back.gif"))],
        &["back.gif", "output format"],
    );
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&d.join("no/dir/back.png"))],
        &["back.png", "does not exist"],
    );
    fails_cleanly(
        &["inverse", p(&d.join("nope.npy")), "-o", p(&back)],
        &["nope.npy", "No such file"],
    );
    std::fs::write(d.join("coeffs.npy.json"), b"{").unwrap();
    fails_cleanly(
        &["inverse", p(&coeffs), "-o", p(&back)],
        &["coeffs.npy.json", "invalid sidecar"],
    );
    assert!(!back.exists());
}

#[test]
fn coefficients_without_sidecar_use_the_flags_and_keep_the_padded_size() {
    let dir = tempfile::tempdir().unwrap();
    let coeffs = dir.path().join("c.npy");
    succeeds(&[
        "transform",
        p(&testdata("coins.png")),
        "-o",
        p(&coeffs),
        "--layout",
        "separable",
        "--pad",
        "edge",
    ]);
    std::fs::remove_file(dir.path().join("c.npy.json")).unwrap();
    let out = dir.path().join("out.png");
    let run = succeeds(&[
        "inverse",
        p(&coeffs),
        "-o",
        p(&out),
        "--layout",
        "separable",
        "--depth",
        "u8",
    ]);
    let note = text(&run.stderr);
    assert!(note.contains("no sidecar") && note.contains("original size is unknown"));
    let padded = read_image::<f64>(&out).unwrap();
    let original = read_image::<f64>(&testdata("coins.png")).unwrap();
    assert_eq!((padded.height(), padded.width()), (512, 512));
    let crop = padded
        .planes()
        .slice(ndarray::s![.., ..original.height(), ..original.width()])
        .to_owned();
    assert_eq!(crop, original.planes());
    // Edge padding: the row below the image repeats its last row.
    let h = original.height();
    assert_eq!(
        padded.planes().slice(ndarray::s![0, h, ..original.width()]),
        original.planes().slice(ndarray::s![0, h - 1, ..])
    );
}

#[test]
fn info_reports_size_channels_depth_and_ranges() {
    let run = succeeds(&["info", p(&testdata("chelsea.png"))]);
    let out = text(&run.stdout);
    let original = read_image::<f64>(&testdata("chelsea.png")).unwrap();
    assert!(
        out.contains("size:     451 x 300 (width x height)"),
        "{out}"
    );
    assert!(out.contains("channels: rgb (3)"), "{out}");
    assert!(out.contains("depth:    u8"), "{out}");
    for (name, plane) in ["red", "green", "blue"]
        .iter()
        .zip(original.planes().outer_iter())
    {
        let lo = plane.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = plane.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let line = format!("range:    {name:<5} {lo} .. {hi}");
        assert!(out.contains(&line), "{out} lacks {line}");
    }

    let dir = tempfile::tempdir().unwrap();
    let coeffs = dir.path().join("c.npy");
    succeeds(&["transform", p(&testdata("text.png")), "-o", p(&coeffs)]);
    let out = text(&succeeds(&["info", p(&coeffs)]).stdout);
    assert!(out.contains("haarshift coefficients"), "{out}");
    assert!(out.contains("array:     1 planes of 512 x 256"), "{out}");
    assert!(
        out.contains("original:  448 x 172 (width x height), gray"),
        "{out}"
    );
}

#[test]
fn help_explains_every_flag_with_examples_and_usage_errors_exit_2() {
    for (command, flags) in [
        (
            "transform",
            &[
                "--levels", "--layout", "--norm", "--pad", "--force", "--output",
            ][..],
        ),
        (
            "inverse",
            &[
                "--levels", "--layout", "--norm", "--pad", "--force", "--depth", "--output",
            ][..],
        ),
        ("info", &[][..]),
    ] {
        let out = text(&succeeds(&[command, "--help"]).stdout);
        assert!(out.contains("Examples:"), "{command}: {out}");
        assert!(
            out.contains(&format!("haarshift {command} ")),
            "{command}: {out}"
        );
        for flag in flags {
            assert!(out.contains(flag), "{command} --help lacks {flag}");
        }
    }
    // Help is wrapped to the terminal: compare with whitespace collapsed.
    let out = text(&succeeds(&["transform", "--help"]).stdout);
    let out = out.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        out.contains("[possible values: pyramid, separable]"),
        "{out}"
    );
    assert!(
        out.contains("[possible values: zero, edge, reflect, wrap]"),
        "{out}"
    );

    for (args, flag) in [
        (&["transform"][..], "<INPUT>"),
        (&["transform", "a.png"][..], "--output"),
        (
            &["transform", "a.png", "-o", "b.npy", "--layout", "spiral"][..],
            "--layout",
        ),
        (
            &["transform", "a.png", "-o", "b.npy", "--levels", "-1"][..],
            "-1",
        ),
        (&["frobnicate"][..], "frobnicate"),
    ] {
        usage_error(args, &[flag]);
    }
}
