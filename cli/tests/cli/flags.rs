//! The `rotate` and `shift` flags that change values, each checked on the values it must
//! produce (so that a command ignoring the flag fails): `--fill`, `--boundary`, `--keys-a`,
//! `--depth u16` and `--depth f16`; and images with alpha (RGBA shifts, gray+alpha
//! rotations).

use std::path::{Path, PathBuf};

use crate::common::run;

use haarshift::io::{WriteOptions, write_image};
use haarshift::{Channels, PlanarImage, SampleDepth};
use ndarray::{Array2, Array3};

/// Writes `planes` as `dir/name` at `depth` with `channels`.
fn write_planes(
    dir: &Path,
    name: &str,
    planes: Array3<f64>,
    channels: Channels,
    depth: SampleDepth,
) -> PathBuf {
    let path = dir.join(name);
    let image = PlanarImage::new(planes, channels, depth).unwrap();
    write_image(&image, &path, WriteOptions::default()).unwrap();
    path
}

/// An irregular 10x12 gray plane of whole numbers 0..=250.
fn irregular() -> Array2<f64> {
    Array2::from_shape_fn((10, 12), |(r, c)| {
        ((r * 37 + c * 91 + r * c * 7) % 251) as f64
    })
}

/// `--fill V`: pixels the rotation brings from outside are V, inside a constant image stays
/// constant. Ignoring the flag gives 0 at the corners.
#[test]
fn fill_sets_the_outside_value() {
    let dir = tempfile::tempdir().unwrap();
    let planes = Array3::from_elem((1, 16, 16), 100.0);
    let input = write_planes(
        dir.path(),
        "flat.png",
        planes,
        Channels::Gray,
        SampleDepth::U8,
    );
    let got = run(
        "rotate",
        &input,
        &dir.path().join("out.png"),
        &["--angle", "30", "--method", "linear", "--fill", "37"],
    );
    let g = got.plane(0);
    // The corner (-7.5, -7.5) from the centre comes from (-2.7, -10.2): 2.7 rows outside,
    // beyond the linear kernel's reach, in each of the three shears.
    for corner in [[0, 0], [0, 15], [15, 0], [15, 15]] {
        assert_eq!(g[corner], 37.0, "corner {corner:?}");
    }
    for r in 6..10 {
        for c in 6..10 {
            assert_eq!(g[[r, c]], 100.0, "centre ({r}, {c})");
        }
    }
    // Along the border, pixels partly covered lie between the two.
    assert!(g.iter().any(|&v| v > 37.0 && v < 100.0));
}

/// The source index of position `i` in a signal of `n` samples, written from the boundary
/// table (edge: clamp; reflect: `c b a | a b c d | d c b`; wrap: periodic).
fn extend(mode: &str, i: isize, n: usize) -> usize {
    let n = n as isize;
    let k = match mode {
        "edge" => i.clamp(0, n - 1),
        "wrap" => i.rem_euclid(n),
        "reflect" => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
        _ => unreachable!("{mode}"),
    };
    k as usize
}

/// `shift --boundary MODE` with a pixel-domain method: a whole shift by (2, -1) is
/// `out[r][c] = x[r + 1][c - 2]` continued by the mode, for each mode (the default, wrap,
/// would pass none of the others).
#[test]
fn shift_boundary_modes_continue_the_image_as_the_table_says() {
    let dir = tempfile::tempdir().unwrap();
    let x = irregular();
    let (h, w) = x.dim();
    let input = write_planes(
        dir.path(),
        "x.png",
        x.clone().into_shape_with_order((1, h, w)).unwrap(),
        Channels::Gray,
        SampleDepth::U8,
    );
    for mode in ["edge", "reflect", "wrap"] {
        let out = dir.path().join(format!("{mode}.png"));
        let flags = [
            "--dx",
            "2",
            "--dy",
            "-1",
            "--method",
            "linear",
            "--boundary",
            mode,
        ];
        let got = run("shift", &input, &out, &flags);
        let want = Array2::from_shape_fn((h, w), |(r, c)| {
            x[[
                extend(mode, r as isize + 1, h),
                extend(mode, c as isize - 2, w),
            ]]
        });
        assert_eq!(got.plane(0), want, "{mode}");
    }
}

/// `rotate --boundary edge` continues a constant image: every pixel, corners included, keeps
/// its value (with the default fill the corners would be 0).
#[test]
fn rotate_boundary_edge_continues_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let planes = Array3::from_elem((1, 16, 16), 100.0);
    let input = write_planes(
        dir.path(),
        "flat.png",
        planes,
        Channels::Gray,
        SampleDepth::U8,
    );
    for mode in ["edge", "reflect", "wrap"] {
        let out = dir.path().join(format!("{mode}.png"));
        let got = run(
            "rotate",
            &input,
            &out,
            &["--angle", "30", "--boundary", mode],
        );
        assert!(got.plane(0).iter().all(|&v| v == 100.0), "{mode}");
    }
}

/// Cubic convolution with parameter `a` (Keys 1981): the weight of a sample at distance `t`.
fn keys(a: f64, t: f64) -> f64 {
    let t = t.abs();
    if t <= 1.0 {
        (a + 2.0) * t.powi(3) - (a + 3.0) * t * t + 1.0
    } else if t < 2.0 {
        a * t.powi(3) - 5.0 * a * t * t + 8.0 * a * t - 4.0 * a
    } else {
        0.0
    }
}

/// `--keys-a A`: a shift by 0.3 columns is `out[n] = sum_k x[k] w_A(n - 0.3 - k)` (wrap); the
/// default a = -0.5 differs by about 0.03 per unit of curvature.
#[test]
fn keys_a_sets_the_cubic_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let (h, w) = (3, 16);
    let x = Array2::from_shape_fn((h, w), |(r, c)| ((c * c * 5 + r * 11) % 97) as f64 + 0.25);
    let input = write_planes(
        dir.path(),
        "x.npy",
        x.clone().into_shape_with_order((1, h, w)).unwrap(),
        Channels::Gray,
        SampleDepth::F64,
    );
    for a in [-0.75, -1.0] {
        let out = dir.path().join(format!("keys{a}.npy"));
        let flags = [
            "--dx",
            "0.3",
            "--method",
            "keys",
            "--keys-a",
            &a.to_string(),
        ];
        let got = run("shift", &input, &out, &flags);
        let mut default_differs = false;
        for r in 0..h {
            for n in 0..w {
                let pos = n as f64 - 0.3;
                let value = |a: f64| -> f64 {
                    (-3..=3)
                        .map(|d| {
                            let k = pos.floor() as isize + d;
                            x[[r, k.rem_euclid(w as isize) as usize]] * keys(a, pos - k as f64)
                        })
                        .sum()
                };
                let (want, default) = (value(a), value(-0.5));
                let v = got.plane(0)[[r, n]];
                assert!((v - want).abs() < 1e-9, "a={a} ({r}, {n}): {v} vs {want}");
                default_differs |= (default - want).abs() > 1e-3;
            }
        }
        assert!(default_differs, "a={a}: the default would pass");
    }
}

/// `rotate --depth u16` from a float image: a quarter turn (an exact copy) written as a 16-bit
/// PNG holds each value rounded to the nearest 16-bit code (8 bits would clamp everything
/// above 255).
#[test]
fn depth_u16_writes_sixteen_bit_codes() {
    let dir = tempfile::tempdir().unwrap();
    let (h, w) = (8, 8);
    let x = Array2::from_shape_fn((h, w), |(r, c)| 300.4 + 811.3 * (r * w + c) as f64);
    let input = write_planes(
        dir.path(),
        "x.npy",
        x.clone().into_shape_with_order((1, h, w)).unwrap(),
        Channels::Gray,
        SampleDepth::F64,
    );
    let out = dir.path().join("x.png");
    let got = run("rotate", &input, &out, &["--angle", "90", "--depth", "u16"]);
    assert_eq!(got.depth(), SampleDepth::U16);
    // Counter-clockwise as displayed: out[r][c] = x[c][w - 1 - r].
    let want = Array2::from_shape_fn((w, h), |(r, c)| x[[c, w - 1 - r]].round());
    assert_eq!(got.plane(0), want);
    assert!(want.iter().all(|&v| v > 255.0 && v % 257.0 != 0.0));
}

/// `rotate --depth u16` from an 8-bit image: the rotation is rounded once, to 16-bit codes,
/// not to 8-bit codes then multiplied by 257. It equals 257 x the unrounded rotation (written
/// as f32) rounded, within one code for f32 arithmetic; rounding to 8 bits first would give
/// only multiples of 257.
#[test]
fn depth_u16_from_eight_bits_keeps_the_finer_codes() {
    let dir = tempfile::tempdir().unwrap();
    let planes = irregular().insert_axis(ndarray::Axis(0));
    let input = write_planes(dir.path(), "i.png", planes, Channels::Gray, SampleDepth::U8);
    let flags = ["--angle", "30", "--method", "linear"];
    let wide = run(
        "rotate",
        &input,
        &dir.path().join("w.png"),
        &[&flags[..], &["--depth", "u16"]].concat(),
    );
    let exact = run(
        "rotate",
        &input,
        &dir.path().join("e.npy"),
        &[&flags[..], &["--depth", "f32"]].concat(),
    );
    assert_eq!(wide.depth(), SampleDepth::U16);
    assert_eq!(wide.plane(0).dim(), exact.plane(0).dim());
    let mut finer = 0;
    for (&w, &e) in wide.plane(0).iter().zip(exact.plane(0).iter()) {
        assert!(
            (w - (e * 257.0).round()).abs() <= 1.0,
            "{w} against {}",
            e * 257.0
        );
        finer += usize::from(w % 257.0 != 0.0);
    }
    assert!(finer > 20, "only {finer} pixels off the 8-bit codes");
}

/// The nearest half float of `v` (round to nearest even), from the format: 11 significant
/// bits for normal values.
fn to_f16(v: f64) -> f64 {
    if v == 0.0 {
        return 0.0;
    }
    let e = v.abs().log2().floor().max(-14.0);
    let ulp = 2f64.powf(e - 10.0);
    let q = v / ulp;
    let r = q.round();
    // Ties to even.
    let r = if (q - q.trunc()).abs() == 0.5 && r % 2.0 != 0.0 {
        r - q.signum()
    } else {
        r
    };
    r * ulp
}

/// `--depth f16` to EXR: the rotated values (as `--depth f32` writes them) rounded to half
/// floats; an f32 file would keep bits that a half float cannot hold.
#[test]
fn depth_f16_writes_half_floats() {
    let dir = tempfile::tempdir().unwrap();
    let (h, w) = (12, 12);
    let x = Array2::from_shape_fn((h, w), |(r, c)| {
        0.1 + 0.0371 * ((r * 13 + c * 7) % 29) as f64
    });
    let input = write_planes(
        dir.path(),
        "x.npy",
        x.into_shape_with_order((1, h, w)).unwrap(),
        Channels::Gray,
        SampleDepth::F32,
    );
    let flags = |depth| ["--angle", "20", "--method", "keys", "--depth", depth];
    let full = run("rotate", &input, &dir.path().join("f32.exr"), &flags("f32"));
    let half = run("rotate", &input, &dir.path().join("f16.exr"), &flags("f16"));
    assert_eq!(full.depth(), SampleDepth::F32);
    assert_eq!(half.depth(), SampleDepth::F16);
    let mut changed = 0;
    for (&f, &g) in full.plane(0).iter().zip(half.plane(0)) {
        assert_eq!(g, to_f16(f), "{f}");
        changed += usize::from(g != f);
    }
    assert!(changed > h * w / 2, "{changed} values changed by rounding");
}

/// RGBA shifts move every plane, alpha included, as it is: a whole Haar shift rolls all four
/// planes; a half-pixel linear shift blends each plane with its neighbour on its own (no
/// premultiplication), as the command's help says.
#[test]
fn rgba_shifts_move_every_plane() {
    let dir = tempfile::tempdir().unwrap();
    let (h, w) = (8, 16);
    let planes = Array3::from_shape_fn((4, h, w), |(k, r, c)| {
        ((k * 61 + r * 29 + c * 17 + r * c) % 256) as f64
    });
    let input = write_planes(
        dir.path(),
        "x.png",
        planes.clone(),
        Channels::Rgba,
        SampleDepth::U8,
    );
    let rolled = run(
        "shift",
        &input,
        &dir.path().join("roll.png"),
        &["--dx", "3", "--dy", "-2"],
    );
    assert_eq!(rolled.channels(), Channels::Rgba);
    let want = Array3::from_shape_fn((4, h, w), |(k, r, c)| {
        planes[[k, (r + 2) % h, (c + w - 3) % w]]
    });
    assert_eq!(rolled.planes(), want);

    let flags = ["--dx", "0.5", "--method", "linear", "--boundary", "wrap"];
    let half = run("shift", &input, &dir.path().join("half.npy"), &flags);
    // A PNG output rounds; .npy keeps the float values.
    let want = Array3::from_shape_fn((4, h, w), |(k, r, c)| {
        (planes[[k, r, c]] + planes[[k, r, (c + w - 1) % w]]) / 2.0
    });
    assert_eq!(half.planes(), want);
}

/// Gray+alpha rotations are premultiplied like RGBA: a visible pixel keeps the gray of the
/// opaque half, nothing of the transparent half's gray (30) bleeds in, and the alpha is the
/// rotated alpha.
#[test]
fn gray_alpha_rotation_does_not_bleed_from_transparent_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let (h, w) = (24, 24);
    let planes = Array3::from_shape_fn((2, h, w), |(k, _, c)| match (k, c < w / 2) {
        (0, true) => 200.0,
        (0, false) => 30.0,
        (_, true) => 255.0,
        (_, false) => 0.0,
    });
    let input = write_planes(
        dir.path(),
        "ga.png",
        planes,
        Channels::GrayAlpha,
        SampleDepth::U8,
    );
    let got = run(
        "rotate",
        &input,
        &dir.path().join("out.png"),
        &["--angle", "20", "--method", "linear"],
    );
    assert_eq!(got.channels(), Channels::GrayAlpha);
    let (mut visible, mut partial) = (0, 0);
    for ((r, c), &a) in got.plane(1).indexed_iter() {
        if a > 0.0 {
            visible += 1;
            partial += usize::from(a < 255.0);
            assert_eq!(got.plane(0)[[r, c]], 200.0, "gray at ({r}, {c}), alpha {a}");
        }
    }
    assert!(
        visible > h * w / 4 && partial > h,
        "{visible} visible, {partial} partly"
    );
}
