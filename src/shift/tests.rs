//! Shift tests: every fast path against the definition ([`oracle`]), exhaustively on small
//! sizes and by proptest on larger ones; the pixel-domain meaning of fractional shifts against
//! an independent bilinear interpolation; composition; Alnasser 2008's own closed forms
//! (corrected) against the oracle; input validation.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2, s};
use proptest::prelude::*;

use super::dense::{self, shift_pyramid_in_strips};
use super::*;
use crate::Error;
use crate::patterns::whole_shifts;
use crate::transform::{Band, Band1d, Coefficients, Normalization, TransformSpec, haar1d, pyramid};

const TOL: f64 = 1e-12;

/// Deterministic, irregular data of magnitude about 10.
fn signal(n: usize, seed: u64) -> Array1<f64> {
    Array1::from_shape_fn(n, |i| {
        ((i as u64 * 7919 + seed * 104_729) % 1009) as f64 / 50.0 - 10.0
    })
}

fn image(h: usize, w: usize, seed: u64) -> Array2<f64> {
    Array2::from_shape_fn((h, w), |(i, j)| {
        ((i as u64 * 7919 + j as u64 * 104_729 + seed * 31) % 1009) as f64 / 50.0 - 10.0
    })
}

/// The largest absolute difference of two arrays; infinite when their shapes differ.
fn max_diff<'a, D: ndarray::Dimension>(
    a: impl ndarray::AsArray<'a, f64, D>,
    b: impl ndarray::AsArray<'a, f64, D>,
) -> f64 {
    let (a, b) = (a.into(), b.into());
    // Arrays of different shapes (an empty result among them) are infinitely far apart.
    if a.shape() != b.shape() {
        return f64::INFINITY;
    }
    a.iter()
        .zip(b.iter())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn max_diff_compares_shapes_before_values() {
    let full = Array2::from_elem((2, 3), 1.0);
    let empty = Array2::<f64>::zeros((0, 3));
    assert_eq!(max_diff(&full, &empty), f64::INFINITY);
    assert_eq!(max_diff(&full, full.view()), 0.0);
    assert_eq!(max_diff(&full, &(&full + 0.25)), 0.25);
}

/// Checks dense (at every split between strip and coarse levels) and random access against
/// the oracle for one 2D case.
fn check_2d(c: ArrayView2<'_, f64>, levels: usize, norm: Normalization, dx: i64, dy: i64) {
    let (dx, dy) = (GridShift::whole(dx), GridShift::whole(dy));
    let want = oracle::shift_pyramid(c, levels, norm, dx, dy).unwrap();
    let mut out = Array2::zeros(c.dim());
    let mut work = ShiftWorkspace::default();
    for fine in 0..=levels {
        shift_pyramid_in_strips(c, levels, norm, (dx, dy), out.view_mut(), &mut work, fine)
            .unwrap();
        let err = max_diff(&out, &want);
        assert!(
            err < TOL,
            "{:?} k={levels} {norm} fine={fine} {dx:?} {dy:?}: {err}",
            c.dim()
        );
    }
    // The public entry: bands whose blocks divide the shift are rolled, the rest in strips.
    dense::shift_pyramid_into(c, levels, norm, dx, dy, out.view_mut(), &mut work).unwrap();
    let err = max_diff(&out, &want);
    assert!(
        err < TOL,
        "{:?} k={levels} {norm} {dx:?} {dy:?}: {err}",
        c.dim()
    );
    let query = ShiftQuery2d::new(c, levels, norm).unwrap();
    let all = query.coarse(dx, dy, levels).unwrap();
    let err = max_diff(&all, &want);
    assert!(
        err < TOL,
        "query {:?} k={levels} {norm} {dx:?} {dy:?}: {err}",
        c.dim()
    );
}

#[test]
fn exhaustive_1d_every_size_shift_level_and_normalisation() {
    for depth in 1..=7usize {
        let n = 1 << depth;
        let x = signal(n, depth as u64);
        for levels in 0..=depth {
            for &norm in Normalization::ALL {
                let c = haar1d::forward(x.view(), levels, norm).unwrap();
                let query = ShiftQuery1d::new(c.view(), levels, norm).unwrap();
                let mut work = ShiftWorkspace::default();
                let mut out = Array1::zeros(n);
                for s in -(n as i64) - 3..=2 * n as i64 + 3 {
                    let shift = GridShift::whole(s);
                    let want = oracle::shift_signal(c.view(), levels, norm, shift).unwrap();
                    dense::shift_signal_into(
                        c.view(),
                        levels,
                        norm,
                        shift,
                        out.view_mut(),
                        &mut work,
                    )
                    .unwrap();
                    let all = query.coarse(shift, levels).unwrap();
                    let ctx = format!("n={n} k={levels} {norm} s={s}");
                    assert!(max_diff(&out, &want) < TOL, "dense {ctx}");
                    assert!(max_diff(&all, &want) < TOL, "query {ctx}");
                }
            }
        }
    }
}

/// Square sizes up to 16 and small rectangles: every shift in `[-side - 1, side + 1]` along
/// both axes (every residue, negative, beyond the size).
#[test]
fn exhaustive_2d_every_shift_up_to_16() {
    let shapes = [
        (1, 1),
        (1, 2),
        (2, 1),
        (2, 2),
        (2, 4),
        (4, 4),
        (4, 8),
        (8, 4),
        (8, 8),
        (8, 16),
        (16, 8),
        (16, 16),
    ];
    for &(h, w) in &shapes {
        let x = image(h, w, (h * 3 + w) as u64);
        for levels in 0..=pyramid::max_levels(h, w) {
            for &norm in Normalization::ALL {
                let c = pyramid::forward(x.view(), levels, norm).unwrap();
                for dy in -(h as i64) - 1..=h as i64 + 1 {
                    for dx in -(w as i64) - 1..=w as i64 + 1 {
                        check_2d(c.view(), levels, norm, dx, dy);
                    }
                }
            }
        }
    }
}

/// Sizes with a side of 32: a dense sweep of shifts (odd, even, multiples of every power of
/// two, negative, beyond the size).
#[test]
fn exhaustive_2d_shift_sweep_at_32() {
    let sweep = [
        -33i64, -17, -6, -1, 0, 1, 2, 3, 4, 7, 8, 12, 16, 31, 32, 37, 67,
    ];
    for &(h, w) in &[(32usize, 32usize), (16, 32), (32, 16), (4, 32)] {
        let x = image(h, w, 5);
        for levels in 0..=pyramid::max_levels(h, w) {
            for &norm in Normalization::ALL {
                let c = pyramid::forward(x.view(), levels, norm).unwrap();
                for &dy in &sweep {
                    for &dx in &sweep {
                        check_2d(c.view(), levels, norm, dx, dy);
                    }
                }
            }
        }
    }
}

#[test]
fn large_image_uses_the_coarse_stage_and_f32_matches() {
    // 2048 columns of f64 keep only two levels in a strip: the coarse stage does the rest.
    let (h, w) = (16, 2048);
    let x = image(h, w, 9);
    let levels = pyramid::max_levels(h, w);
    let c = pyramid::forward(x.view(), levels, Normalization::Average).unwrap();
    let (dx, dy) = (GridShift::whole(-1237), GridShift::whole(7));
    let want = oracle::shift_pyramid(c.view(), levels, Normalization::Average, dx, dy).unwrap();
    let got = dense::shift_pyramid(c.view(), levels, Normalization::Average, dx, dy).unwrap();
    assert!(max_diff(&got, &want) < TOL);
    let c32 = c.mapv(|v| v as f32);
    let got32 = dense::shift_pyramid(c32.view(), levels, Normalization::Average, dx, dy).unwrap();
    let err = max_diff(&got32.mapv(f64::from), &want);
    // Measured 6.9e-7 (f32 rounding of values about 1); bound 4x.
    assert!(err < 3e-6, "f32 error {err}");
}

/// `x` rolled periodically: `out[r][c] = x[r - dy][c - dx]`.
fn roll_2d(x: ArrayView2<'_, f64>, dx: i64, dy: i64) -> Array2<f64> {
    let (h, w) = (x.nrows() as i64, x.ncols() as i64);
    Array2::from_shape_fn(x.dim(), |(r, c)| {
        x[[
            (r as i64 - dy).rem_euclid(h) as usize,
            (c as i64 - dx).rem_euclid(w) as usize,
        ]]
    })
}

/// 8-bit values (integers 0..=255), irregular.
fn bytes_image(h: usize, w: usize) -> Array2<f64> {
    Array2::from_shape_fn((h, w), |(i, j)| {
        ((i * 37 + j * j * 11 + i * j) % 256) as f64
    })
}

#[test]
fn whole_shifts_by_multiples_of_the_block_only_move_coefficients() {
    // Arbitrary (non-dyadic) data: bit-exactness can only come from moving coefficients.
    let x = image(32, 64, 3).mapv(|v| v * std::f64::consts::PI);
    for &norm in Normalization::ALL {
        for levels in 0..=5 {
            let c = pyramid::forward(x.view(), levels, norm).unwrap();
            let unit = 1i64 << levels;
            let (dx, dy) = (3 * unit, -5 * unit);
            let got = dense::shift_pyramid(
                c.view(),
                levels,
                norm,
                GridShift::whole(dx),
                GridShift::whole(dy),
            )
            .unwrap();
            let want = pyramid::forward(roll_2d(x.view(), dx, dy).view(), levels, norm).unwrap();
            assert_eq!(got, want, "{norm} k={levels}");
        }
        // Shift (4, 12) with 5 levels: the two finest levels are rolled bit for bit, the
        // coarse 8x16 block is recomputed.
        let c = pyramid::forward(x.view(), 5, norm).unwrap();
        let got =
            dense::shift_pyramid(c.view(), 5, norm, GridShift::whole(4), GridShift::whole(12))
                .unwrap();
        let want = pyramid::forward(roll_2d(x.view(), 4, 12).view(), 5, norm).unwrap();
        let fine_bands = |a: &Array2<f64>| {
            let mut v = a.slice(s![8.., ..]).to_owned().into_raw_vec_and_offset().0;
            v.extend(a.slice(s![..8, 16..]).iter());
            v
        };
        assert_eq!(fine_bands(&got), fine_bands(&want), "{norm}");
        assert!(max_diff(&got, &want) < TOL);
    }
    // 1D: a shift by a multiple of 2^levels permutes the whole transform.
    let v = signal(64, 4).mapv(|v| v / 3.0);
    for &norm in Normalization::ALL {
        let c = haar1d::forward(v.view(), 3, norm).unwrap();
        let got = dense::shift_signal(c.view(), 3, norm, GridShift::whole(-24)).unwrap();
        let rolled = Array1::from_shape_fn(64, |i| v[(i + 24) % 64]);
        assert_eq!(
            got,
            haar1d::forward(rolled.view(), 3, norm).unwrap(),
            "{norm}"
        );
    }
}

#[test]
fn chains_of_whole_shifts_are_bit_exact_where_the_arithmetic_is() {
    // 8-bit data, average normalisation or the 2D orthonormal pyramid (factors 1/4 and 1/2):
    // every intermediate is a short dyadic rational, so any chain equals one roll exactly.
    let x = bytes_image(64, 32);
    let shifts = whole_shifts(300, 70, 1);
    let (tx, ty) = shifts
        .iter()
        .fold((0, 0), |(a, b), &(dx, dy)| (a + dx, b + dy));
    for &norm in Normalization::ALL {
        let spec = TransformSpec {
            normalization: norm,
            ..Default::default()
        };
        let mut c = spec.forward(x.view()).unwrap();
        for &(dx, dy) in &shifts {
            c = shift_image(&c, dx as f64, dy as f64, 0).unwrap();
        }
        let want = spec.forward(roll_2d(x.view(), tx, ty).view()).unwrap();
        assert_eq!(c.as_array(), want.as_array(), "{norm}");
    }
    // Arbitrary floats, shifts by multiples of 2^levels: a pure permutation, any data.
    let y = image(64, 32, 8).mapv(|v| v.exp());
    let spec = TransformSpec {
        levels: crate::transform::Levels::Count(3),
        ..Default::default()
    };
    let shifts = whole_shifts(300, 9, 8);
    let (tx, ty) = shifts
        .iter()
        .fold((0, 0), |(a, b), &(dx, dy)| (a + dx, b + dy));
    let mut c = spec.forward(y.view()).unwrap();
    for &(dx, dy) in &shifts {
        c = shift_image(&c, dx as f64, dy as f64, 0).unwrap();
    }
    let want = spec.forward(roll_2d(y.view(), tx, ty).view()).unwrap();
    assert_eq!(c.as_array(), want.as_array());
}

/// The compact fractional shift, computed independently in the pixel domain: periodic linear
/// (1D) / bilinear (2D) interpolation at the shift rounded to the 1/2^h grid.
fn interpolate_1d(x: ArrayView1<'_, f64>, s: f64, h: u32) -> Array1<f64> {
    let n = x.len() as i64;
    let scale = (1u64 << h) as f64;
    let rounded = (s * scale + 0.5).floor() / scale; // ties up
    Array1::from_shape_fn(x.len(), |i| {
        let pos = i as f64 - rounded;
        let (k, a) = (pos.floor(), pos - pos.floor());
        let at = |k: f64| x[(k as i64).rem_euclid(n) as usize];
        (1.0 - a) * at(k) + a * at(k + 1.0)
    })
}

fn interpolate_2d(x: ArrayView2<'_, f64>, dx: f64, dy: f64, h: u32) -> Array2<f64> {
    let rows = Array2::from_shape_fn(x.dim(), |(i, j)| x[[i, j]]);
    let mut out = rows.clone();
    for (mut dst, src) in out.rows_mut().into_iter().zip(rows.rows()) {
        dst.assign(&interpolate_1d(src, dx, h));
    }
    let tmp = out.clone();
    for (mut dst, src) in out.columns_mut().into_iter().zip(tmp.columns()) {
        dst.assign(&interpolate_1d(src, dy, h));
    }
    out
}

#[test]
fn compact_fractional_shift_is_linear_interpolation_and_matches_the_oracle() {
    for depth in 1..=5usize {
        let n = 1 << depth;
        let x = signal(n, 3);
        for levels in 0..=depth {
            for &norm in Normalization::ALL {
                let c = haar1d::forward(x.view(), levels, norm).unwrap();
                let query = ShiftQuery1d::new(c.view(), levels, norm).unwrap();
                for h in 0..=4u32 {
                    for &s in &[0.3, -0.3, 1.7, -2.55, 5.0 / 16.0, -0.5, 9.96] {
                        let shift = GridShift::new(s, h).unwrap();
                        let want = oracle::shift_signal(c.view(), levels, norm, shift).unwrap();
                        let pixel =
                            haar1d::forward(interpolate_1d(x.view(), s, h).view(), levels, norm)
                                .unwrap();
                        let got = dense::shift_signal(c.view(), levels, norm, shift).unwrap();
                        let all = query.coarse(shift, levels).unwrap();
                        let ctx = format!("n={n} k={levels} {norm} h={h} s={s}");
                        assert!(max_diff(&pixel, &want) < TOL, "pixel vs oracle {ctx}");
                        assert!(max_diff(&got, &want) < TOL, "dense {ctx}");
                        assert!(max_diff(&all, &want) < TOL, "query {ctx}");
                    }
                }
            }
        }
    }
    for &(hh, ww) in &[(4usize, 4usize), (4, 8), (8, 8)] {
        let x = image(hh, ww, 4);
        for levels in 0..=pyramid::max_levels(hh, ww) {
            for &norm in Normalization::ALL {
                let c = pyramid::forward(x.view(), levels, norm).unwrap();
                let query = ShiftQuery2d::new(c.view(), levels, norm).unwrap();
                for h in 0..=3u32 {
                    for &(dx, dy) in &[(0.3, -0.6), (-1.25, 2.5), (0.0, 0.4), (3.9, 0.0)] {
                        let (gx, gy) = (
                            GridShift::new(dx, h).unwrap(),
                            GridShift::new(dy, h).unwrap(),
                        );
                        let want = oracle::shift_pyramid(c.view(), levels, norm, gx, gy).unwrap();
                        let z = interpolate_2d(x.view(), dx, dy, h);
                        let pixel = pyramid::forward(z.view(), levels, norm).unwrap();
                        let got = dense::shift_pyramid(c.view(), levels, norm, gx, gy).unwrap();
                        let all = query.coarse(gx, gy, levels).unwrap();
                        let ctx = format!("{hh}x{ww} k={levels} {norm} h={h} ({dx},{dy})");
                        assert!(max_diff(&pixel, &want) < TOL, "pixel vs oracle {ctx}");
                        assert!(max_diff(&got, &want) < TOL, "dense {ctx}");
                        assert!(max_diff(&all, &want) < TOL, "query {ctx}");
                    }
                }
            }
        }
    }
}

#[test]
fn ties_round_up_for_both_signs() {
    // 0.25 at h = 1 is a tie between 0 and 0.5: it becomes 0.5; -0.25 becomes 0 (not -0.5).
    let x = signal(8, 1);
    let norm = Normalization::Average;
    let c = haar1d::forward(x.view(), 3, norm).unwrap();
    let up = dense::shift_signal(c.view(), 3, norm, GridShift::new(0.25, 1).unwrap()).unwrap();
    let half = dense::shift_signal(c.view(), 3, norm, GridShift::new(0.5, 1).unwrap()).unwrap();
    assert!(max_diff(&up, &half) < TOL);
    let down = dense::shift_signal(c.view(), 3, norm, GridShift::new(-0.25, 1).unwrap()).unwrap();
    assert!(max_diff(&down, &c) < TOL);
}

#[test]
fn separable_shift_is_the_per_axis_oracle() {
    for &(h, w) in &[(4usize, 8usize), (8, 8), (16, 4)] {
        let x = image(h, w, 6);
        for &norm in Normalization::ALL {
            for (kh, kw) in [(0, 1), (2, 0), (h.ilog2() as usize, w.ilog2() as usize)] {
                let mut c = x.clone();
                crate::transform::separable::forward_in_place(c.view_mut(), &[kh, kw], norm)
                    .unwrap();
                for &(dx, dy, p) in &[(3.0, -5.0, 0), (0.5, 1.25, 2), (-7.75, 0.0, 3)] {
                    let shifts = [
                        GridShift::new(dy, p).unwrap(),
                        GridShift::new(dx, p).unwrap(),
                    ];
                    let mut got = c.clone();
                    separable::shift_in_place(got.view_mut(), &[kh, kw], norm, &shifts).unwrap();
                    // Oracle: the 1D definition along every column, then every row.
                    let mut want = c.clone();
                    for mut col in want.columns_mut() {
                        let v = oracle::shift_signal(col.view(), kh, norm, shifts[0]).unwrap();
                        col.assign(&v);
                    }
                    for mut row in want.rows_mut() {
                        let v = oracle::shift_signal(row.view(), kw, norm, shifts[1]).unwrap();
                        row.assign(&v);
                    }
                    assert!(max_diff(&got, &want) < TOL, "{h}x{w} ({kh},{kw}) {norm}");
                }
            }
        }
    }
}

#[test]
fn shift_image_dispatches_on_layout_and_keeps_the_info() {
    let x = image(5, 11, 2); // padded to 8 x 16: the shift is periodic over the padded size
    for layout in crate::transform::Layout::ALL {
        let spec = TransformSpec {
            layout: *layout,
            padding: crate::BoundaryMode::Wrap,
            ..Default::default()
        };
        let c = spec.forward(x.view()).unwrap();
        let moved = shift_image(&c, 3.0, -2.0, 0).unwrap();
        assert_eq!(moved.info(), c.info());
        let back = shift_image(&moved, -3.0, 2.0, 0).unwrap();
        assert!(max_diff(back.as_array(), c.as_array()) < TOL);
        let padded =
            crate::transform::pad_to_power_of_two(x.view(), crate::BoundaryMode::Wrap).unwrap();
        let y = Coefficients::inverse(&moved).unwrap();
        for ((i, j), &v) in y.indexed_iter() {
            let src = padded[[(i + 8 + 2) % 8, (j + 16 - 3) % 16]];
            assert!((v - src).abs() < TOL);
        }
    }
}

#[test]
fn retained_chain_equals_one_shift_and_projects_to_the_compact_shift() {
    let x = image(8, 16, 7);
    let spec = TransformSpec::default();
    let c = spec.forward(x.view()).unwrap();
    let h = 3;
    let steps = [
        (0.375, -0.625),
        (1.125, 0.25),
        (-0.5, 2.875),
        (0.125, -0.125),
    ];
    let mut chain = RetainedImage::new(&c, h).unwrap();
    let mut total = (0.0, 0.0);
    for &(dx, dy) in &steps {
        chain.shift(dx, dy).unwrap();
        total = (total.0 + dx, total.1 + dy);
    }
    assert_eq!(chain.offset(), total);
    let mut once = RetainedImage::new(&c, h).unwrap();
    once.shift(total.0, total.1).unwrap();
    assert!(max_diff(chain.fine(), once.fine()) < TOL);
    // One retained shift projected = the compact shift.
    let compact = shift_image(&c, total.0, total.1, h).unwrap();
    assert!(max_diff(once.project().as_array(), compact.as_array()) < TOL);
    // A chain summing to whole pixels is exactly the whole shift.
    let mut whole = RetainedImage::new(&c, h).unwrap();
    for _ in 0..8 {
        whole.shift(0.125, -0.375).unwrap();
    }
    let want = shift_image(&c, 1.0, -3.0, 0).unwrap();
    assert!(max_diff(whole.project().as_array(), want.as_array()) < TOL);
}

#[test]
fn retained_signal_chain_is_exact() {
    let x = signal(32, 2);
    let norm = Normalization::Orthonormal;
    let c = haar1d::forward(x.view(), 4, norm).unwrap();
    let mut r = RetainedSignal::new(c.view(), 4, norm, 4).unwrap();
    for _ in 0..16 {
        r.shift(-0.3125).unwrap(); // -5/16
    }
    assert_eq!(r.offset(), -5.0);
    let want = dense::shift_signal(c.view(), 4, norm, GridShift::whole(-5)).unwrap();
    assert!(max_diff(&r.project(), &want) < TOL);
    assert_eq!(r.fine().len(), 32 << 4);
}

/// Alnasser 2008's 1D closed forms (2.13) and (2.23), implemented literally with its D tables
/// (2.5)-(2.6), with the typos of the module docs corrected, in its sign convention
/// (`y[n] = x[n + S]`, so `S = -s`) and the average normalisation.
fn seed_1d(c: &[f64], levels: usize, shift: i64) -> Vec<f64> {
    let len = c.len();
    let n_bits = len.trailing_zeros() as usize;
    let seed_s = (-shift).rem_euclid(len as i64) as usize;
    let t = if seed_s == 0 {
        usize::MAX
    } else {
        seed_s.trailing_zeros() as usize
    };
    let top = n_bits - levels; // coarsest level held: A^{N-K}
    let n0 = 1usize << top;
    // Level l (seed numbering, N - k) holds 2^l details at c[n0 << (l - top) ..].
    let d = |l: usize, i: usize| c[(n0 << (l - top)) + (i % (1 << l))];
    // D tables: D^{top} = A^{top} - mean, then (2.6).
    let mean = c[..n0].iter().sum::<f64>() / n0 as f64;
    let mut tables: Vec<Vec<f64>> = vec![c[..n0].iter().map(|a| a - mean).collect()];
    for l in top + 1..=n_bits {
        let prev = &tables[l - 1 - top];
        tables.push(
            (0..1usize << l)
                .map(|i| {
                    prev[i / 2]
                        + if i % 2 == 0 {
                            d(l - 1, i / 2)
                        } else {
                            -d(l - 1, i / 2)
                        }
                })
                .collect(),
        );
    }
    let dt = |l: usize, i: i64| tables[l - top][i.rem_euclid(1 << l) as usize];
    let dd = |l: usize, i: i64| d(l, i.rem_euclid(1 << l) as usize);
    let mut out = vec![0.0; len];
    // Scaling coefficients (2.23), k = levels.
    for i in 0..n0 {
        let k = levels;
        out[i] = if k <= t {
            c[(i + seed_s / (1 << k)) % n0]
        } else {
            let l = n_bits - t - 1;
            let base = (seed_s >> (t + 1)) as i64;
            let i1 = ((i as i64) << (k - t - 1)) + base;
            let i2 = (((i + 1) as i64) << (k - t - 1)) + base;
            let inner: f64 = (i1 + 1..i2).map(|m| dt(l, m)).sum();
            mean + (dt(l, i1) + 2.0 * inner + dt(l, i2) - dd(l, i1) + dd(l, i2))
                / (1u64 << (k - t)) as f64
        };
    }
    // Wavelet coefficients (2.13): level N - k for k = 1..=levels.
    for k in 1..=levels {
        let level = n_bits - k;
        for i in 0..1usize << level {
            let value = if k <= t {
                d(level, (i + seed_s / (1 << k)) % (1 << level))
            } else {
                let l = n_bits - t - 1;
                let base = (seed_s >> (t + 1)) as i64;
                let i1 = ((i as i64) << (k - t - 1)) + base;
                let i3 = (((i + 1) as i64) << (k - t - 1)) + base;
                // i2 = 2^{k-t-2}(2i+1) + base: not an integer when k = t + 1.
                let (i2, d2) = if k > t + 1 {
                    let i2 = (((2 * i + 1) as i64) << (k - t - 2)) + base;
                    (i2, dd(l, i2))
                } else {
                    (i1, 0.0)
                };
                let left: f64 = (i1 + 1..i2).map(|m| dt(l, m)).sum();
                let right: f64 = (i2 + 1..i3).map(|m| dt(l, m)).sum();
                let right = if k > t + 1 { right } else { 0.0 };
                (dt(l, i1) + 2.0 * left - 2.0 * right - dt(l, i3) - dd(l, i1) + 2.0 * d2
                    - dd(l, i3))
                    / (1u64 << (k - t)) as f64
            };
            out[(n0 << (level - top)) + i] = value;
        }
    }
    out
}

#[test]
fn seed_1d_closed_forms_corrected_agree_with_the_oracle() {
    let norm = Normalization::Average;
    for depth in 1..=6usize {
        let n = 1 << depth;
        let x = signal(n, 11);
        for levels in 1..=depth {
            let c = haar1d::forward(x.view(), levels, norm).unwrap();
            for s in -(n as i64)..n as i64 {
                let want =
                    oracle::shift_signal(c.view(), levels, norm, GridShift::whole(s)).unwrap();
                let got = seed_1d(c.as_slice().unwrap(), levels, s);
                let err = max_diff(&got, &want);
                assert!(err < TOL, "n={n} k={levels} s={s}: {err}");
            }
        }
    }
}

/// Alnasser 2008's 2D cases `k = t + 1` of (3.13), (3.16) (horizontal shift) and (3.17), (3.19)
/// (vertical shift), literally, in its sign convention and the average normalisation.
#[test]
fn seed_2d_half_window_cases_agree_with_the_oracle() {
    // Both cases have the form ((p0 - c0 + p1 + c1) / 2, (p0 - c0 - p1 - c1) / 2).
    let pair = |(p0, c0): (f64, f64), (p1, c1): (f64, f64)| {
        ((p0 - c0 + p1 + c1) / 2.0, (p0 - c0 - p1 - c1) / 2.0)
    };
    let norm = Normalization::Average;
    for side_bits in 1..=4usize {
        let side = 1usize << side_bits;
        let c = pyramid::forward(image(side, side, 8).view(), side_bits, norm).unwrap();
        for seed_s in 1..side {
            let t = seed_s.trailing_zeros() as usize;
            let k = t + 1;
            let level = side_bits - k; // seed level N - k = our level index
            let m = 1usize << level;
            let q = seed_s >> k;
            // Entry (i, j) of band `b` at this level of `arr`, indices taken periodically.
            let entry = |arr: &Array2<f64>, b: Band, i: usize, j: usize| {
                let (r, cc) = pyramid::band_ranges((side, side), side_bits, b, level).unwrap();
                arr[[r.start + i % m, cc.start + j % m]]
            };
            let band = |b: Band, i: usize, j: usize| entry(&c, b, i, j);
            let s = -(seed_s as i64);
            let zero = GridShift::whole(0);
            let horizontal =
                oracle::shift_pyramid(c.view(), side_bits, norm, GridShift::whole(s), zero)
                    .unwrap();
            let vertical =
                oracle::shift_pyramid(c.view(), side_bits, norm, zero, GridShift::whole(s))
                    .unwrap();
            for i in 0..m {
                for j in 0..m {
                    let (ah, bv, cv) = (Band::Horizontal, Band::Vertical, Band::Diagonal);
                    // Horizontal shift, (3.13) and (3.16): b and c from b, c at j', j' + 1.
                    let jj = j + q;
                    let (b_new, c_new) = pair(
                        (band(bv, i, jj), band(cv, i, jj)),
                        (band(bv, i, jj + 1), band(cv, i, jj + 1)),
                    );
                    let at = |arr: &Array2<f64>, b: Band| entry(arr, b, i, j);
                    assert!(
                        (at(&horizontal, bv) - b_new).abs() < TOL,
                        "(3.13) s={seed_s}"
                    );
                    assert!(
                        (at(&horizontal, cv) - c_new).abs() < TOL,
                        "(3.16) s={seed_s}"
                    );
                    // Vertical shift, (3.17) and (3.19): a and c from a, c at i', i' + 1.
                    let ii = i + q;
                    let (a_new, c_new) = pair(
                        (band(ah, ii, j), band(cv, ii, j)),
                        (band(ah, ii + 1, j), band(cv, ii + 1, j)),
                    );
                    assert!((at(&vertical, ah) - a_new).abs() < TOL, "(3.17) s={seed_s}");
                    assert!((at(&vertical, cv) - c_new).abs() < TOL, "(3.19) s={seed_s}");
                }
            }
        }
    }
}

#[test]
fn sparse_queries_agree_with_the_dense_shift() {
    let x = image(64, 128, 3);
    let norm = Normalization::Orthonormal;
    let c = pyramid::forward(x.view(), 6, norm).unwrap();
    let (dx, dy) = (
        GridShift::new(-40.375, 3).unwrap(),
        GridShift::new(17.5, 3).unwrap(),
    );
    let dense = dense::shift_pyramid(c.view(), 6, norm, dx, dy).unwrap();
    let query = ShiftQuery2d::new(c.view(), 6, norm).unwrap();
    let coarse = query.coarse(dx, dy, 3).unwrap();
    // Measured 9.8e-15; bound 10x.
    assert!(max_diff(&coarse, dense.slice(s![..8, ..16])) < 1e-13);
    let which = [
        (Band::Scaling, 0, 0, 1),
        (Band::Diagonal, 5, 31, 63),
        (Band::Vertical, 2, 3, 7),
    ];
    let got = query.coefficients(dx, dy, &which).unwrap();
    let want = [dense[[0, 1]], dense[[32 + 31, 64 + 63]], dense[[4 + 3, 7]]];
    // Measured 9.8e-15; bound 10x.
    assert!(max_diff(&got, &want) < 1e-13);
    // The coarse-resolution query needs only the top-left 1/4^t of the coefficients.
    let mut coarse_only = c.clone();
    coarse_only.slice_mut(s![8.., ..]).fill(f64::NAN);
    coarse_only.slice_mut(s![..8, 16..]).fill(f64::NAN);
    let low = ShiftQuery2d::with_resolution(coarse_only.view(), 6, norm, 3).unwrap();
    let (dx, dy) = (GridShift::whole(-40), GridShift::whole(16));
    let dense = dense::shift_pyramid(c.view(), 6, norm, dx, dy).unwrap();
    let block = low.coarse(dx, dy, 3).unwrap();
    // Measured 1.3e-15; bound 75x (TOL).
    assert!(max_diff(&block, dense.slice(s![..8, ..16])) < TOL);
    assert_err!(
        low.coefficient(GridShift::whole(4), dy, Band::Scaling, 0, 0, 0),
        InvalidParameter { name: "shift", .. },
        "whole multiple of 8 samples"
    );
    assert_err!(
        low.coefficient(dx, dy, Band::Diagonal, 3, 0, 0),
        InvalidParameter { name: "level", .. },
        "detail level 3"
    );
}

#[test]
fn rejects_bad_inputs_with_typed_errors() {
    let norm = Normalization::Average;
    let c = Array2::<f64>::zeros((8, 8));
    let whole = GridShift::whole(1);
    assert!(matches!(
        GridShift::new(f64::NAN, 1),
        Err(Error::InvalidParameter { name: "shift", .. })
    ));
    assert!(matches!(
        GridShift::new(1.0, 21),
        Err(Error::InvalidParameter {
            name: "precision",
            ..
        })
    ));
    assert!(matches!(
        GridShift::new(1e308, 20),
        Err(Error::InvalidParameter { .. })
    ));
    assert_err!(
        dense::shift_pyramid(Array2::<f64>::zeros((6, 8)).view(), 1, norm, whole, whole),
        InvalidShape { .. },
        "[6, 8]",
        "powers of two"
    );
    assert_err!(
        dense::shift_pyramid(c.view(), 4, norm, whole, whole),
        InvalidParameter { name: "levels", .. },
        "at most 3"
    );
    let mut wrong = Array2::zeros((8, 4));
    let mut work = ShiftWorkspace::default();
    assert!(matches!(
        dense::shift_pyramid_into(c.view(), 3, norm, whole, whole, wrong.view_mut(), &mut work),
        Err(Error::InvalidShape { .. })
    ));
    let mut transposed = Array2::zeros((8, 8));
    let t = transposed.view_mut().reversed_axes();
    assert_err!(
        dense::shift_pyramid_into(c.view(), 3, norm, whole, whole, t, &mut work),
        InvalidShape { .. },
        "standard-layout"
    );
    assert_err!(
        dense::shift_signal(Array1::<f64>::zeros(3).view(), 1, norm, whole),
        InvalidShape { .. },
        "[3]",
        "power of two"
    );
    assert_err!(
        ShiftQuery2d::new(c.view(), 4, norm),
        InvalidParameter { name: "levels", .. },
        "at most 3"
    );
    assert_err!(
        ShiftQuery2d::with_resolution(c.view(), 2, norm, 3),
        InvalidParameter {
            name: "resolution",
            ..
        },
        "exceeds the 2 levels"
    );
    let q = ShiftQuery2d::new(c.view(), 3, norm).unwrap();
    assert_err!(
        q.coefficient(whole, whole, Band::Horizontal, 3, 0, 0),
        InvalidParameter { name: "level", .. },
        "detail level 3"
    );
    assert_err!(
        q.coefficient(whole, whole, Band::Horizontal, 1, 2, 0),
        InvalidParameter { name: "index", .. },
        "(2, 0) is out of range"
    );
    assert_err!(
        q.coefficient(whole, whole, Band::Scaling, 1, 0, 0),
        InvalidParameter { name: "level", .. },
        "level 0 only"
    );
    assert_err!(
        q.coarse(whole, whole, 4),
        InvalidParameter { name: "levels", .. },
        "4 detail levels requested of 3"
    );
    let q1 = ShiftQuery1d::new(Array1::<f64>::zeros(8).view(), 3, norm).unwrap();
    assert_err!(
        q1.coefficient(whole, Band1d::Detail(3), 0),
        InvalidParameter { name: "level", .. },
        "detail level 3"
    );
    assert_err!(
        q1.coefficient(whole, Band1d::Detail(2), 4),
        InvalidParameter { name: "index", .. },
        "4 is out of range"
    );
    assert_err!(
        separable::shift_in_place(c.clone().view_mut(), &[1, 1], norm, &[whole]),
        InvalidParameter { name: "shift", .. },
        "2 level counts and 1 shifts"
    );
    let spec = TransformSpec::default().forward(c.view()).unwrap();
    assert!(matches!(
        RetainedImage::with_budget(&spec, 3, 1000),
        Err(Error::MemoryBudget { .. })
    ));
    assert_err!(
        RetainedImage::new(&spec, 21),
        InvalidParameter {
            name: "precision",
            ..
        },
        "above the maximum of 20"
    );
    let sep = TransformSpec {
        layout: crate::transform::Layout::Separable,
        ..Default::default()
    };
    assert_err!(
        RetainedImage::new(&sep.forward(c.view()).unwrap(), 1),
        InvalidParameter { name: "layout", .. },
        "pyramid layout"
    );
    assert_err!(
        ShiftQuery2d::from_coefficients(&sep.forward(c.view()).unwrap()),
        InvalidParameter { name: "layout", .. },
        "pyramid layout"
    );
}

/// The bound of the two proptests below: over their 48 cases each the largest difference
/// measured was 1.4e-14 (values of magnitude up to 10, up to 128 x 128 or 1,024 samples at
/// `h <= 8`); the bound is 70x that, for the sizes and shifts a run did not draw.
const RANDOM_SIZE_BOUND: f64 = 1e-12;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Larger 2D sizes, fractional shifts, precisions up to 8: dense = pixel-domain bilinear
    /// statement = random access; integer shifts compose exactly.
    #[test]
    fn pyramid_fractional_shifts_on_random_sizes(
        hb in 0u32..8, wb in 0u32..8, k_frac in 0.0f64..1.0, seed in 0u64..1000,
        dx in -300.0f64..300.0, dy in -300.0f64..300.0, h in 0u32..=8,
        a in -500i64..500, b in -500i64..500, ortho in any::<bool>(),
    ) {
        let (rows, cols) = (1usize << hb, 1usize << wb);
        let norm = if ortho { Normalization::Orthonormal } else { Normalization::Average };
        let levels = (k_frac * (hb.min(wb) + 1) as f64) as usize;
        let x = image(rows, cols, seed);
        let c = pyramid::forward(x.view(), levels, norm).unwrap();
        let (gx, gy) = (GridShift::new(dx, h).unwrap(), GridShift::new(dy, h).unwrap());
        let got = dense::shift_pyramid(c.view(), levels, norm, gx, gy).unwrap();
        let pixel = pyramid::forward(interpolate_2d(x.view(), dx, dy, h).view(), levels, norm).unwrap();
        prop_assert!(max_diff(&got, &pixel) < RANDOM_SIZE_BOUND);
        let query = ShiftQuery2d::new(c.view(), levels, norm).unwrap();
        let (h0, w0) = (rows >> levels, cols >> levels);
        for n in 0..16usize {
            let (r, q) = ((n * 7919 + seed as usize) % rows, (n * 104_729 + seed as usize) % cols);
            let idx = random_access::pyramid_index(h0, w0, r, q);
            let v = query.coefficients(gx, gy, &[idx]).unwrap()[0];
            prop_assert!((v - got[[r, q]]).abs() < RANDOM_SIZE_BOUND);
        }
        let (ga, gb) = (GridShift::whole(a), GridShift::whole(b));
        let first = dense::shift_pyramid(c.view(), levels, norm, ga, gb).unwrap();
        let twice = dense::shift_pyramid(first.view(), levels, norm, gb, ga).unwrap();
        let once = dense::shift_pyramid(c.view(), levels, norm, ga + gb, gb + ga).unwrap();
        prop_assert!(max_diff(&twice, &once) < RANDOM_SIZE_BOUND);
    }

    /// Larger 1D sizes, precisions up to 8, against the oracle itself; composition on the
    /// retained grid is exact.
    #[test]
    fn signal_fractional_shifts_on_random_sizes(
        depth in 1u32..=10, k_frac in 0.0f64..1.0, seed in 0u64..1000,
        s in -3000.0f64..3000.0, t in -3000.0f64..3000.0, h in 0u32..=8, ortho in any::<bool>(),
    ) {
        let n = 1usize << depth;
        let norm = if ortho { Normalization::Orthonormal } else { Normalization::Average };
        let levels = (k_frac * (depth + 1) as f64) as usize;
        let x = signal(n, seed);
        let c = haar1d::forward(x.view(), levels, norm).unwrap();
        let shift = GridShift::new(s, h).unwrap();
        let got = dense::shift_signal(c.view(), levels, norm, shift).unwrap();
        let pixel = haar1d::forward(interpolate_1d(x.view(), s, h).view(), levels, norm).unwrap();
        prop_assert!(max_diff(&got, &pixel) < RANDOM_SIZE_BOUND);
        if n << h <= 1 << 14 {
            let want = oracle::shift_signal(c.view(), levels, norm, shift).unwrap();
            prop_assert!(max_diff(&got, &want) < RANDOM_SIZE_BOUND);
        }
        let query = ShiftQuery1d::new(c.view(), levels, norm).unwrap();
        prop_assert!(max_diff(&query.coarse(shift, levels).unwrap(), &got) < RANDOM_SIZE_BOUND);
        let mut chain = RetainedSignal::new(c.view(), levels, norm, h).unwrap();
        chain.shift(s).unwrap();
        chain.shift(t).unwrap();
        let mut once = RetainedSignal::new(c.view(), levels, norm, h).unwrap();
        let total = GridShift::new(s, h).unwrap() + GridShift::new(t, h).unwrap();
        once.shift(total.amount()).unwrap();
        prop_assert!(max_diff(chain.fine(), once.fine()) < RANDOM_SIZE_BOUND);
    }
}

#[test]
fn plane_whole_shifts_are_the_transform_path_as_a_permutation_and_exact_in_f32() {
    // On 8-bit codes in f64 the transform path is exact (module docs), so it is the oracle for
    // the permutation, non-power-of-two sizes (periodic padding wrapping into view) included.
    let haar = PlaneShift::new(
        crate::kernels::ShiftMethod::Haar,
        Default::default(),
        crate::BoundaryMode::Wrap,
    )
    .unwrap();
    let spec = TransformSpec {
        padding: crate::BoundaryMode::Wrap,
        ..Default::default()
    };
    for (h, w) in [(8, 8), (5, 7), (12, 3), (1, 6)] {
        let x = bytes_image(h, w);
        for (dx, dy) in [(5, -3), (-1000, 77), (0, 1), (9, 0)] {
            let via_transform =
                shift_image(&spec.forward(x.view()).unwrap(), dx as f64, dy as f64, 0)
                    .unwrap()
                    .inverse()
                    .unwrap();
            let rolled = haar.apply(x.view(), dx as f64, dy as f64).unwrap();
            assert_eq!(rolled, via_transform, "{h}x{w} by ({dx}, {dy})");
        }
    }
    // Codes divided by 255 in f32: the transform path rounds, the permutation does not.
    let x = bytes_image(16, 16).mapv(|v| (v / 255.0) as f32);
    let rolled = haar.apply(x.view(), 5.0, -3.0).unwrap();
    let exact = roll_2d(x.mapv(f64::from).view(), 5, -3).mapv(|v| v as f32);
    assert_eq!(rolled, exact);
    let via_transform = shift_image(&spec.forward(x.view()).unwrap(), 5.0, -3.0, 0)
        .unwrap()
        .inverse()
        .unwrap();
    assert!(
        via_transform != exact,
        "the f32 transform path is exact here: no test"
    );
    // A shift that rounds to whole pixels at the precision asked is whole too.
    let coarse = PlaneShift::new(
        crate::kernels::ShiftMethod::Haar,
        crate::kernels::KernelOptions {
            precision: 1,
            ..Default::default()
        },
        crate::BoundaryMode::Wrap,
    )
    .unwrap();
    assert_eq!(coarse.apply(x.view(), 5.1, -2.9).unwrap(), exact);
}
