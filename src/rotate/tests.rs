use ndarray::{Array2, Array3, array, s};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;
use crate::kernels::ShiftMethod;
use crate::{Channels, SampleDepth};

/// `plane` turned counter-clockwise (as displayed) by `turns` quarter turns, by index
/// arithmetic: one turn sends pixel `(r, c)` of an `h x w` plane to `(w - 1 - c, r)` of a
/// `w x h` one.
fn turned<A: Copy>(plane: ArrayView2<'_, A>, turns: u8) -> Array2<A> {
    let mut out = plane.to_owned();
    for _ in 0..turns % 4 {
        let (_, w) = out.dim();
        let next = Array2::from_shape_fn((w, out.nrows()), |(i, j)| out[[j, w - 1 - i]]);
        out = next;
    }
    out
}

/// The quarter turns in `deg`, a multiple of 90.
fn turns_in(deg: f64) -> u8 {
    (deg / 90.0).rem_euclid(4.0) as u8
}

fn random_plane(h: usize, w: usize, seed: u64) -> Array2<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    Array2::from_shape_fn((h, w), |_| rng.random_range(-1.0..1.0))
}

/// A smooth, effectively band-limited test image: a few Gaussians (sigma 4 to 5 pixels) around
/// the centre, below 1e-10 at the edges of a 96x96 image.
fn smooth_plane(h: usize, w: usize) -> Array2<f64> {
    let blobs = [
        (0.45, 0.5, 5.0, 1.0),
        (0.55, 0.56, 4.0, -0.7),
        (0.5, 0.42, 4.5, 0.5),
    ];
    Array2::from_shape_fn((h, w), |(r, c)| {
        blobs
            .iter()
            .map(|&(fr, fc, sigma, amp)| {
                let (dr, dc) = (r as f64 - fr * h as f64, c as f64 - fc * w as f64);
                amp * (-(dr * dr + dc * dc) / (2.0 * sigma * sigma)).exp()
            })
            .sum()
    })
}

fn options(canvas: Canvas, outside: Outside) -> RotateOptions {
    RotateOptions {
        canvas,
        outside,
        ..Default::default()
    }
}

/// Largest `|a - b|` over pixels within `radius` of the centre.
fn interior_error(a: &Array2<f64>, b: &Array2<f64>, radius: f64) -> f64 {
    assert_eq!(a.dim(), b.dim());
    let (h, w) = a.dim();
    let (cy, cx) = ((h as f64 - 1.0) / 2.0, (w as f64 - 1.0) / 2.0);
    let mut err: f64 = 0.0;
    for ((r, c), v) in a.indexed_iter() {
        if (r as f64 - cy).hypot(c as f64 - cx) <= radius {
            err = err.max((v - b[[r, c]]).abs());
        }
    }
    err
}

#[test]
fn angles_reduce_exactly() {
    let cases = [
        (45.0, 0, 45.0),
        (-45.0, 0, -45.0),
        (135.0, 2, -45.0),
        (1e6, 3, 10.0),
        (-180.0, 2, 0.0),
        (90.0, 1, 0.0),
        (-90.0, 3, 0.0),
        (270.0, 3, 0.0),
        (720.5, 0, 0.5),
        (-1e6, 1, -10.0),
    ];
    for (deg, q, residual) in cases {
        let r = reduce_angle(deg).unwrap();
        assert_eq!((r.quarter_turns, r.residual_deg), (q, residual), "{deg}");
    }
    let r = reduce_angle(359.999).unwrap();
    assert_eq!(r.quarter_turns, 0);
    assert_eq!(r.residual_deg, 359.999 - 360.0);
    assert!((r.residual_deg + 0.001).abs() < 1e-12);
    let r = reduce_angle(1e300).unwrap();
    assert!(r.residual_deg.abs() <= 45.0 && r.quarter_turns < 4);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_err!(
            reduce_angle(bad),
            InvalidParameter { name: "angle", .. },
            "not a finite number of degrees"
        );
    }
}

#[test]
fn multiples_of_90_degrees_are_bit_exact_for_every_kernel() {
    let square = random_plane(13, 13, 1);
    let even_gap = random_plane(12, 16, 2);
    let odd_gap = random_plane(9, 14, 3);
    for method in ShiftMethod::ALL {
        let k = method.kernel::<f64>();
        for deg in [0.0, 90.0, 180.0, 270.0, -90.0, 450.0, -720.0] {
            let turns = turns_in(deg);
            for outside in [Outside::Fill(0.0), Outside::Boundary(BoundaryMode::Reflect)] {
                // Expand: the quarter-turned array itself, any shape.
                for p in [&square, &even_gap, &odd_gap] {
                    let r =
                        rotate_plane(p.view(), deg, k.as_ref(), &options(Canvas::Expand, outside));
                    assert_eq!(r.unwrap(), turned(p.view(), turns), "{method} {deg}");
                }
                // Same canvas: exact when the centre stays on the grid.
                let r = rotate_plane(
                    square.view(),
                    deg,
                    k.as_ref(),
                    &options(Canvas::Same, outside),
                );
                assert_eq!(r.unwrap(), turned(square.view(), turns), "{method} {deg}");
                let r = rotate_plane(
                    even_gap.view(),
                    deg,
                    k.as_ref(),
                    &options(Canvas::Same, outside),
                )
                .unwrap();
                let want = turned(even_gap.view(), turns);
                let (h, w) = want.dim();
                let (oh, ow) = (h.saturating_sub(12) / 2, w.saturating_sub(16) / 2);
                let (ih, iw) = (12usize.saturating_sub(h) / 2, 16usize.saturating_sub(w) / 2);
                let (ch, cw) = (h.min(12), w.min(16));
                assert_eq!(
                    r.slice(s![ih..ih + ch, iw..iw + cw]),
                    want.slice(s![oh..oh + ch, ow..ow + cw]),
                    "{method} {deg}"
                );
            }
        }
    }
}

#[test]
fn rotation_is_counter_clockwise_about_the_centre() {
    // A small Gaussian blob: its centroid must land where R(theta) sends it, with y up.
    let (h, w) = (48, 64);
    let (r0, c0) = (14.0, 40.0);
    let blob = Array2::from_shape_fn((h, w), |(r, c)| {
        let d2 = (r as f64 - r0).powi(2) + (c as f64 - c0).powi(2);
        (-d2 / 8.0).exp()
    });
    let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    for method in [ShiftMethod::Keys, ShiftMethod::BSpline5, ShiftMethod::Fft] {
        for deg in [30.0, -20.0, 100.0, 200.0] {
            let k = method.kernel::<f64>();
            let out =
                rotate_plane(blob.view(), deg, k.as_ref(), &RotateOptions::default()).unwrap();
            let total: f64 = out.sum();
            let (mut mr, mut mc) = (0.0, 0.0);
            for ((r, c), v) in out.indexed_iter() {
                mr += r as f64 * v;
                mc += c as f64 * v;
            }
            let t = f64::to_radians(deg);
            let (x, y) = (c0 - cx, cy - r0);
            let (x1, y1) = (x * t.cos() - y * t.sin(), x * t.sin() + y * t.cos());
            let (er, ec) = (cy - y1, x1 + cx);
            assert!(
                (mr / total - er).abs() < 2e-7 && (mc / total - ec).abs() < 2e-7,
                "{method} {deg}: centroid ({}, {}) expected ({er}, {ec})",
                mr / total,
                mc / total
            );
            assert!((total - blob.sum()).abs() < 1e-8 * blob.sum());
        }
    }
}

#[test]
fn rotating_back_restores_the_interior() {
    // On a smooth image of peak ~1, within 25 px of the centre of 96x96. Measured worst:
    // fft 3.2e-15, quintic B-spline 1.03e-6; bounds 6x and 4x.
    let p = smooth_plane(96, 96);
    for (method, tol) in [(ShiftMethod::Fft, 2e-14), (ShiftMethod::BSpline5, 4e-6)] {
        let k = method.kernel::<f64>();
        for deg in [17.0, 44.0, 73.0] {
            let opts = RotateOptions::default();
            let there = rotate_plane(p.view(), deg, k.as_ref(), &opts).unwrap();
            let back = rotate_plane(there.view(), -deg, k.as_ref(), &opts).unwrap();
            let err = interior_error(&back, &p, 25.0);
            assert!(err < tol, "{method} {deg}: {err}");
        }
    }
}

#[test]
fn constant_images_stay_constant() {
    let value = 3.5;
    for (h, w) in [(100, 100), (91, 120)] {
        let p = Array2::from_elem((h, w), value);
        for method in ShiftMethod::ALL {
            let k = method.kernel::<f64>();
            for canvas in Canvas::ALL {
                for deg in [17.0, -33.0, 44.9, 123.0] {
                    // Everywhere, when the outside continues the constant.
                    for outside in [Outside::Fill(value), Outside::Boundary(BoundaryMode::Edge)] {
                        let r = rotate_plane(p.view(), deg, k.as_ref(), &options(*canvas, outside))
                            .unwrap();
                        let err = r.iter().map(|v| (v - value).abs()).fold(0.0, f64::max);
                        // Measured at most 1.1e-14 (7 ulps of 3.5); bound 5x.
                        assert!(err < 5e-14, "{method} {canvas} {deg} {outside:?}: {err}");
                    }
                    // In the interior with a zero outside, 30 px from the edge step, where the
                    // splines' IIR tails (|z| = 0.43 for the quintic) are small: measured at most
                    // 3.8e-11 (quintic), bound 5x (the FFT's sinc rings from the step like
                    // 1/distance, so it is held only above).
                    if *method != ShiftMethod::Fft {
                        let opts = options(*canvas, Outside::Fill(0.0));
                        let r = rotate_plane(p.view(), deg, k.as_ref(), &opts).unwrap();
                        let (rh, rw) = r.dim();
                        let expected = Array2::from_elem((rh, rw), value);
                        let radius = (h.min(w) as f64) / 2.0 - 30.0;
                        let err = interior_error(&r, &expected, radius);
                        assert!(err < 2e-10, "{method} {canvas} {deg}: {err}");
                    }
                }
            }
        }
    }
}

#[test]
fn expand_canvas_has_the_documented_size_and_holds_everything() {
    for (h, w, deg) in [
        (100, 100, 45.0),
        (30, 50, 90.0),
        (31, 47, 20.0),
        (31, 47, -110.0),
    ] {
        let t = f64::to_radians(deg);
        let (s, c) = (t.sin().abs(), t.cos().abs());
        let expected = (
            (w as f64 * s + h as f64 * c + 0.5).floor() as usize,
            (w as f64 * c + h as f64 * s + 0.5).floor() as usize,
        );
        assert_eq!(expanded_size(h, w, deg).unwrap(), expected, "{h}x{w} {deg}");
        let ones = Array2::<f64>::ones((h, w));
        let k = ShiftMethod::Linear.kernel::<f64>();
        let r = rotate_plane(
            ones.view(),
            deg,
            k.as_ref(),
            &options(Canvas::Expand, Outside::Fill(0.0)),
        )
        .unwrap();
        assert_eq!(r.dim(), expected);
        // Nothing lost: linear interpolation keeps the mass of what stays on the canvas, and
        // only the corner pixels' half-pixel spread may fall off (measured at most 0.72, at
        // 45 degrees; the bound of one pixel is that spread).
        assert!(
            (r.sum() - ones.sum()).abs() < 1.0,
            "{h}x{w} {deg}: {}",
            r.sum()
        );
        // And the canvas is tight: content reaches its first and last rows and columns.
        let (rh, rw) = r.dim();
        for line in [r.row(0), r.row(rh - 1), r.column(0), r.column(rw - 1)] {
            assert!(line.iter().any(|v| *v > 0.05), "{h}x{w} {deg}");
        }
    }
}

#[test]
fn tiny_and_degenerate_images() {
    let k = ShiftMethod::BSpline3.kernel::<f64>();
    let one = array![[2.5]];
    for deg in [30.0, 90.0, 1e6, -44.0] {
        let r = rotate_plane(one.view(), deg, k.as_ref(), &RotateOptions::default()).unwrap();
        assert_eq!(r, one);
    }
    let row = Array2::from_shape_fn((1, 9), |(_, c)| c as f64);
    let r = rotate_plane(
        row.view(),
        90.0,
        k.as_ref(),
        &options(Canvas::Expand, Outside::Fill(0.0)),
    )
    .unwrap();
    assert_eq!(r.dim(), (9, 1));
    assert_eq!(r[[0, 0]], 8.0);
    let r = rotate_plane(row.view(), 30.0, k.as_ref(), &RotateOptions::default()).unwrap();
    assert_eq!(r.dim(), (1, 9));
    assert_eq!(r[[0, 4]], 4.0, "the centre pixel stays");
    let empty = Array2::<f64>::zeros((0, 4));
    assert_err!(
        rotate_plane(empty.view(), 10.0, k.as_ref(), &RotateOptions::default()),
        InvalidShape { .. },
        "image is empty"
    );
    let nan = array![[1.0, f64::NAN]];
    assert_err!(
        rotate_plane(nan.view(), 10.0, k.as_ref(), &RotateOptions::default()),
        NonFinite { .. },
        "index [0, 1]"
    );
    assert_err!(
        rotate_plane(one.view(), f64::NAN, k.as_ref(), &RotateOptions::default()),
        InvalidParameter { name: "angle", .. },
        "NaN"
    );
    let bad_fill = options(Canvas::Same, Outside::Fill(f64::INFINITY));
    assert_err!(
        rotate_plane(one.view(), 10.0, k.as_ref(), &bad_fill),
        InvalidParameter { name: "fill", .. },
        "inf"
    );
}

#[test]
fn huge_angles_equal_their_reduction() {
    let p = random_plane(17, 23, 5);
    let k = ShiftMethod::BSpline3.kernel::<f64>();
    let opts = options(Canvas::Expand, Outside::Fill(0.0));
    let a = rotate_plane(p.view(), 1e6, k.as_ref(), &opts).unwrap();
    let b = rotate_plane(p.view(), 280.0, k.as_ref(), &opts).unwrap();
    assert_eq!(a, b);
}

#[test]
fn supersampling_is_validated_and_exact_on_quarter_turns() {
    let p = random_plane(6, 10, 6);
    let k = ShiftMethod::Lanczos3.kernel::<f64>();
    let opts = RotateOptions {
        supersample: 2,
        canvas: Canvas::Expand,
        ..Default::default()
    };
    let r = rotate_plane(p.view(), 270.0, k.as_ref(), &opts).unwrap();
    assert_eq!(r, turned(p.view(), 3));
    // Supersampled nearest neighbour is close to a finer rotation: the error against the
    // plain bspline5 rotation of a smooth image shrinks as S grows.
    let smooth = smooth_plane(40, 40);
    let reference = rotate_plane(
        smooth.view(),
        25.0,
        ShiftMethod::BSpline5.kernel::<f64>().as_ref(),
        &RotateOptions::default(),
    )
    .unwrap();
    let nearest = ShiftMethod::Nearest.kernel::<f64>();
    let errors: Vec<f64> = (0..3)
        .map(|s| {
            let o = RotateOptions {
                supersample: s,
                ..Default::default()
            };
            let r = rotate_plane(smooth.view(), 25.0, nearest.as_ref(), &o).unwrap();
            interior_error(&r, &reference, 12.0)
        })
        .collect();
    assert!(errors[2] < errors[1] && errors[1] < errors[0], "{errors:?}");
    let too_fine = RotateOptions {
        supersample: MAX_SUPERSAMPLE + 1,
        ..Default::default()
    };
    assert_err!(
        rotate_plane(p.view(), 10.0, k.as_ref(), &too_fine),
        InvalidParameter {
            name: "supersample",
            ..
        },
        "at most 8"
    );
    let small_budget = RotateOptions {
        memory_budget: 1000,
        ..Default::default()
    };
    let err = rotate_plane(p.view(), 10.0, k.as_ref(), &small_budget).unwrap_err();
    assert!(matches!(err, Error::MemoryBudget { .. }), "{err}");
}

#[test]
fn chain_matches_single_rotations_and_keeps_the_fine_grid() {
    let p = smooth_plane(24, 24);
    let k = ShiftMethod::Keys.kernel::<f64>();
    let opts = RotateOptions::default();
    let mut chain = RotationChain::new(p.view(), k.as_ref(), opts).unwrap();
    chain.rotate(20.0).unwrap();
    assert_eq!(
        chain.working().to_owned(),
        rotate_plane(p.view(), 20.0, k.as_ref(), &opts).unwrap()
    );
    let fine = RotateOptions {
        supersample: 1,
        ..opts
    };
    let mut chain = RotationChain::new(p.view(), k.as_ref(), fine).unwrap();
    chain.rotate(20.0).unwrap().rotate(-20.0).unwrap();
    assert_eq!(chain.working().dim(), (48, 48));
    let back = chain.finish();
    // Measured 4.5e-3 (two keys resamplings of a random image on the 2x grid); bound 1.1x.
    assert!(interior_error(&back, &p, 6.0) < 5e-3);
}

#[test]
fn rgba_rotates_without_colour_bleeding_and_round_trips() {
    // Left half opaque red, right half fully transparent with garbage green.
    let (h, w) = (20, 20);
    let mut planes = Array3::<f32>::zeros((4, h, w));
    for r in 0..h {
        for c in 0..w {
            let opaque = c < w / 2;
            planes[[0, r, c]] = if opaque { 255.0 } else { 0.0 };
            planes[[1, r, c]] = if opaque { 0.0 } else { 255.0 };
            planes[[3, r, c]] = if opaque { 255.0 } else { 0.0 };
        }
    }
    let img = PlanarImage::new(planes, Channels::Rgba, SampleDepth::U8).unwrap();
    let k = ShiftMethod::Linear.kernel::<f32>();
    let r = rotate_image(&img, 10.0, k.as_ref(), &RotateOptions::default()).unwrap();
    let alpha = r.plane(3);
    let mut partial = 0;
    for ((row, col), &a) in alpha.indexed_iter() {
        if a >= 1.0 {
            assert_eq!(
                r.plane(0)[[row, col]],
                255.0,
                "red at ({row}, {col}), alpha {a}"
            );
            assert_eq!(
                r.plane(1)[[row, col]],
                0.0,
                "no green bleeds in at ({row}, {col})"
            );
            partial += usize::from(a < 255.0);
        }
    }
    assert!(partial > 10, "the edge has partially transparent pixels");
    // Quarter turns are exact, and a turn and back keeps opaque pixels within one code value.
    let q = rotate_image(&img, 90.0, k.as_ref(), &RotateOptions::default()).unwrap();
    for c in 0..4 {
        assert_eq!(q.plane(c), turned(img.plane(c), 1));
    }
    let k5 = ShiftMethod::BSpline5.kernel::<f32>();
    let mut rng = StdRng::seed_from_u64(9);
    let smooth = smooth_plane(32, 32);
    let planes = Array3::from_shape_fn((4, 32, 32), |(c, r, col)| {
        if c == 3 {
            255.0
        } else {
            (128.0 + 100.0 * smooth[[r, col]] + rng.random_range(-2.0..2.0)).round() as f32
        }
    });
    let img = PlanarImage::new(planes, Channels::Rgba, SampleDepth::U8).unwrap();
    let there = rotate_image(&img, 12.0, k5.as_ref(), &RotateOptions::default()).unwrap();
    let back = rotate_image(&there, -12.0, k5.as_ref(), &RotateOptions::default()).unwrap();
    for c in 0..4 {
        let a = back.plane(c).mapv(f64::from);
        let b = img.plane(c).mapv(f64::from);
        let err = interior_error(&a, &b, 9.0);
        // Measured 2, 2, 2 and 0 code values; bound 1.5x.
        assert!(err <= 3.0, "channel {c}: {err}");
    }
}

#[test]
fn sixteen_bit_images_round_trip() {
    let smooth = smooth_plane(32, 40);
    let plane = smooth.mapv(|v| (30000.0 + 30000.0 * v).round().clamp(0.0, 65535.0));
    let img = PlanarImage::from_gray(plane.clone(), SampleDepth::U16).unwrap();
    let k = ShiftMethod::BSpline3.kernel::<f64>();
    let opts = options(Canvas::Expand, Outside::Fill(0.0));
    for (deg, turns) in [(90.0, 1), (180.0, 2), (270.0, 3)] {
        let r = rotate_image(&img, deg, k.as_ref(), &opts).unwrap();
        assert_eq!(r.plane(0), turned(plane.view(), turns));
        assert_eq!(r.depth(), SampleDepth::U16);
    }
    let there = rotate_image(&img, 21.0, k.as_ref(), &RotateOptions::default()).unwrap();
    assert!(
        there
            .plane(0)
            .iter()
            .all(|v| v.fract() == 0.0 && (0.0..=65535.0).contains(v))
    );
    let back = rotate_image(&there, -21.0, k.as_ref(), &RotateOptions::default()).unwrap();
    let err = interior_error(&back.plane(0).to_owned(), &plane, 9.0);
    // Measured 4 code values; bound 2x.
    assert!(err <= 8.0, "{err} code values of 65535");
}

/// Alpha at a float depth under every boundary mode: colour is premultiplied by alpha, the
/// planes rotated alone, and divided by the rotated alpha (the definition in `rotate_image`'s
/// docs), with no rounding to codes. Skipping the premultiplication moves colour by far more
/// than the bound (the alpha here varies from 0.2 to 1), and rounding would show on the
/// non-integer values.
#[test]
fn float_alpha_is_premultiplied_under_every_boundary_mode() {
    use crate::boundary::BoundaryMode;
    use ndarray::Axis;
    let (h, w) = (14, 17);
    let mut rng = StdRng::seed_from_u64(41);
    let mut planes = Array3::<f64>::zeros((4, h, w));
    for r in 0..h {
        for c in 0..w {
            for ch in 0..3 {
                planes[[ch, r, c]] = rng.random::<f64>();
            }
            planes[[3, r, c]] = 0.2 + 0.8 * ((r * w + c) % 7) as f64 / 6.0;
        }
    }
    let img = PlanarImage::new(planes.clone(), Channels::Rgba, SampleDepth::F32).unwrap();
    let k = ShiftMethod::Keys.kernel::<f64>();
    for &mode in BoundaryMode::ALL {
        let opts = RotateOptions {
            outside: Outside::Boundary(mode),
            ..Default::default()
        };
        let got = rotate_image(&img, 23.0, k.as_ref(), &opts).unwrap();
        assert_eq!(got.depth(), SampleDepth::F32);
        let alpha = rotate_plane(planes.index_axis(Axis(0), 3), 23.0, k.as_ref(), &opts).unwrap();
        assert_eq!(got.plane(3), alpha, "{mode}: alpha is rotated as a plane");
        let mut fractional = 0;
        for ch in 0..3 {
            let premultiplied = &planes.index_axis(Axis(0), ch) * &planes.index_axis(Axis(0), 3);
            let rotated = rotate_plane(premultiplied.view(), 23.0, k.as_ref(), &opts).unwrap();
            for ((rc, &v), (&p, &a)) in got
                .plane(ch)
                .indexed_iter()
                .zip(rotated.iter().zip(alpha.iter()))
            {
                let want = if a > 1e-6 { p / a } else { 0.0 };
                // Same operations in the same order: equal to rounding.
                assert!(
                    (v - want).abs() <= 1e-12 * want.abs().max(1.0),
                    "{mode} {ch} {rc:?}: {v} vs {want}"
                );
                fractional += usize::from(v.fract() != 0.0);
            }
        }
        assert!(fractional > h * w, "{mode}: float samples are not rounded");
    }
}
