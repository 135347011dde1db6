//! Rotating a Phong lobe, whose rotation is known in closed form: every method puts the peak
//! where it belongs and keeps the integral; the Haar methods converge at their stated rates;
//! the errors per level; the exact whole-column yaw of `haar-cubic`. The lobe and the
//! expected peak are written here from their definitions, not with [`super::lobes`].

use std::f64::consts::PI;

use super::latlong::angles;
use super::level_tests::block_means;
use super::map_error::weighted_rms;
use super::*;
use crate::test_support::sphere_options;

/// `(e + 2) / (2 pi) max(0, axis . d)^e`, the energy-normalised Phong lobe.
fn lobe(exponent: f64, axis: [f64; 3], h: usize) -> LatLongMap<f64> {
    LatLongMap::from_fn(h, 1, |d, out| {
        let c = axis[0] * d[0] + axis[1] * d[1] + axis[2] * d[2];
        out[0] = (exponent + 2.0) / (2.0 * PI) * c.max(0.0).powf(exponent);
    })
    .unwrap()
}

/// Its integral over the sphere, `(e + 2) / (e + 1)`.
fn lobe_integral(exponent: f64) -> f64 {
    (exponent + 2.0) / (exponent + 1.0)
}

const UP: [f64; 3] = [0.0, 1.0, 0.0];

fn rotations() -> Vec<SphereRotation> {
    [
        (0.0, 30.0, 0.0),
        (0.0, 60.0, 0.0),
        (0.0, 90.0, 0.0),
        (40.0, -25.0, 60.0),
    ]
    .iter()
    .map(|&(y, p, r)| SphereRotation::from_degrees(y, p, r).unwrap())
    .collect()
}

/// The texel `(row, column)` of an `h`-row map that contains direction `d`.
fn texel_of(h: usize, d: [f64; 3]) -> (usize, usize) {
    let (t, p) = angles(d);
    let step = PI / h as f64;
    (
        ((t / step) as usize).min(h - 1),
        ((p / step) as usize).min(2 * h - 1),
    )
}

/// Texels between two texels (Chebyshev, columns around the seam).
fn texel_distance(a: (usize, usize), b: (usize, usize), w: usize) -> usize {
    let dc = a.1.abs_diff(b.1);
    a.0.abs_diff(b.0).max(dc.min(w - dc))
}

/// The weighted RMS of `g` against the lobe about `R^-1 axis` at the texel centres, over the
/// latter's weighted RMS.
fn relative_error(g: &LatLongMap<f64>, exponent: f64, axis: [f64; 3], r: &SphereRotation) -> f64 {
    let truth = lobe(exponent, r.inverse().apply(axis), g.height());
    let zero = LatLongMap::from_fn(g.height(), 1, |_, o| o[0] = 0.0).unwrap();
    weighted_rms(g, &truth).unwrap() / weighted_rms(&truth, &zero).unwrap()
}

/// Phong 50 about +Y on 64 x 128, turned by pitch 30, 60, 90 and a compound rotation: `g`
/// is the lobe about `r = R^-1 (+Y)`, so every method's brightest texel must be within one
/// texel of the one holding `r`.
///
/// Integral against the analytic `(e + 2) / (e + 1)`, worst over the rotations: the
/// source's own plain sum is 0.51 % high (the lobe sits on the pole, where the samples'
/// sum overstates it). Measured: reference 1.0e-2 and bilinear 1.03e-2 (the source's excess
/// plus bilinear's own overshoot on a convex peak), bicubic 1.8e-4, haar 5.07e-3 (it keeps
/// the source's plain sum exactly), haar-cubic 3.5e-5 (it keeps the pole-corrected sum).
/// Bounds 1.3x, the Haar ones 1.5x.
#[test]
fn a_lobe_turned_to_r_peaks_at_r_and_keeps_its_integral() {
    let (h, e) = (64, 50.0);
    let f = lobe(e, UP, h);
    let exact = lobe_integral(e);
    for &method in Method::ALL {
        let mut worst = 0.0f64;
        for r in rotations() {
            let g = rotate_map(&f, &r, &sphere_options(method, None))
                .unwrap()
                .map;
            let want = texel_of(h, r.inverse().apply(UP));
            let got = g.brightest();
            assert!(
                texel_distance(got, want, 2 * h) <= 1,
                "{method}: peak at {got:?}, r in {want:?}"
            );
            worst = worst.max((g.energy()[0] / exact - 1.0).abs());
        }
        let bound = match method {
            Method::Reference => 1.3e-2,
            Method::Bilinear => 1.35e-2,
            Method::Bicubic => 2.4e-4,
            Method::Haar => 7.6e-3,
            Method::HaarCubic => 5.2e-5,
        };
        assert!(worst < bound, "{method}: integral off by {worst:e}");
    }
}

/// From the finest level, the error against the analytic rotated lobe (Phong 10 and 50,
/// compound rotation) as the map doubles from 32 to 256 rows. Measured relative errors and
/// rates (log2 of the ratio per doubling):
///
/// | | 32 | 64 | 128 | 256 | rates |
/// |---|---|---|---|---|---|
/// | haar, e = 10 | 1.0e-2 | 2.5e-3 | 6.0e-4 | 1.5e-4 | 2.02, 2.03, 1.99 |
/// | haar-cubic, e = 10 | 5.6e-4 | 3.1e-5 | 2.7e-6 | 1.9e-7 | 4.16, 3.55, 3.82 |
/// | haar, e = 50 | 5.1e-2 | 1.3e-2 | 2.9e-3 | 7.4e-4 | 2.01, 2.09, 1.99 |
/// | haar-cubic, e = 50 | 1.1e-2 | 7.7e-4 | 5.7e-5 | 3.9e-6 | 3.80, 3.74, 3.86 |
///
/// Asserted: haar's rate above 1.8 (second order), haar-cubic's above 3.2 (fourth order,
/// with margin), at every doubling; the finest errors within 1.5x of those measured.
#[test]
fn haar_errors_fall_as_the_resolution_doubles() {
    let r = SphereRotation::from_degrees(40.0, -25.0, 60.0).unwrap();
    for e in [10.0, 50.0] {
        for method in [Method::Haar, Method::HaarCubic] {
            let errors: Vec<f64> = [32, 64, 128, 256]
                .iter()
                .map(|&h| {
                    let g = rotate_map(&lobe(e, UP, h), &r, &sphere_options(method, None)).unwrap();
                    relative_error(&g.map, e, UP, &r)
                })
                .collect();
            let rates: Vec<f64> = errors.windows(2).map(|p| (p[0] / p[1]).log2()).collect();
            let (rate, finest) = match (method, e == 10.0) {
                (Method::Haar, true) => (1.8, 1.5e-4),
                (Method::Haar, false) => (1.8, 7.4e-4),
                (_, true) => (3.2, 1.9e-7),
                (_, false) => (3.2, 3.9e-6),
            };
            assert!(
                rates.iter().all(|&r| r > rate),
                "{method} e={e}: errors {errors:?}, rates {rates:?}"
            );
            assert!(errors[3] < 1.5 * finest, "{method} e={e}: {errors:?}");
        }
    }
}

/// The error of each `--level` on a 128 x 256 Phong 50 lobe (compound rotation), relative to
/// the lobe's RMS: against the analytic rotated lobe at the texel centres of the full map
/// (`full`, dominated by the detail a coarse level does not compute) and against that lobe
/// reduced to the level's block means (`own`, the method's own error). Measured, levels 0
/// to 6 (the thesis's 1 to 7):
///
/// | | full | own |
/// |---|---|---|
/// | haar | 1.19 1.15 0.81 0.41 0.197 0.087 0.0029 | 0.79 0.74 0.51 0.179 0.056 0.0139 0.0029 |
/// | haar-cubic | 1.21 1.16 0.81 0.40 0.191 0.086 5.7e-5 | 0.83 0.77 0.50 0.137 0.0233 0.0040 5.7e-5 |
/// | bilinear | 1.20 1.15 0.79 0.40 0.195 0.087 0.0028 | 0.81 0.75 0.48 0.137 0.0477 0.0121 0.0028 |
/// | bicubic | 1.22 1.17 0.79 0.40 0.191 0.086 1.1e-4 | 0.84 0.77 0.48 0.133 0.0228 0.0039 1.1e-4 |
///
/// Both fall with every level here (unlike the thesis's level 5 against 6 on its scenes), so
/// that is asserted; and from level 4 on (where the lobe is resolved), haar-cubic's own
/// error is at most 1.1x bicubic's (measured 1.02, 1.02, 0.52).
#[test]
fn errors_per_level() {
    let (h, e) = (128, 50.0);
    let f = lobe(e, UP, h);
    let r = SphereRotation::from_degrees(40.0, -25.0, 60.0).unwrap();
    let truth = lobe(e, r.inverse().apply(UP), h);
    let zero = LatLongMap::from_fn(h, 1, |_, o| o[0] = 0.0).unwrap();
    let scale = weighted_rms(&truth, &zero).unwrap();
    let mut per_method = Vec::new();
    for method in [
        Method::Haar,
        Method::HaarCubic,
        Method::Bilinear,
        Method::Bicubic,
    ] {
        let (errors, own): (Vec<f64>, Vec<f64>) = (0..7)
            .map(|level| {
                let g = rotate_map(&f, &r, &sphere_options(method, Some(level)))
                    .unwrap()
                    .map;
                let reduced = block_means(&truth.as_array().to_owned(), h >> (level + 1));
                let reduced = LatLongMap::new(reduced).unwrap();
                (
                    relative_error(&g, e, UP, &r),
                    weighted_rms(&g, &reduced).unwrap() / scale,
                )
            })
            .unzip();
        for list in [&errors, &own] {
            assert!(
                list.windows(2).all(|p| p[1] < p[0]),
                "{method}: {errors:?} {own:?}"
            );
        }
        per_method.push(own);
    }
    let levels = per_method[1].iter().zip(&per_method[3]).enumerate();
    for (level, (&cubic, &bicubic)) in levels.skip(4).take(3) {
        assert!(
            cubic <= 1.1 * bicubic,
            "level {level}: haar-cubic {cubic:e}, bicubic {bicubic:e}"
        );
    }
}

/// A yaw by whole columns is the exact coefficient shift for `haar-cubic` too, from
/// coefficients and from pixels, at the finest level and at a coarser one.
#[test]
fn whole_column_yaw_of_haar_cubic_is_the_exact_coefficient_shift() {
    let h = 32;
    let f = lobe(10.0, [0.5, 0.3, 0.812_403_840_463_596], h);
    let c = SphereCoefficients::from_map(&f).unwrap();
    for k in [1usize, 6, 16, 63] {
        let r = SphereRotation::from_degrees(k as f64 * 360.0 / 64.0, 0.0, 0.0).unwrap();
        let shift = yaw::yaw_coefficients(&c, k).unwrap();
        let got = rotate_coefficients(&c, &r, &sphere_options(Method::HaarCubic, None)).unwrap();
        assert_eq!(got, shift, "k={k}");
        let from_pixels = rotate_map(&f, &r, &sphere_options(Method::HaarCubic, None)).unwrap();
        assert_eq!(from_pixels.coefficients, shift, "k={k}");
        assert_eq!(from_pixels.map, f.roll_columns(k), "k={k}");
        let coarse =
            rotate_coefficients(&c, &r, &sphere_options(Method::HaarCubic, Some(2))).unwrap();
        assert_eq!(coarse, shift.truncated(2).unwrap(), "k={k}");
    }
}
