//! Transform tests: every coefficient against its brute-force basis function, perfect
//! reconstruction, Parseval, padding and cropping.

use ndarray::{Array2, ArrayView2};
use proptest::prelude::*;

use super::basis::{haar_basis_1d, pyramid_basis};
use super::*;

/// Deterministic, irregular test data (no two neighbours alike, signs mixed).
fn test_image(h: usize, w: usize, seed: u64) -> Array2<f64> {
    Array2::from_shape_fn((h, w), |(i, j)| {
        let x = (i as u64 * 7919 + j as u64 * 104_729 + seed * 31) % 1009;
        x as f64 / 7.0 - 60.0
    })
}

fn inner(a: ArrayView2<'_, f64>, b: ArrayView2<'_, f64>) -> f64 {
    a.iter().zip(b.iter()).map(|(x, y)| x * y).sum()
}

const SHAPES: [(usize, usize); 9] = [
    (1, 1),
    (1, 4),
    (2, 2),
    (2, 4),
    (4, 2),
    (4, 4),
    (8, 4),
    (8, 8),
    (16, 8),
];

#[test]
fn pyramid_coefficients_are_inner_products_with_the_basis() {
    for &(h, w) in &SHAPES {
        let x = test_image(h, w, 1);
        for levels in 0..=pyramid::max_levels(h, w) {
            for &norm in Normalization::ALL {
                let c = pyramid::forward(x.view(), levels, norm).unwrap();
                let mut seen = Array2::<u8>::zeros((h, w));
                let (h0, w0) = (h >> levels, w >> levels);
                let mut check = |band: Band, level: usize, bh: usize, bw: usize| {
                    let (rows, cols) = pyramid::band_ranges((h, w), levels, band, level).unwrap();
                    assert_eq!((rows.len(), cols.len()), (bh, bw));
                    for i in 0..bh {
                        for j in 0..bw {
                            let basis = pyramid_basis((h, w), levels, band, level, i, j, norm);
                            let (r, q) = (rows.start + i, cols.start + j);
                            let want = inner(basis.view(), x.view());
                            assert!(
                                (c[[r, q]] - want).abs() < 1e-12,
                                "{h}x{w} k={levels} {band:?} l={level} ({i},{j}) {norm:?}"
                            );
                            seen[[r, q]] += 1;
                        }
                    }
                };
                check(Band::Scaling, 0, h0, w0);
                for level in 0..levels {
                    for band in [Band::Horizontal, Band::Vertical, Band::Diagonal] {
                        check(band, level, h0 << level, w0 << level);
                    }
                }
                // The bands tile the array exactly once.
                assert!(seen.iter().all(|&n| n == 1), "{h}x{w} k={levels}");
            }
        }
    }
}

#[test]
fn separable_coefficients_are_products_of_1d_bases() {
    for &(h, w) in &SHAPES {
        let x = test_image(h, w, 2);
        let (dh, dw) = (h.trailing_zeros() as usize, w.trailing_zeros() as usize);
        for kh in 0..=dh {
            for kw in 0..=dw {
                for &norm in Normalization::ALL {
                    let mut c = x.clone();
                    separable::forward_in_place(c.view_mut(), &[kh, kw], norm).unwrap();
                    for r in 0..h {
                        let br = haar_basis_1d(h, kh, r, norm);
                        for q in 0..w {
                            let bq = haar_basis_1d(w, kw, q, norm);
                            let want: f64 = (0..h)
                                .flat_map(|i| (0..w).map(move |j| (i, j)))
                                .map(|(i, j)| br[i] * bq[j] * x[[i, j]])
                                .sum();
                            assert!((c[[r, q]] - want).abs() < 1e-12);
                        }
                    }
                    separable::inverse_in_place(c.view_mut(), &[kh, kw], norm).unwrap();
                    assert!(c.iter().zip(x.iter()).all(|(a, b)| (a - b).abs() < 1e-12));
                }
            }
        }
    }
}

#[test]
fn one_block_matches_the_documented_formulas() {
    let (p, q, r, s) = (9.0, 2.0, -3.0, 5.0);
    let c = pyramid::forward(
        ndarray::array![[p, q], [r, s]].view(),
        1,
        Normalization::Average,
    )
    .unwrap();
    assert_eq!(
        c,
        ndarray::array![
            [(p + q + r + s) / 4.0, (p - q + r - s) / 4.0],
            [(p + q - r - s) / 4.0, (p - q - r + s) / 4.0]
        ]
    );
    let o = pyramid::forward(
        ndarray::array![[p, q], [r, s]].view(),
        1,
        Normalization::Orthonormal,
    )
    .unwrap();
    assert_eq!(o, c.mapv(|v| 2.0 * v));
}

#[test]
fn average_scaling_coefficient_is_the_mean_and_orthonormal_keeps_energy() {
    for &(h, w) in &[(64usize, 64usize), (32, 128), (256, 256)] {
        let x = test_image(h, w, 3);
        let mean = x.mean().unwrap();
        let avg =
            pyramid::forward(x.view(), pyramid::max_levels(h, w), Normalization::Average).unwrap();
        let roots = avg.slice(ndarray::s![
            ..h >> pyramid::max_levels(h, w),
            ..w >> pyramid::max_levels(h, w)
        ]);
        assert!((roots.mean().unwrap() - mean).abs() < 1e-12);
        let energy: f64 = x.iter().map(|v| v * v).sum();
        for layout in [Layout::Pyramid, Layout::Separable] {
            let spec = TransformSpec {
                layout,
                normalization: Normalization::Orthonormal,
                ..Default::default()
            };
            let c = spec.forward(x.view()).unwrap();
            let ce: f64 = c.as_array().iter().map(|v| v * v).sum();
            // Measured at most 3.9e-13 relative; bound 5x.
            assert!((ce - energy).abs() < 2e-12 * energy, "{layout} {h}x{w}");
        }
    }
}

#[test]
fn spec_round_trips_any_size_with_every_padding_layout_and_level() {
    for &(h, w) in &[
        (1usize, 1usize),
        (1, 7),
        (3, 5),
        (5, 3),
        (17, 33),
        (31, 64),
        (64, 32),
    ] {
        let x = test_image(h, w, 4);
        let (ph, pw) = (h.next_power_of_two(), w.next_power_of_two());
        let max = pyramid::max_levels(ph, pw);
        for &layout in Layout::ALL {
            for &normalization in Normalization::ALL {
                for &padding in BoundaryMode::ALL {
                    for levels in (0..=max).map(Levels::Count).chain([Levels::Full]) {
                        let spec = TransformSpec {
                            layout,
                            normalization,
                            levels,
                            padding,
                        };
                        let c = spec.forward(x.view()).unwrap();
                        assert_eq!(c.as_array().dim(), (ph, pw));
                        let back = c.inverse().unwrap();
                        assert_eq!(back.dim(), (h, w));
                        let err = back
                            .iter()
                            .zip(x.iter())
                            .map(|(a, b)| (a - b).abs())
                            .fold(0.0, f64::max);
                        assert!(err < 1e-12, "{spec:?} {h}x{w}: {err}");
                    }
                }
            }
        }
    }
}

#[test]
fn f32_transforms_round_trip_to_single_precision() {
    let x = test_image(128, 64, 5).mapv(|v| v as f32);
    for &layout in Layout::ALL {
        for &normalization in Normalization::ALL {
            let spec = TransformSpec {
                layout,
                normalization,
                ..Default::default()
            };
            let back = spec.forward(x.view()).unwrap().inverse().unwrap();
            // Relative to the image's peak: f32 carries about 7 digits of the largest value.
            let peak = x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
            let err = back
                .iter()
                .zip(x.iter())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max)
                / peak;
            // Measured at most 3.6e-7 (separable, orthonormal); bound 2.8x.
            assert!(err < 1e-6, "{layout} {normalization}: {err}");
        }
    }
}

#[test]
fn rejects_empty_non_finite_and_impossible_levels() {
    let spec = TransformSpec::default();
    assert!(matches!(
        spec.forward(Array2::<f64>::zeros((0, 4)).view()),
        Err(Error::InvalidShape { .. })
    ));
    let mut x = Array2::<f64>::zeros((4, 4));
    x[[2, 3]] = f64::INFINITY;
    assert!(matches!(
        spec.forward(x.view()),
        Err(Error::NonFinite { .. })
    ));
    let deep = TransformSpec {
        levels: Levels::Count(3),
        ..Default::default()
    };
    assert!(matches!(
        deep.forward(Array2::<f64>::zeros((4, 8)).view()),
        Err(Error::InvalidParameter { .. })
    ));
    assert_err!(
        pyramid::forward(
            Array2::<f64>::zeros((3, 4)).view(),
            0,
            Normalization::Average
        ),
        InvalidShape { .. },
        "[3, 4]",
        "powers of two"
    );
}

#[test]
fn band_accessors_find_the_documented_places() {
    let x = test_image(8, 8, 6);
    let c = TransformSpec::default().forward(x.view()).unwrap();
    let raw = c.as_array();
    assert_eq!(c.get(Band::Scaling, 0, 0, 0), Some(raw[[0, 0]]));
    for l in 0..3usize {
        let n = 1 << l;
        assert_eq!(c.get(Band::Horizontal, l, n - 1, 0), Some(raw[[n - 1, n]]));
        assert_eq!(c.get(Band::Vertical, l, 0, n - 1), Some(raw[[n, n - 1]]));
        assert_eq!(
            c.get(Band::Diagonal, l, n - 1, n - 1),
            Some(raw[[2 * n - 1, 2 * n - 1]])
        );
        assert_eq!(c.get(Band::Diagonal, l, n, 0), None);
    }
    assert_err!(
        c.band(Band::Horizontal, 3),
        InvalidParameter { name: "level", .. },
        "detail level 3"
    );
    assert_err!(
        c.band(Band::Scaling, 1),
        InvalidParameter { name: "level", .. },
        "level 0 only"
    );
    assert_err!(
        c.separable_band(Band1d::Scaling, Band1d::Scaling),
        InvalidParameter { name: "band", .. },
        "separable layout"
    );
}

#[test]
fn from_parts_checks_consistency() {
    let x = test_image(5, 9, 7);
    let c = TransformSpec::default().forward(x.view()).unwrap();
    let (data, info) = c.clone().into_parts();
    assert_eq!(Coefficients::from_parts(data.clone(), info).unwrap(), c);
    let wrong = TransformInfo {
        original_shape: [3, 9],
        ..info
    };
    assert_err!(
        Coefficients::from_parts(data.clone(), wrong),
        InvalidShape { .. },
        "original image of 3x9"
    );
    let deep = TransformInfo {
        levels: [5, 5],
        ..info
    };
    assert_err!(
        Coefficients::from_parts(data, deep),
        InvalidParameter { name: "levels", .. },
        "[5, 5] do not fit"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Larger random shapes: the fast pyramid equals the separable-per-block definition
    /// checked above by the recursive relation A(level) = mean of children.
    #[test]
    fn pyramid_round_trips_and_averages(h in 0u32..9, w in 0u32..9, seed in 0u64..1000) {
        let (h, w) = (1usize << h, 1usize << w);
        let x = test_image(h, w, seed);
        let k = pyramid::max_levels(h, w);
        let c = pyramid::forward(x.view(), k, Normalization::Average).unwrap();
        // The scaling block is the block means.
        // Measured over 64 cases (values of magnitude up to 84, up to 256 x 256): at most
        // 7.1e-15 for the means and 2.8e-14 for the round trip; bound 1e-12 (35x and more).
        let side = 1 << k;
        for i in 0..h >> k {
            for j in 0..w >> k {
                let mean = x.slice(ndarray::s![i * side..(i + 1) * side, j * side..(j + 1) * side]).mean().unwrap();
                prop_assert!((c[[i, j]] - mean).abs() < 1e-12);
            }
        }
        let back = pyramid::inverse(c.view(), k, Normalization::Average).unwrap();
        prop_assert!(back.iter().zip(x.iter()).all(|(a, b)| (a - b).abs() < 1e-12));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]
    /// The pyramid's finiteness check rides on its own pass: a NaN or an infinity anywhere, at
    /// any size (padded or not), any depth and in either precision, is refused with the
    /// image's own index, exactly as a separate pass over the input would name it.
    #[test]
    fn a_non_finite_value_anywhere_is_named(
        rows in 1usize..40,
        cols in 1usize..40,
        at in 0usize..1600,
        which in 0usize..3,
        levels in 0usize..6,
        padding in 0usize..4,
    ) {
        let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][which];
        let (r, c) = ((at / 40) % rows, at % cols);
        let mut x = test_image(rows, cols, at as u64);
        x[[r, c]] = bad;
        let spec = TransformSpec {
            levels: Levels::Count(levels.min(pyramid::max_levels(
                rows.next_power_of_two(),
                cols.next_power_of_two(),
            ))),
            padding: BoundaryMode::ALL[padding],
            ..Default::default()
        };
        let want = ensure_finite(&x).unwrap_err().to_string();
        prop_assert_eq!(spec.forward(x.view()).unwrap_err().to_string(), want.clone());
        let single = x.mapv(|v| v as f32);
        prop_assert_eq!(spec.forward(single.view()).unwrap_err().to_string(), want);
    }
}

#[test]
fn orthonormal_coefficients_that_overflow_are_refused_and_average_ones_cannot_overflow() {
    // Every value is finite and near the largest f32: left minus right of the block is not.
    let x = ndarray::array![[3e38f32, -3e38], [3e38, -3e38]];
    let orthonormal = TransformSpec {
        normalization: Normalization::Orthonormal,
        ..Default::default()
    };
    let err = orthonormal.forward(x.view()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "invalid image: values too large: the transform overflows f32"
    );
    // The average normalisation scales first: the half-difference is 3e38 itself.
    let c = TransformSpec::default().forward(x.view()).unwrap();
    assert_eq!(c.as_array(), ndarray::array![[0.0f32, 3e38], [0.0, 0.0]]);
    assert_eq!(c.inverse().unwrap(), x);
}
