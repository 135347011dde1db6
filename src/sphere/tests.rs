//! Sphere rotation tests: exact cases (identity, whole-column yaw, constants), oracles for the
//! recursive filters and the per-coefficient path, convergence of the chain-rule derivatives
//! on a smooth map, round trips, and the sun of a real HDR map.

use std::f64::consts::PI;

use ndarray::Array3;

use super::chain_rule::{
    CoefficientIndex, DifferenceFields, rotate_selected, set_mean_from_energy,
};
use super::latlong::{angles, direction, pixel_centre};
use super::map_error::{relative_energy_error, weighted_rms};
use super::*;
use crate::test_support::sphere_options;
use crate::transform::Band;

/// A smooth test function: spherical harmonics up to degree 2 (plus a constant), with its
/// ambient gradient (the tangential part is what the chain rule sees).
fn harmonic(d: [f64; 3]) -> f64 {
    let [x, y, z] = d;
    1.0 + 0.5 * x - 0.4 * z + 0.3 * y * z + 0.2 * (3.0 * y * y - 1.0) + 0.25 * x * y
}

fn harmonic_gradient(d: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = d;
    [0.5 + 0.25 * y, 0.3 * z + 1.2 * y + 0.25 * x, -0.4 + 0.3 * y]
}

fn harmonic_map(h: usize, channels: usize) -> LatLongMap<f64> {
    LatLongMap::from_fn(h, channels, |d, out| {
        for (k, o) in out.iter_mut().enumerate() {
            *o = harmonic(d) * (1.0 + k as f64);
        }
    })
    .unwrap()
}

fn compound() -> SphereRotation {
    SphereRotation::from_degrees(20.0, 35.0, 10.0).unwrap()
}

fn max_abs_diff(a: &Array3<f64>, b: &Array3<f64>) -> f64 {
    (a - b).iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// The rooitou park test map (128 x 256 x 3, see testdata/envmaps/SOURCES.md).
fn rooitou() -> LatLongMap<f32> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/testdata/envmaps/rooitou_park_256x128.npy"
    );
    let data: Array3<f32> = ndarray_npy::read_npy(path).unwrap();
    LatLongMap::new(data).unwrap()
}

#[test]
fn identity_is_exact_for_every_method() {
    let f = harmonic_map(16, 2);
    let c = SphereCoefficients::from_map(&f).unwrap();
    for &method in Method::ALL {
        let g = rotate_map(
            &f,
            &SphereRotation::identity(),
            &sphere_options(method, None),
        )
        .unwrap();
        assert_eq!(g.map, f, "{method}");
        assert_eq!(g.coefficients, c, "{method}");
    }
}

#[test]
fn whole_column_yaws_are_exact_shifts() {
    let f = harmonic_map(16, 2);
    let (w, levels) = (32, 4);
    for k in [1usize, 2, 3, 4, 6, 8, 12, 16, 24, 31] {
        let r = SphereRotation::from_degrees(k as f64 * 360.0 / w as f64, 0.0, 0.0).unwrap();
        assert_eq!(r.whole_column_yaw(w), Some(k));
        let want = f.roll_columns(k);
        let want_c = SphereCoefficients::from_map(&want).unwrap();
        for &method in Method::ALL {
            let g = rotate_map(&f, &r, &sphere_options(method, None)).unwrap();
            assert_eq!(g.map, want, "{method} k={k}");
            let err = max_abs_diff(
                &g.coefficients.as_array().to_owned(),
                &want_c.as_array().to_owned(),
            );
            assert!(err < 1e-14, "{method} k={k}: {err}");
        }
        // The coefficient-domain path permutes the levels whose blocks divide k, bit for bit.
        let got = yaw::yaw_coefficients(&SphereCoefficients::from_map(&f).unwrap(), k).unwrap();
        let s = (k.trailing_zeros() as usize).min(levels);
        for level in levels - s..levels {
            for band in [Band::Horizontal, Band::Vertical, Band::Diagonal] {
                for ch in 0..2 {
                    assert_eq!(
                        got.band(ch, band, level).unwrap(),
                        want_c.band(ch, band, level).unwrap(),
                        "k={k} level {level}"
                    );
                }
            }
        }
    }
    // Just off a whole column: not the exact path, but close to the neighbouring shift.
    let r = SphereRotation::from_degrees(360.0 / 32.0 + 1e-4, 0.0, 0.0).unwrap();
    assert_eq!(r.whole_column_yaw(w), None);
    let g = rotate_map(&f, &r, &sphere_options(Method::Haar, None)).unwrap();
    let err = max_abs_diff(&g.map.into_array(), &f.roll_columns(1).into_array());
    // Measured 2.2e-6 (the step's slope times 1e-4 of a column); bound 4.5x.
    assert!(err < 1e-5, "{err}");
}

#[test]
fn a_constant_map_stays_constant() {
    let f =
        LatLongMap::<f64>::from_fn(32, 3, |_, out| out.copy_from_slice(&[0.5, 2.0, 7.0])).unwrap();
    for rotation in [
        SphereRotation::from_degrees(0.0, 5.0, 0.0).unwrap(),
        SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap(),
        compound(),
    ] {
        for &method in Method::ALL {
            for level in [None, Some(2)] {
                let o = SphereOptions {
                    method,
                    level,
                    ..Default::default()
                };
                let g = rotate_map(&f, &rotation, &o).unwrap();
                let err = max_abs_diff(&g.map.into_array(), &f.clone().into_array());
                assert!(err < 1e-12, "{method} {level:?}: {err}");
            }
        }
    }
}

#[test]
fn recursive_filters_reproduce_the_forward_transform_exactly() {
    // Exact differences in, the exact pyramid out: (4.18)-(4.22) as identities.
    for h in [2usize, 4, 8, 32] {
        let x = LatLongMap::<f64>::from_fn(h, 2, |d, out| {
            out[0] = (3.0 * d[0]).sin() + d[1] * d[2];
            out[1] = (d[0] - 0.3 * d[1]).exp();
        })
        .unwrap();
        let want = SphereCoefficients::from_map(&x).unwrap();
        let mut got = DifferenceFields::of_map(&x).to_coefficients().unwrap();
        let (wa, ga) = (want.as_array(), got.as_array());
        for k in 0..2 {
            // Details everywhere; the scaling block holds (d/2, -d/2) with d = A0 - A1.
            for ((i, j), v) in ga.index_axis(ndarray::Axis(0), k).indexed_iter() {
                if i == 0 && j < 2 {
                    continue;
                }
                assert!((v - wa[[k, i, j]]).abs() < 1e-13, "h={h} ({i},{j})");
            }
            let d = wa[[k, 0, 0]] - wa[[k, 0, 1]];
            assert!((ga[[k, 0, 0]] - ga[[k, 0, 1]] - d).abs() < 1e-13);
        }
        set_mean_from_energy(&mut got, &x.energy()).unwrap();
        let err = max_abs_diff(&got.as_array().to_owned(), &want.as_array().to_owned());
        assert!(err < 1e-13, "h={h}: {err}");
    }
}

#[test]
fn selected_coefficients_equal_the_recursive_ones() {
    let f = harmonic_map(16, 2);
    let r = compound();
    let all = chain_rule::rotate(&f, &r, chain_rule::Scheme::Linear).unwrap();
    let mut requests = Vec::new();
    for level in 0..4 {
        for band in [Band::Horizontal, Band::Vertical, Band::Diagonal] {
            for row in 0..1usize << level {
                for column in 0..2usize << level {
                    requests.push(CoefficientIndex {
                        band,
                        level,
                        row,
                        column,
                    });
                }
            }
        }
    }
    let got = rotate_selected(&f, &r, &requests).unwrap();
    for (req, vals) in requests.iter().zip(&got) {
        for (ch, v) in vals.iter().enumerate() {
            let want = all.band(ch, req.band, req.level).unwrap()[[req.row, req.column]];
            assert!((v - want).abs() < 1e-13, "{req:?}: {v} vs {want}");
        }
    }
    let scaling = CoefficientIndex {
        band: Band::Scaling,
        level: 0,
        row: 0,
        column: 0,
    };
    assert_err!(
        rotate_selected(&f, &r, &[scaling]),
        InvalidParameter {
            name: "coefficient",
            ..
        },
        "not a detail coefficient"
    );
    let outside = CoefficientIndex {
        level: 4,
        ..requests[0]
    };
    assert_err!(
        rotate_selected(&f, &r, &[outside]),
        InvalidParameter {
            name: "coefficient",
            ..
        },
        "level: 4"
    );
}

/// Largest error of the chain-rule derivatives `-V / delta` and `-U / delta` of a rotated
/// smooth map against the analytic `g_theta`, `g_phi`.
fn derivative_error(h: usize, rotation: &SphereRotation) -> f64 {
    let f = harmonic_map(h, 1);
    let fields = DifferenceFields::rotated(&f, rotation, chain_rule::Scheme::Linear);
    let step = PI / h as f64;
    let analytic = |theta: f64, phi: f64, along_theta: bool| {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let tangent = if along_theta {
            [ct * sp, -st, ct * cp]
        } else {
            [st * cp, 0.0, -st * sp]
        };
        let q = rotation.apply(direction(theta, phi));
        let t = rotation.apply(tangent);
        let g = harmonic_gradient(q);
        g[0] * t[0] + g[1] * t[1] + g[2] * t[2]
    };
    let mut worst = 0.0f64;
    for ((i, j, _), v) in fields.vertical().indexed_iter() {
        let want = analytic((i + 1) as f64 * step, (j as f64 + 0.5) * step, true);
        worst = worst.max((-v / step - want).abs());
    }
    for ((i, j, _), u) in fields.horizontal().indexed_iter() {
        let want = analytic((i as f64 + 0.5) * step, (j + 1) as f64 * step, false);
        worst = worst.max((-u / step - want).abs());
    }
    worst
}

#[test]
fn chain_rule_derivatives_converge_at_second_order() {
    // Maps of 64x32, 128x64 and 256x128: the largest error anywhere on the sphere (poles
    // included) must fall by about 4 per doubling. Measured: errors 5.1e-3, 1.3e-3, 3.3e-4
    // (rates 1.92 and 2.02 in log2) for the compound rotation, 4.8e-3, 1.3e-3, 3.3e-4 (rates
    // 1.90 and 1.94) for pitch 90. Bounds: rate above 1.8 (second order is 2); the finest
    // error below 7e-4 (2x).
    for rotation in [
        compound(),
        SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap(),
    ] {
        let errors: Vec<f64> = [32, 64, 128]
            .iter()
            .map(|&h| derivative_error(h, &rotation))
            .collect();
        for pair in errors.windows(2) {
            let rate = (pair[0] / pair[1]).log2();
            assert!(rate > 1.8, "errors {errors:?}: rate {rate}");
        }
        assert!(errors[2] < 7e-4, "{errors:?}");
    }
}

#[test]
fn rotating_there_and_back_returns_the_map() {
    // Smooth map, 128 x 256, values about 0.2 to 2: each leg costs a second-order error.
    // Measured weighted RMS: reference 2.0e-4, bilinear 1.25e-4, bicubic 1.9e-7, haar 9.5e-5,
    // haar-cubic 6.4e-8; bounds 2x each (a bicubic that fell back to bilinear would be 600x
    // over its bound, a haar-cubic that fell back to haar 700x).
    let f = harmonic_map(128, 1);
    let r = compound();
    for &method in Method::ALL {
        let there = rotate_map(&f, &r, &sphere_options(method, None)).unwrap();
        let back = rotate_map(&there.map, &r.inverse(), &sphere_options(method, None)).unwrap();
        let rms = weighted_rms(&back.map, &f).unwrap();
        let bound = match method {
            Method::Reference => 4e-4,
            Method::Bilinear => 2.5e-4,
            Method::Bicubic => 4e-7,
            Method::Haar => 2e-4,
            Method::HaarCubic => 1.3e-7,
        };
        assert!(rms < bound, "{method}: {rms}");
    }
}

#[test]
fn smooth_maps_rotate_accurately_and_keep_their_energy() {
    let f = harmonic_map(64, 1);
    let r = compound();
    let exact = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = harmonic(r.apply(d))).unwrap();
    // Measured weighted RMS against the exact rotated function: reference 4.3e-4 (it
    // averages over pixels, the exact map is point-sampled), bilinear 2.7e-4, bicubic 2.6e-6,
    // haar 2.0e-4, haar-cubic 3.6e-7; bounds 1.4x for the reference, 2x for the others.
    // Energy: 4.1e-5, 8.3e-5, -2.8e-6, 3e-15 and -2.9e-6 (haar-cubic keeps the pole-corrected
    // sampled integral, not the plain sum); bounds 2.5x, 2.4x, 2.1x, 1e-14 and 2x.
    for &method in Method::ALL {
        let g = rotate_map(&f, &r, &sphere_options(method, None)).unwrap();
        let rms = weighted_rms(&g.map, &exact).unwrap();
        let (rms_bound, energy_bound) = match method {
            Method::Reference => (6e-4, 1e-4),
            Method::Bilinear => (5.5e-4, 2e-4),
            Method::Bicubic => (5.5e-6, 6e-6),
            Method::Haar => (4e-4, 1e-14),
            Method::HaarCubic => (7e-7, 6e-6),
        };
        assert!(rms < rms_bound, "{method}: {rms}");
        let energy = relative_energy_error(&g.map, &f);
        assert!(energy.abs() < energy_bound, "{method}: energy {energy}");
    }
}

#[test]
fn coefficients_in_equal_pixels_in() {
    let f = harmonic_map(32, 2);
    let c = SphereCoefficients::from_map(&f).unwrap();
    let r = compound();
    for &method in Method::ALL {
        for level in [None, Some(1), Some(3)] {
            let o = SphereOptions {
                method,
                level,
                ..Default::default()
            };
            let a = rotate_coefficients(&c, &r, &o).unwrap();
            let b = rotate_map(&f, &r, &o).unwrap().coefficients;
            let err = max_abs_diff(&a.as_array().to_owned(), &b.as_array().to_owned());
            assert!(err < 1e-12, "{method} {level:?}: {err}");
            if let Some(l) = level {
                // Nothing finer than the computed level.
                assert!(
                    a.band(0, Band::Diagonal, l + 1)
                        .unwrap()
                        .iter()
                        .all(|&v| v == 0.0)
                );
            }
        }
    }
}

#[test]
fn coefficient_files_hold_the_generic_pyramid_of_each_channel() {
    let f = harmonic_map(16, 3);
    let rotated = rotate_map(&f, &compound(), &sphere_options(Method::Haar, None)).unwrap();
    let file = rotated
        .coefficients
        .to_coefficient_file(crate::SampleDepth::F64)
        .unwrap();
    let image = rotated.map.to_image(crate::SampleDepth::F64).unwrap();
    assert_eq!(LatLongMap::from_image(&image).unwrap(), rotated.map);
    assert_eq!(file.metadata().channels, crate::Channels::Rgb);
    for (k, plane) in file.planes().iter().enumerate() {
        // The oracle: the generic transform of the channel, with the default spec.
        let generic = crate::transform::TransformSpec::default()
            .forward(image.plane(k))
            .unwrap();
        assert_eq!(plane.info(), generic.info());
        let err = (&plane.as_array() - &generic.as_array())
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(err < 1e-12, "channel {k}: {err}");
    }
    let back = file.inverse().unwrap();
    let err = (&back.planes() - &image.planes())
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(err < 1e-12, "{err}");
    // Five channels have no image layout.
    let five = LatLongMap::<f64>::from_fn(2, 5, |_, o| o.fill(1.0)).unwrap();
    assert_err!(
        five.to_image(crate::SampleDepth::F64),
        InvalidParameter {
            name: "channels",
            ..
        },
        "5 channels"
    );
    let square = image.map_planes(|p| Ok(p.slice(ndarray::s![.., ..16]).to_owned()));
    assert_err!(
        LatLongMap::from_image(&square.unwrap()),
        InvalidShape { .. },
        "twice as wide as it is high"
    );
}

#[test]
fn lookups_are_exact_at_centres_and_continue_over_seam_and_poles() {
    let f = harmonic_map(64, 1);
    let mut v = [0.0];
    for (i, j) in [(0, 0), (5, 127), (63, 64)] {
        let (t, p) = pixel_centre(64, i, j);
        f.bilinear(t, p, &mut v);
        assert!((v[0] - f.as_array()[[i, j, 0]]).abs() < 1e-14);
        f.bicubic(t, p, &mut v);
        assert!((v[0] - f.as_array()[[i, j, 0]]).abs() < 1e-14);
    }
    // Between the first row and the pole, on the seam: interpolation across both. Measured
    // worst errors: bilinear 3.5e-4, bicubic 3.2e-6; bounds 2x and 3x.
    let step = PI / 64.0;
    for (theta, phi) in [
        (0.1 * step, 0.01),
        (PI - 0.2 * step, 2.0 * PI - 0.001),
        (0.3 * step, 3.0),
    ] {
        let want = harmonic(direction(theta, phi));
        f.bilinear(theta, phi, &mut v);
        assert!(
            (v[0] - want).abs() < 7e-4,
            "bilinear {theta} {phi}: {}",
            v[0] - want
        );
        f.bicubic(theta, phi, &mut v);
        assert!(
            (v[0] - want).abs() < 1e-5,
            "bicubic {theta} {phi}: {}",
            v[0] - want
        );
    }
}

#[test]
fn f32_agrees_with_f64() {
    let f = harmonic_map(32, 1);
    let f32map = LatLongMap::new(f.as_array().mapv(|v| v as f32)).unwrap();
    let r = compound();
    let a = rotate_map(&f, &r, &sphere_options(Method::Haar, None)).unwrap();
    let b = rotate_map(&f32map, &r, &sphere_options(Method::Haar, None)).unwrap();
    let err = max_abs_diff(&a.map.into_array(), &b.map.into_array().mapv(|v| v as f64));
    // Measured 5.7e-7 (f32 rounding of values about 1); bound 3.5x.
    assert!(err < 2e-6, "{err}");
}

#[test]
fn bad_input_is_an_error() {
    let f = harmonic_map(16, 1);
    let r = compound();
    let too_deep = SphereOptions {
        level: Some(4),
        ..Default::default()
    };
    assert_err!(
        rotate_map(&f, &r, &too_deep),
        InvalidParameter { name: "level", .. },
        "detail levels 0..=3"
    );
    let odd = LatLongMap::<f64>::from_fn(12, 1, |_, o| o[0] = 1.0).unwrap();
    assert_err!(
        rotate_map(&odd, &r, &SphereOptions::default()),
        InvalidShape { .. },
        "[12, 24]",
        "power of two"
    );
    let few = SphereOptions {
        method: Method::Reference,
        reference_samples: 0,
        ..Default::default()
    };
    assert_err!(
        rotate_map(&f, &r, &few),
        InvalidParameter {
            name: "samples",
            ..
        },
        "0 samples per axis"
    );
    assert_err!(
        SphereRotation::from_degrees(0.0, f64::INFINITY, 0.0),
        InvalidParameter { name: "pitch", .. },
        "inf degrees"
    );
    assert_err!(
        SphereRotation::from_matrix([[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        InvalidParameter {
            name: "rotation",
            ..
        },
        "not a rotation matrix"
    );
    let mut nan = f.clone().into_array();
    nan[[3, 4, 0]] = f64::NAN;
    assert_err!(LatLongMap::new(nan), NonFinite { .. }, "index [3, 4, 0]");
    assert_err!(
        LatLongMap::<f64>::from_fn(0, 1, |_, _| ()),
        InvalidShape { .. },
        "1 to 2^20 rows"
    );
}

/// The pixel of an `h`-row map that contains direction `d`.
fn pixel_of(h: usize, d: [f64; 3]) -> (usize, usize) {
    let (t, p) = angles(d);
    let step = PI / h as f64;
    (
        ((t / step) as usize).min(h - 1),
        ((p / step) as usize).min(2 * h - 1),
    )
}

/// Distance in pixels between two pixels, the columns taken around the seam.
fn pixel_distance(a: (usize, usize), b: (usize, usize), w: usize) -> usize {
    let dc = a.1.abs_diff(b.1);
    a.0.abs_diff(b.0).max(dc.min(w - dc))
}

#[test]
fn the_sun_lands_where_the_reference_puts_it() {
    let f = rooitou();
    // The full-resolution map's brightest pixel, column 614 and row 226 of 1024 x 512
    // (testdata/envmaps/SOURCES.md), seen through the same geometry at 256 x 128.
    let (t, p) = pixel_centre(512, 226, 614);
    let sun = direction(t, p);
    assert_eq!(pixel_of(128, sun), (56, 153));
    assert_eq!(f.brightest(), (56, 153));
    for rotation in [
        SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap(),
        SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap(),
        SphereRotation::from_degrees(40.0, -25.0, 60.0).unwrap(),
    ] {
        // g(p) = f(R p): the sun appears along R^-1 sun.
        let predicted = pixel_of(128, rotation.inverse().apply(sun));
        let truth = rotate_map(&f, &rotation, &sphere_options(Method::Reference, None)).unwrap();
        let at = truth.map.brightest();
        assert!(
            pixel_distance(at, predicted, 256) <= 1,
            "{at:?} vs {predicted:?}"
        );
        for method in [Method::Bilinear, Method::Bicubic, Method::Haar] {
            let g = rotate_map(&f, &rotation, &sphere_options(method, None)).unwrap();
            let here = g.map.brightest();
            assert!(
                pixel_distance(here, at, 256) <= 1,
                "{method}: {here:?} vs {at:?}"
            );
        }
    }
}

#[test]
fn real_map_energy_within_tolerance() {
    // Rooitou park: 63% of the energy is in a sun of a few pixels, the hardest case. The
    // reference keeps energy to the accuracy of its quadrature; the Haar method exactly (by
    // its choice of scaling coefficients); one-sample methods miss or double-count part of
    // the sun. Measured at pitch 30: reference 1.4e-4, haar 1.4e-8 (f32), bilinear 3.1e-3,
    // bicubic -1.5e-3. Bounds about 2x (the Haar one 7x: an f32 sum over the map).
    let f = rooitou();
    let r = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
    for (method, bound) in [
        (Method::Reference, 3e-4),
        (Method::Haar, 1e-7),
        (Method::Bilinear, 6e-3),
        (Method::Bicubic, 3e-3),
    ] {
        let g = rotate_map(&f, &r, &sphere_options(method, None)).unwrap();
        let e = relative_energy_error(&g.map, &f);
        assert!(e.abs() < bound, "{method}: {e}");
    }
}

/// The polynomial `atan2` against the C library's: every angle of a fine sweep at several
/// magnitudes (both reductions and all eight octants), within 2 ulp of pi; signed zeros,
/// infinities and NaN as the C library has them.
#[test]
fn fast_atan2_matches_the_c_library() {
    use super::latlong::atan2;
    let mut worst = 0.0f64;
    for k in 0..200_000 {
        let a = -PI + 2.0 * PI * (k as f64 + 0.37) / 200_000.0;
        for scale in [1e-300, 1e-8, 1.0, 3.7e5, 1e300] {
            let (y, x) = (scale * a.sin(), scale * a.cos());
            worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
        }
    }
    assert!(worst <= 9e-16, "worst difference {worst:e}");
    // Axes and diagonals (texel edges) bit for bit, with every sign of zero and infinity.
    let specials = [0.0, -0.0, 1.0, -1.0, 2.5, f64::INFINITY, f64::NEG_INFINITY];
    for &y in &specials {
        for &x in &specials {
            if y.abs() == x.abs() || y == 0.0 || x == 0.0 || y.is_infinite() || x.is_infinite() {
                assert_eq!(
                    atan2(y, x).to_bits(),
                    y.atan2(x).to_bits(),
                    "atan2({y}, {x})"
                );
            }
        }
    }
    assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
}

proptest::proptest! {
    /// Any finite pair, including ones far apart in magnitude.
    #[test]
    fn fast_atan2_is_within_two_ulp(y in -1e10f64..1e10, x in -1e10f64..1e10, e in -200i32..200) {
        let y = y * 2f64.powi(e);
        let a = super::latlong::atan2(y, x);
        proptest::prop_assert!((a - y.atan2(x)).abs() <= 9e-16, "atan2({}, {}) = {}", y, x, a);
    }
}

/// A zonal source takes the shorter path; the same source with one texel nudged off
/// zonality by 1e-13 takes the general one, and the two agree to the nudge.
#[test]
fn the_zonal_path_is_the_general_chain_rule() {
    use super::chain_rule::{Rotator, Scheme};
    let lobe = LatLongMap::<f64>::from_fn(32, 2, |d, out| {
        out[0] = d[1].max(0.0).powi(30);
        out[1] = (2.0 * d[1]).exp();
    })
    .unwrap();
    let mut nudged = lobe.as_array().to_owned();
    nudged[[7, 11, 0]] += 1e-13;
    let nudged = LatLongMap::new(nudged).unwrap();
    for scheme in [Scheme::Linear, Scheme::Cubic] {
        let (zonal, general) = (
            Rotator::new(&lobe, scheme).unwrap(),
            Rotator::new(&nudged, scheme).unwrap(),
        );
        assert!(zonal.is_zonal() && !general.is_zonal());
        for r in [
            compound(),
            SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap(),
        ] {
            let (a, b) = (zonal.rotate(&r).unwrap(), general.rotate(&r).unwrap());
            let diff = max_abs_diff(&a.as_array().to_owned(), &b.as_array().to_owned());
            assert!(diff < 1e-11, "{scheme:?}: {diff}");
        }
    }
}

/// An `f32` lobe takes the zonal path with its geometry in `f32` (the pre-image angles and
/// the chain rule's factors, eight lanes wide): its rotation stays within 2e-7 of the lobe's
/// peak of the `f64` one (measured 5e-8: `f32`'s own rounding), far below the method's own
/// error (about 1e-3 of the peak here).
#[test]
fn an_f32_lobe_rotates_as_the_f64_lobe_does() {
    use super::chain_rule::{Rotator, Scheme};
    let lobe = |d: [f64; 3]| 52.0 / (2.0 * PI) * d[1].max(0.0).powi(50);
    let wide = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = lobe(d)).unwrap();
    let narrow = LatLongMap::<f32>::from_fn(64, 1, |d, out| out[0] = lobe(d) as f32).unwrap();
    let peak = wide.as_array().iter().fold(0.0f64, |a, v| a.max(*v));
    for scheme in [Scheme::Linear, Scheme::Cubic] {
        let (a, b) = (
            Rotator::new(&wide, scheme).unwrap(),
            Rotator::new(&narrow, scheme).unwrap(),
        );
        assert!(a.is_zonal() && b.is_zonal());
        for r in [
            compound(),
            SphereRotation::from_degrees(10.0, 90.0, 0.0).unwrap(),
        ] {
            let wide = a.rotate(&r).unwrap().as_array().to_owned();
            let narrow = b.rotate(&r).unwrap().as_array().mapv(f64::from);
            let diff = max_abs_diff(&wide, &narrow) / peak;
            assert!(diff < 2e-7, "{scheme:?}: {diff:e} of the peak");
        }
    }
}

/// Reading the fields `k` columns on is rotating the turned map, for both schemes.
#[test]
fn a_turned_rotation_is_the_rotation_of_the_turned_map() {
    use super::chain_rule::{Rotator, Scheme};
    let f = harmonic_map(16, 2);
    for scheme in [Scheme::Linear, Scheme::Cubic] {
        let rotator = Rotator::new(&f, scheme).unwrap();
        for k in [1, 7, 16, 31] {
            let turned = Rotator::new(&yaw::yaw_pixels(&f, k), scheme).unwrap();
            let (a, b) = (
                rotator.rotate_turned(&compound(), k).unwrap(),
                turned.rotate(&compound()).unwrap(),
            );
            let diff = max_abs_diff(&a.as_array().to_owned(), &b.as_array().to_owned());
            assert!(diff < 1e-13, "{scheme:?} k = {k}: {diff}");
        }
    }
}

/// The midpoint rule written out: every sample's direction from its own angles, each weighted
/// by its `sin theta`, a bilinear lookup at the rotated direction. `from_fn_mean` tabulates
/// the sines and cosines and the lookup skips the seam arithmetic inside the map; the values
/// must be the same, bit for bit (the source-resolution lighting rotation depends on it).
#[test]
fn the_reference_is_the_midpoint_rule_written_out_bit_for_bit() {
    let (h, samples) = (8, 3);
    let g = LatLongMap::<f64>::from_fn(h, 3, |d, o| {
        for (c, v) in o.iter_mut().enumerate() {
            *v = harmonic(d) + c as f64 * d[0];
        }
    })
    .unwrap();
    let r = SphereRotation::from_degrees(17.0, 40.0, -23.0).unwrap();
    let got = reference::reference(&g, &r, samples).unwrap();
    let step = PI / h as f64;
    let sub = step / samples as f64;
    for i in 0..h {
        for j in 0..2 * h {
            let (mut acc, mut total) = ([0.0f64; 3], 0.0);
            for a in 0..samples {
                let theta = i as f64 * step + (a as f64 + 0.5) * sub;
                let weight = theta.sin();
                total += weight * samples as f64;
                for b in 0..samples {
                    let phi = j as f64 * step + (b as f64 + 0.5) * sub;
                    let (t, p) = angles(r.apply(direction(theta, phi)));
                    let mut value = [0.0; 3];
                    g.bilinear(t, p, &mut value);
                    for (s, v) in acc.iter_mut().zip(value) {
                        *s += weight * v;
                    }
                }
            }
            for (c, s) in acc.iter().enumerate() {
                assert_eq!(got.as_array()[[i, j, c]], s / total, "({i}, {j}, {c})");
            }
        }
    }
}
