//! Every kernel's row shift against a brute-force evaluation of its defining formula.

use ndarray::{Array2, array};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;

/// The outside rules every oracle runs under.
const RULES: [Outside; 5] = [
    Outside::Fill(0.7),
    Outside::Boundary(BoundaryMode::Zero),
    Outside::Boundary(BoundaryMode::Edge),
    Outside::Boundary(BoundaryMode::Reflect),
    Outside::Boundary(BoundaryMode::Wrap),
];

fn random_row(rng: &mut StdRng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

/// Runs `kernel` on random rows, shifts and rules and compares with `oracle(row, shift, rule,
/// len_out)` to `tol`.
fn check_against_oracle(
    kernel: &dyn ShearKernel<f64>,
    mut oracle: impl FnMut(&[f64], f64, Outside, usize) -> Vec<f64>,
    tol: f64,
) {
    let mut rng = StdRng::seed_from_u64(4);
    for trial in 0..40 {
        let len_in = rng.random_range(1..24);
        let len_out = rng.random_range(1..30);
        let row = random_row(&mut rng, len_in);
        let shift = rng.random_range(-8.0..8.0);
        let rule = RULES[trial % RULES.len()];
        let geometry = RowGeometry {
            len_in,
            len_out,
            min_shift: shift,
            max_shift: shift,
        };
        let mut out = vec![0.0; len_out];
        kernel
            .row_shifter(geometry, rule)
            .shift_row(&row, shift, &mut out)
            .unwrap();
        let expected = oracle(&row, shift, rule, len_out);
        for (n, (o, e)) in out.iter().zip(&expected).enumerate() {
            assert!(
                (o - e).abs() <= tol,
                "{}: n={n} shift={shift} {rule:?} len {len_in}->{len_out}: {o} vs {e}",
                kernel.name()
            );
        }
    }
}

/// `sum_i ext(i) k(x - i)` over the `taps` samples around `x`, optionally normalised.
fn direct_convolution(
    row: &[f64],
    x: f64,
    rule: Outside,
    radius: isize,
    k: impl Fn(f64) -> f64,
    normalise: bool,
) -> f64 {
    let i0 = x.floor() as isize;
    let (mut sum, mut weight) = (0.0, 0.0);
    for i in i0 - radius + 1..=i0 + radius {
        let w = k(x - i as f64);
        sum += w * rule.sample(row, i);
        weight += w;
    }
    if normalise { sum / weight } else { sum }
}

#[test]
fn nearest_is_the_rounded_sample() {
    check_against_oracle(
        &Nearest,
        |row, s, rule, len| {
            (0..len)
                .map(|n| rule.sample(row, (n as f64 - s + 0.5).floor() as isize))
                .collect()
        },
        0.0,
    );
}

#[test]
fn linear_is_the_two_point_interpolation() {
    check_against_oracle(
        &Linear,
        |row, s, rule, len| {
            (0..len)
                .map(|n| {
                    let x = n as f64 - s;
                    let i = x.floor();
                    let t = x - i;
                    (1.0 - t) * rule.sample(row, i as isize) + t * rule.sample(row, i as isize + 1)
                })
                .collect()
        },
        1e-14,
    );
}

/// Keys (1981), equation (15), written out term by term.
fn keys_reference(a: f64, s: f64) -> f64 {
    let s = s.abs();
    if s < 1.0 {
        (a + 2.0) * s.powi(3) - (a + 3.0) * s.powi(2) + 1.0
    } else if s < 2.0 {
        a * s.powi(3) - 5.0 * a * s.powi(2) + 8.0 * a * s - 4.0 * a
    } else {
        0.0
    }
}

#[test]
fn keys_is_the_piecewise_cubic_convolution() {
    for a in [-0.5, -0.75, -1.0] {
        let kernel = Keys::new(a).unwrap();
        check_against_oracle(
            &kernel,
            |row, s, rule, len| {
                (0..len)
                    .map(|n| {
                        let x = n as f64 - s;
                        direct_convolution(row, x, rule, 2, |d| keys_reference(a, d), false)
                    })
                    .collect()
            },
            1e-13,
        );
    }
}

#[test]
fn lanczos_is_the_normalised_windowed_sinc() {
    for a in [3usize, 4] {
        let af = a as f64;
        let lanczos = |d: f64| {
            if d == 0.0 {
                1.0
            } else if d.abs() < af {
                let p = std::f64::consts::PI * d;
                p.sin() / p * (p / af).sin() / (p / af)
            } else {
                0.0
            }
        };
        check_against_oracle(
            &Lanczos::new(a),
            |row, s, rule, len| {
                (0..len)
                    .map(|n| {
                        let x = n as f64 - s;
                        direct_convolution(row, x, rule, a as isize, lanczos, true)
                    })
                    .collect()
            },
            1e-13,
        );
    }
}

/// The centred B-spline of degree `n` from its truncated-power definition:
/// `beta^n(x) = 1/n! sum_k (-1)^k C(n+1, k) max(0, x + (n+1)/2 - k)^n`.
/// Evaluated at `-|x|` (the spline is even) where fewer truncated powers are active, since
/// they cancel badly in floating point on the right; zero outside the support.
fn bspline_reference(n: usize, x: f64) -> f64 {
    if x.abs() >= (n as f64 + 1.0) / 2.0 {
        return 0.0;
    }
    let x = -x.abs();
    let mut binomial = 1.0;
    let mut factorial = 1.0;
    for i in 1..=n {
        factorial *= i as f64;
    }
    let mut sum = 0.0;
    for k in 0..=n + 1 {
        let t = x + (n as f64 + 1.0) / 2.0 - k as f64;
        if t > 0.0 {
            sum += if k % 2 == 0 { 1.0 } else { -1.0 } * binomial * t.powi(n as i32);
        }
        binomial = binomial * (n + 1 - k) as f64 / (k + 1) as f64;
    }
    sum / factorial
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting (dense, small).
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..n {
            let factor = a[row][col] / a[col][col];
            let (upper, lower) = a.split_at_mut(row);
            for (x, y) in lower[0][col..].iter_mut().zip(&upper[col][col..]) {
                *x -= factor * y;
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}

#[test]
fn bsplines_evaluate_the_densely_solved_interpolant() {
    for spline in [BSpline::cubic(), BSpline::quintic()] {
        let degree = spline.degree();
        for x in [-3.5, -2.2, -1.0, -0.3, 0.0, 0.7, 1.5, 2.9] {
            let (v, r) = (spline.value(x), bspline_reference(degree, x));
            assert!((v - r).abs() < 1e-14, "degree {degree} x {x}: {v} vs {r}");
        }
        check_against_oracle(
            &spline,
            |row, s, rule, len| {
                // Interpolation conditions on a window far wider than everything read, so the
                // truncated system's edge effects (decaying like |z|^distance) vanish.
                let margin = 120isize;
                let lo = -margin - 10;
                let hi = (row.len().max(len) as isize) + margin + 10;
                let positions: Vec<isize> = (lo..hi).collect();
                let matrix: Vec<Vec<f64>> = positions
                    .iter()
                    .map(|&i| {
                        let r = |k: &isize| bspline_reference(degree, (i - k) as f64);
                        positions.iter().map(r).collect()
                    })
                    .collect();
                let samples = positions.iter().map(|&i| rule.sample(row, i)).collect();
                let c = solve_dense(matrix, samples);
                (0..len)
                    .map(|n| {
                        let x = n as f64 - s;
                        positions
                            .iter()
                            .zip(&c)
                            .map(|(&k, ck)| ck * bspline_reference(degree, x - k as f64))
                            .sum()
                    })
                    .collect()
            },
            1e-11,
        );
    }
}

/// The smallest `2^a 3^b 5^c` at least `n`, by enumerating the products.
fn smallest_5_smooth(n: usize) -> usize {
    let mut best = usize::MAX;
    for a in 0..40 {
        for b in 0..25 {
            for c in 0..18 {
                let m = 2f64.powi(a) * 3f64.powi(b) * 5f64.powi(c);
                if m >= n as f64 && m < best as f64 {
                    best = m as usize;
                }
            }
        }
    }
    best
}

#[test]
fn fft_is_the_trigonometric_interpolant_of_the_padded_window_or_the_period() {
    let kernel = FftShift::<f64>::new();
    let mut seen_odd = false;
    let mut seen_even = false;
    check_against_oracle(
        &kernel,
        |row, s, rule, len| {
            let k = s.floor() as isize;
            let f = s - k as f64;
            // With wrap the window is the row itself (one period). Otherwise, as documented, it
            // covers the row (0..n), every position the output reads (n - k - f for n in
            // 0..len, so -k - 1 to len - 1 - k) and PAD more on each side, and its length is
            // the smallest 2^a 3^b 5^c that fits.
            let (lo, p) = if rule == Outside::Boundary(BoundaryMode::Wrap) {
                (0, row.len())
            } else {
                let pad = FftShift::<f64>::PAD as isize;
                let first = 0.min(-k - 1) - pad;
                let last = (row.len() as isize - 1).max(len as isize - 1 - k) + pad;
                (first, smallest_5_smooth((last - first + 1) as usize))
            };
            seen_odd |= !p.is_multiple_of(2);
            seen_even |= p.is_multiple_of(2);
            let x: Vec<f64> = (0..p as isize).map(|m| rule.sample(row, lo + m)).collect();
            // Direct DFT, then the interpolant y(t) = 1/P [sum_{|q|<P/2} X_q e^{2 pi i q t/P}
            // + X_{P/2} cos(pi t)] at t = m - f.
            let tau = 2.0 * std::f64::consts::PI / p as f64;
            let spectrum: Vec<(f64, f64)> = (0..p)
                .map(|q| {
                    x.iter().enumerate().fold((0.0, 0.0), |(re, im), (m, v)| {
                        let a = tau * (q * m) as f64;
                        (re + v * a.cos(), im - v * a.sin())
                    })
                })
                .collect();
            (0..len)
                .map(|n| {
                    let t = (n as isize - k - lo) as f64 - f;
                    let mut y = 0.0;
                    for (q, (re, im)) in spectrum.iter().enumerate() {
                        let signed = if 2 * q > p {
                            q as f64 - p as f64
                        } else {
                            q as f64
                        };
                        if 2 * q == p {
                            y += re * (std::f64::consts::PI * t).cos();
                        } else {
                            let a = tau * signed * t;
                            y += re * a.cos() - im * a.sin();
                        }
                    }
                    y / p as f64
                })
                .collect()
        },
        1e-11,
    );
    assert!(seen_odd && seen_even, "both FFT length parities exercised");
}

#[test]
fn f32_kernels_follow_f64_ones() {
    let mut rng = StdRng::seed_from_u64(7);
    let rows = Array2::from_shape_fn((6, 50), |_| rng.random_range(-1.0..1.0));
    let shifts = [0.3, -2.7, 5.5, 0.01, -0.99, 11.25];
    for method in ShiftMethod::ALL {
        let k64 = method.kernel::<f64>();
        let k32 = method.kernel::<f32>();
        let rule = Outside::Boundary(BoundaryMode::Reflect);
        let a = shear_rows(rows.view(), 60, &shifts, k64.as_ref(), rule).unwrap();
        let rows32 = rows.mapv(|v| v as f32);
        let b = shear_rows(rows32.view(), 60, &shifts, k32.as_ref(), rule).unwrap();
        let err = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - *y as f64).abs())
            .fold(0.0, f64::max);
        // Measured at most 3.1e-7 (quintic B-spline; about 5 f32 ulps at 1); bound 3x.
        assert!(err < 1e-6, "{method}: f32 differs from f64 by {err}");
    }
}

#[test]
fn integer_shifts_are_exact_copies_for_every_kernel() {
    let rows = array![[1.5f32, -2.25, 3.0, 7.125], [0.1, 0.2, 0.3, 0.4]];
    for method in ShiftMethod::ALL {
        let k = method.kernel::<f32>();
        let out = shear_rows(
            rows.view(),
            5,
            &[2.0, -1.0],
            k.as_ref(),
            Outside::Fill(-9.0),
        );
        let out = out.unwrap();
        assert_eq!(
            out,
            array![[-9.0, -9.0, 1.5, -2.25, 3.0], [0.2, 0.3, 0.4, -9.0, -9.0]],
            "{method}"
        );
    }
}

#[test]
fn shear_rows_rejects_bad_input() {
    let k = ShiftMethod::Linear.kernel::<f64>();
    let rows = array![[1.0, 2.0]];
    let run =
        |shifts: &[f64], len_out, rule| shear_rows(rows.view(), len_out, shifts, k.as_ref(), rule);
    assert_err!(
        run(&[f64::NAN], 2, Outside::Fill(0.0)),
        InvalidParameter { name: "shift", .. },
        "NaN is not a finite shift"
    );
    assert_err!(
        run(&[f64::INFINITY], 2, Outside::Fill(0.0)),
        InvalidParameter { name: "shift", .. },
        "inf is not a finite shift"
    );
    assert_err!(
        run(&[1e300], 2, Outside::Fill(0.0)),
        InvalidParameter { name: "shift", .. },
        "at most 1e15"
    );
    assert_err!(
        run(&[0.5, 0.5], 2, Outside::Fill(0.0)),
        InvalidShape { .. },
        "2 shifts for 1 rows"
    );
    assert_err!(
        run(&[0.5], 0, Outside::Fill(0.0)),
        InvalidShape { .. },
        "rows must not be empty"
    );
    assert_err!(
        run(&[0.5], 2, Outside::Fill(f64::NAN)),
        InvalidParameter { name: "fill", .. },
        "NaN"
    );
    let nan = array![[1.0, f64::NAN]];
    assert_err!(
        shear_rows(nan.view(), 2, &[0.5], k.as_ref(), Outside::Fill(0.0)),
        NonFinite { .. },
        "NaN at index [0, 1]"
    );
    // Far shifts are fine and give the outside.
    let far = run(&[1e12 + 0.5], 2, Outside::Fill(3.0)).unwrap();
    assert_eq!(far, array![[3.0, 3.0]]);
}

#[test]
fn shift_plane_is_a_row_then_column_shift() {
    let mut rng = StdRng::seed_from_u64(11);
    let plane = Array2::from_shape_fn((9, 13), |_| rng.random_range(0.0..1.0));
    for method in ShiftMethod::ALL {
        let k = method.kernel::<f64>();
        let rule = Outside::Boundary(BoundaryMode::Edge);
        let out = shift_plane(plane.view(), 0.4, -1.3, k.as_ref(), rule).unwrap();
        let rows = shear_rows(plane.view(), 13, &[0.4; 9], k.as_ref(), rule).unwrap();
        let cols = shear_rows(rows.t(), 9, &[-1.3; 13], k.as_ref(), rule).unwrap();
        let diff = (&out - &cols.t())
            .mapv(f64::abs)
            .fold(0.0, |a: f64, b| a.max(*b));
        assert!(diff < 1e-15, "{method}: {diff}");
        // Integer shifts translate exactly.
        let moved = shift_plane(plane.view(), 2.0, 1.0, k.as_ref(), Outside::Fill(0.0)).unwrap();
        assert_eq!(moved[[3, 5]], plane[[2, 3]]);
        assert_eq!(moved[[0, 5]], 0.0);
    }
}

#[test]
fn transpose_matches_indexing() {
    for (h, w) in [(1, 1), (1, 70), (70, 1), (33, 65), (64, 31)] {
        let a = Array2::from_shape_fn((h, w), |(r, c)| r * 1000 + c);
        assert_eq!(transpose(a.view()), a.t());
        assert_eq!(transpose(a.t()), a);
    }
}

#[test]
fn method_names_round_trip_and_build_named_kernels() {
    for &m in ShiftMethod::ALL {
        assert_eq!(m.name().parse::<ShiftMethod>().unwrap(), m);
        // Default parameters print the bare name, except Haar, whose mode every report must say.
        let name = m.kernel::<f32>().name();
        match m {
            ShiftMethod::Haar => assert_eq!(name, "haar(h=3, compact)"),
            _ => assert_eq!(name, m.name()),
        }
    }
    assert_eq!(
        ShearKernel::<f64>::name(&Keys::new(-0.75).unwrap()),
        "keys(a=-0.75)"
    );
}

/// Rows shifted together (`shift_rows`, as the drivers call it) equal the same rows shifted
/// one at a time, bit for bit, for every kernel and in both sample types.
#[test]
fn grouped_rows_equal_single_rows() {
    fn grouped_rows_equal_single_rows<T: Sample>(rng: &mut StdRng) {
        for method in ShiftMethod::ALL {
            let kernel = method.kernel::<T>();
            for rule in RULES {
                let (len_in, len_out) = (rng.random_range(1..40), rng.random_range(1..50));
                let count = rng.random_range(1..2 * ROW_GROUP + 3);
                let rows: Vec<Vec<T>> = (0..count)
                    .map(|_| {
                        (0..len_in)
                            .map(|_| T::from_f64(rng.random_range(-1.0..1.0)))
                            .collect()
                    })
                    .collect();
                let shifts: Vec<f64> = (0..count).map(|_| rng.random_range(-6.0..6.0)).collect();
                let geometry = RowGeometry {
                    len_in,
                    len_out,
                    min_shift: -6.0,
                    max_shift: 6.0,
                };
                let mut worker = kernel.row_shifter(geometry, rule);
                let mut grouped = vec![vec![T::zero(); len_out]; count];
                let row_refs: Vec<&[T]> = rows.iter().map(|r| r.as_slice()).collect();
                let mut outs: Vec<&mut [T]> =
                    grouped.iter_mut().map(|o| o.as_mut_slice()).collect();
                worker.shift_rows(&row_refs, &shifts, &mut outs).unwrap();
                for ((row, &shift), got) in rows.iter().zip(&shifts).zip(&grouped) {
                    let mut single = vec![T::zero(); len_out];
                    worker.shift_row(row, shift, &mut single).unwrap();
                    assert_eq!(&single, got, "{method} {rule:?} shift {shift}");
                }
            }
        }
    }
    let mut rng = StdRng::seed_from_u64(8);
    grouped_rows_equal_single_rows::<f32>(&mut rng);
    grouped_rows_equal_single_rows::<f64>(&mut rng);
}

/// With wrap, FFT shifts compose: sixteen shifts by 7.3 / 16 equal one by 7.3 for a row without
/// a Nyquist component (the odd length has none).
#[test]
fn periodic_fft_shifts_compose() {
    let kernel = FftShift::<f64>::new();
    let mut rng = StdRng::seed_from_u64(9);
    let row = Array2::from_shape_vec((1, 37), random_row(&mut rng, 37)).unwrap();
    let wrap = Outside::Boundary(BoundaryMode::Wrap);
    let once = shear_rows(row.view(), 37, &[7.3], &kernel, wrap).unwrap();
    let mut chained = row.clone();
    for _ in 0..16 {
        chained = shear_rows(chained.view(), 37, &[7.3 / 16.0], &kernel, wrap).unwrap();
    }
    let err = (&once - &chained)
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(err < 1e-13, "{err}");
}
