//! `haarshift rotate` and `haarshift shift` end to end: exact quarter turns and integer
//! shifts, the pixel-domain meaning of the Haar shift (bilinear at 1/2^h, and the retained
//! finer image), round trips, sizes, channels and depths, and one clean line per error.

use std::path::{Path, PathBuf};

use crate::common::run;
use crate::common::{fails_cleanly, p, succeeds, testdata};

use haarshift::Channels::{Gray, Rgb};
use haarshift::SampleDepth::{F64, U8, U16};
use haarshift::io::{WriteOptions, read_image, write_image};
use haarshift::{Channels, PlanarImage, SampleDepth};
use ndarray::{Array2, Array3};

/// Deterministic pseudo-random values in `0..max` (a 64-bit LCG), whole numbers.
fn noise(len: usize, max: u64, seed: u64) -> Vec<f64> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % max) as f64
        })
        .collect()
}

/// Writes a `channels` image of `h x w` noise at `depth` to `dir/name`.
fn write_noise(
    dir: &Path,
    name: &str,
    (h, w): (usize, usize),
    channels: Channels,
    depth: SampleDepth,
) -> (PathBuf, PlanarImage<f64>) {
    let c = channels.count();
    let max = depth.integer_max().map_or(1000, |m| m as u64 + 1);
    let planes = Array3::from_shape_vec((c, h, w), noise(c * h * w, max, (h * w) as u64)).unwrap();
    let image = PlanarImage::new(planes, channels, depth).unwrap();
    let path = dir.join(name);
    write_image(&image, &path, WriteOptions::default()).unwrap();
    (path, image)
}

/// `np.rot90(plane, turns)`: counter-clockwise quarter turns, computed index by index.
fn rot90(plane: &Array2<f64>, turns: usize) -> Array2<f64> {
    (0..turns % 4).fold(plane.clone(), |a, _| {
        let (h, w) = a.dim();
        Array2::from_shape_fn((w, h), |(r, c)| a[[c, w - 1 - r]])
    })
}

#[test]
fn quarter_turns_are_bit_exact_for_every_method_tried() {
    let dir = tempfile::tempdir().unwrap();
    let camera = testdata("camera.png");
    let input = read_image::<f64>(&camera).unwrap();
    let (small, small_image) = write_noise(dir.path(), "small.png", (12, 12), Rgb, U8);
    for (angle, turns) in [("90", 1), ("180", 2), ("270", 3), ("-90", 3)] {
        for method in ["nearest", "bspline3", "lanczos4", "fft", "haar"] {
            let out = dir.path().join(format!("cam-{angle}-{method}.png"));
            let got = run(
                "rotate",
                &camera,
                &out,
                &["--angle", angle, "--method", method],
            );
            assert_eq!(got.plane(0), rot90(&input.plane(0).to_owned(), turns));
        }
        // The retained Haar mode on a finer grid, and supersampling, stay exact too.
        for flags in [
            &["--method", "haar", "--retain"][..],
            &["--supersample", "1"],
        ] {
            let out = dir
                .path()
                .join(format!("small-{angle}-{}.png", flags.len()));
            let mut args = vec!["rotate", p(&small), "-o", p(&out), "--angle", angle];
            args.extend_from_slice(flags);
            succeeds(&args);
            let got = read_image::<f64>(&out).unwrap();
            for c in 0..3 {
                let plane = small_image.plane(c).to_owned();
                assert_eq!(got.plane(c), rot90(&plane, turns), "{flags:?}");
            }
        }
    }
}

#[test]
fn rotating_back_with_bspline5_restores_the_centre() {
    let dir = tempfile::tempdir().unwrap();
    let camera = testdata("camera.png");
    let there = dir.path().join("there.npy");
    let back = dir.path().join("back.npy");
    let common = ["--method", "bspline5", "--depth", "f64"];
    let mut args = vec!["rotate", p(&camera), "-o", p(&there), "--angle", "30"];
    args.extend_from_slice(&common);
    succeeds(&args);
    let mut args = vec!["rotate", p(&there), "-o", p(&back), "--angle", "-30"];
    args.extend_from_slice(&common);
    succeeds(&args);
    let input = read_image::<f64>(&camera).unwrap();
    let output = read_image::<f64>(&back).unwrap();
    assert_eq!((output.height(), output.width()), (512, 512));
    // The disc of radius 200 about the centre never leaves the canvas at 30 degrees.
    let (mut sum, mut max, mut n) = (0.0f64, 0.0f64, 0usize);
    for r in 0..512 {
        for c in 0..512 {
            let (y, x) = (r as f64 - 255.5, c as f64 - 255.5);
            if x * x + y * y <= 200.0 * 200.0 {
                let e = (output.plane(0)[[r, c]] - input.plane(0)[[r, c]]).abs();
                sum += e;
                max = max.max(e);
                n += 1;
            }
        }
    }
    let mean = sum / n as f64;
    // In 0..255 units, measured: mean 1.33, max 30.4 (at the sharpest edges of the camera
    // man, where the two resamplings' aliasing does not cancel). Tolerances: mean 1.6, max 36
    // (1.2x each).
    assert!(mean < 1.6, "mean abs error {mean}");
    assert!(max < 36.0, "max abs error {max}");
}

#[test]
fn expand_canvas_holds_the_whole_image() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = write_noise(dir.path(), "wide.png", (20, 40), Gray, U8);
    for (angle, deg) in [("30", 30.0f64), ("90", 90.0), ("-125", -125.0)] {
        let out = dir.path().join(format!("wide-{angle}.png"));
        let got = run(
            "rotate",
            &input,
            &out,
            &["--angle", angle, "--canvas", "expand"],
        );
        let (sin, cos) = (deg.to_radians().sin().abs(), deg.to_radians().cos().abs());
        let width = (40.0 * cos + 20.0 * sin).round() as usize;
        let height = (40.0 * sin + 20.0 * cos).round() as usize;
        assert_eq!((got.width(), got.height()), (width, height), "{angle}");
    }
}

#[test]
fn rgba_keeps_alpha_and_colour_does_not_bleed_from_transparent_pixels() {
    let dir = tempfile::tempdir().unwrap();
    // Left half opaque green, right half fully transparent but red.
    let (h, w) = (24, 24);
    let planes = Array3::from_shape_fn((4, h, w), |(c, _, col)| match (c, col < w / 2) {
        (0, false) => 255.0,
        (1, true) | (3, true) => 255.0,
        _ => 0.0,
    });
    let image = PlanarImage::new(planes, Channels::Rgba, SampleDepth::U8).unwrap();
    let input = dir.path().join("half.png");
    write_image(&image, &input, WriteOptions::default()).unwrap();
    let out = dir.path().join("half-20.png");
    let got = run(
        "rotate",
        &input,
        &out,
        &["--angle", "20", "--method", "keys"],
    );
    assert_eq!(got.channels(), Channels::Rgba);
    // A corner comes from outside: transparent.
    assert_eq!(got.plane(3)[[0, 0]], 0.0);
    let mut visible = 0;
    for r in 0..h {
        for c in 0..w {
            if got.plane(3)[[r, c]] > 0.0 {
                visible += 1;
                // Any visible pixel is pure green: no red from the transparent half.
                assert_eq!(got.plane(0)[[r, c]], 0.0, "red at {r},{c}");
                assert_eq!(got.plane(1)[[r, c]], 255.0, "green at {r},{c}");
            }
        }
    }
    assert!(visible > h * w / 4, "{visible} visible pixels");
}

#[test]
fn sixteen_bit_png_stays_sixteen_bit() {
    // A 16-bit ramp `1000 + 150 r + 100 c`: linear interpolation reproduces a linear function
    // exactly, so inside the image every shear, and the rotation, is exact. The rotation by
    // the definition: output pixel at (u, v) from the centre takes the input at
    // (u cos t - v sin t, u sin t + v cos t) (counter-clockwise as displayed, y down).
    let dir = tempfile::tempdir().unwrap();
    let n = 64;
    let ramp = |r: f64, c: f64| 1000.0 + 150.0 * r + 100.0 * c;
    let planes = Array3::from_shape_fn((1, n, n), |(_, r, c)| ramp(r as f64, c as f64));
    let image = PlanarImage::new(planes, Gray, U16).unwrap();
    let input = dir.path().join("ramp.png");
    write_image(&image, &input, WriteOptions::default()).unwrap();
    let out = dir.path().join("ramp-10.png");
    let got = run(
        "rotate",
        &input,
        &out,
        &["--angle", "10", "--method", "linear"],
    );
    assert_eq!(got.depth(), SampleDepth::U16);
    let (sin, cos) = 10f64.to_radians().sin_cos();
    let centre = (n as f64 - 1.0) / 2.0;
    let mut inside = 0;
    for r in 0..n {
        for c in 0..n {
            let (u, v) = (c as f64 - centre, r as f64 - centre);
            if u * u + v * v > 20.0 * 20.0 {
                continue;
            }
            let want = ramp(centre + u * sin + v * cos, centre + u * cos - v * sin);
            let v = got.plane(0)[[r, c]];
            // Rounded to the nearest 16-bit level of an f32 computation (the CLI works in f32
            // for 16-bit input): half a level plus a few f32 ulps (0.0005 at 8000), where 8-bit
            // quantisation would be off by ~128.
            assert!((v - want).abs() <= 0.5 + 0.01, "({r}, {c}): {v} vs {want}");
            inside += 1;
        }
    }
    assert!(inside > 1200, "{inside} pixels checked");
    // Not 8-bit levels scaled by 257 anywhere in the disc's rows.
    let off_grid = got.plane(0).iter().filter(|&&v| v % 257.0 != 0.0).count();
    assert!(off_grid > n * n / 2, "{off_grid} values off the 8-bit grid");
}

/// Reads a one-plane result.
fn plane_of(path: &Path) -> Array2<f64> {
    read_image::<f64>(path).unwrap().plane(0).to_owned()
}

#[test]
fn integer_haar_shift_is_a_periodic_roll() {
    let dir = tempfile::tempdir().unwrap();
    let (input, image) = write_noise(dir.path(), "roll.png", (32, 16), Gray, U8);
    let out = dir.path().join("rolled.png");
    succeeds(&["shift", p(&input), "-o", p(&out), "--dx", "3", "--dy", "-5"]);
    let x = image.plane(0);
    let expected = Array2::from_shape_fn((32, 16), |(r, c)| x[[(r + 5) % 32, (c + 16 - 3) % 16]]);
    assert_eq!(plane_of(&out), expected);
}

/// `x` (periodic) at `n - s`, linearly interpolated along `axis`: `(1 - a) x[n - q] +
/// a x[n - q - 1]` with `s = q + a`.
fn periodic_linear(x: &Array2<f64>, s: f64, axis: usize) -> Array2<f64> {
    let (q, a) = (s.floor() as isize, s - s.floor());
    let len = x.len_of(ndarray::Axis(axis)) as isize;
    Array2::from_shape_fn(x.dim(), |(r, c)| {
        let n = if axis == 0 { r } else { c } as isize;
        let at = |k: isize| {
            let k = k.rem_euclid(len) as usize;
            if axis == 0 { x[[k, c]] } else { x[[r, k]] }
        };
        (1.0 - a) * at(n - q) + a * at(n - q - 1)
    })
}

#[test]
fn fractional_haar_shift_is_bilinear_at_the_rounded_shift_and_retained_box_averages_to_it() {
    let dir = tempfile::tempdir().unwrap();
    let (input, image) = write_noise(dir.path(), "frac.npy", (16, 32), Gray, F64);
    let compact = dir.path().join("compact.npy");
    let shift = ["--dx", "0.3", "--dy", "-0.7", "--precision", "2"];
    let mut args = vec!["shift", p(&input), "-o", p(&compact)];
    args.extend_from_slice(&shift);
    succeeds(&args);
    // 0.3 rounds to 1/4 and -0.7 to -3/4 on the quarter-pixel grid.
    let x = image.plane(0).to_owned();
    let expected = periodic_linear(&periodic_linear(&x, 0.25, 1), -0.75, 0);
    let got = plane_of(&compact);
    let err = (&got - &expected)
        .mapv(f64::abs)
        .fold(0.0f64, |m, &v| m.max(v));
    // Measured 0: the quarter-pixel weights are dyadic; 1e-14 allows a reordered sum.
    assert!(err < 1e-14, "max difference {err}");

    let retained = dir.path().join("retained.npy");
    let mut args = vec!["shift", p(&input), "-o", p(&retained), "--retain"];
    args.extend_from_slice(&shift);
    succeeds(&args);
    let fine = plane_of(&retained);
    assert_eq!(fine.dim(), (64, 128));
    let boxed = Array2::from_shape_fn((16, 32), |(r, c)| {
        fine.slice(ndarray::s![4 * r..4 * r + 4, 4 * c..4 * c + 4])
            .sum()
            / 16.0
    });
    let err = (&boxed - &got)
        .mapv(f64::abs)
        .fold(0.0f64, |m, &v| m.max(v));
    // Measured 0: the quarter-pixel weights are dyadic; 1e-14 allows a reordered sum.
    assert!(err < 1e-14, "max difference {err}");
    // The fine image is the input's pixels as 4x4 blocks moved by (1, -3) fine samples.
    assert_eq!(fine[[3, 1]], x[[1, 0]]);
}

#[test]
fn pixel_methods_shift_with_their_boundary() {
    let dir = tempfile::tempdir().unwrap();
    let (input, image) = write_noise(dir.path(), "pix.png", (10, 12), Gray, U8);
    let out = dir.path().join("pix-linear.png");
    succeeds(&[
        "shift",
        p(&input),
        "-o",
        p(&out),
        "--dx",
        "2",
        "--dy",
        "1",
        "--method",
        "linear",
        "--boundary",
        "zero",
    ]);
    let x = image.plane(0);
    let expected = Array2::from_shape_fn((10, 12), |(r, c)| {
        if r >= 1 && c >= 2 {
            x[[r - 1, c - 2]]
        } else {
            0.0
        }
    });
    assert_eq!(plane_of(&out), expected);
}

#[test]
fn bad_requests_fail_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let camera = testdata("camera.png");
    let out = dir.path().join("out.png");
    let (cam, o) = (p(&camera), p(&out));
    fails_cleanly(&["rotate", cam, "-o", o, "--angle", "NaN"], &["angle"]);
    fails_cleanly(
        &[
            "rotate",
            cam,
            "-o",
            o,
            "--angle",
            "5",
            "--method",
            "keys",
            "--precision",
            "2",
        ],
        &["precision"],
    );
    fails_cleanly(
        &[
            "shift", cam, "-o", o, "--dx", "1", "--method", "linear", "--retain",
        ],
        &["retain"],
    );
    fails_cleanly(
        &["shift", cam, "-o", o, "--dx", "1", "--boundary", "zero"],
        &["periodic"],
    );
    fails_cleanly(&["shift", cam, "-o", o, "--dx", "inf"], &["shift"]);
    let missing = dir.path().join("missing.png");
    fails_cleanly(
        &["rotate", p(&missing), "-o", o, "--angle", "5"],
        &["missing.png"],
    );
    fails_cleanly(
        &["shift", p(&missing), "-o", o, "--dx", "1"],
        &["missing.png"],
    );
    fails_cleanly(
        &[
            "rotate",
            cam,
            "-o",
            o,
            "--angle",
            "5",
            "--supersample",
            "100",
        ],
        &["supersample"],
    );
    std::fs::write(&out, b"keep me").unwrap();
    fails_cleanly(
        &["rotate", cam, "-o", o, "--angle", "90"],
        &["already exists"],
    );
    fails_cleanly(&["shift", cam, "-o", o, "--dx", "1"], &["already exists"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"keep me");
    fails_cleanly(
        &["rotate", cam, "-o", cam, "--angle", "90"],
        &["camera.png"],
    );
}
