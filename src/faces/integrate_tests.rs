use super::*;
use crate::sphere::latlong::pixel_solid_angle;
use ndarray::Array3;

fn positive_map(h: usize, channels: usize, seed: u64) -> LatLongMap<f64> {
    // A deterministic pseudo-random positive map.
    let mut x = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let data = Array3::from_shape_fn((h, 2 * h, channels), |_| {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        0.1 + (x >> 11) as f64 / (1u64 << 53) as f64
    });
    LatLongMap::new(data).unwrap()
}

/// `sum over pixels of prod_k f_k(p) x solid_angle(p)` per channel, broadcasting one
/// channel: the contract, computed directly.
fn pixel_sum(maps: &[LatLongMap<f64>]) -> Vec<f64> {
    let h = maps[0].height();
    let c = maps.iter().map(|m| m.channels()).max().unwrap();
    (0..c)
        .map(|k| {
            let mut sum = 0.0;
            for i in 0..h {
                for j in 0..2 * h {
                    let p: f64 = maps
                        .iter()
                        .map(|m| m.as_array()[[i, j, k.min(m.channels() - 1)]])
                        .product();
                    sum += p * pixel_solid_angle(h, i);
                }
            }
            sum
        })
        .collect()
}

#[test]
fn every_method_equals_the_pixel_sum_with_everything_kept() {
    let maps = [
        positive_map(16, 3, 1),
        positive_map(16, 1, 2),
        positive_map(16, 3, 3),
    ];
    let want = pixel_sum(&maps);
    for &method in IntegralMethod::ALL {
        let o = IntegrateOptions {
            method,
            ..Default::default()
        };
        let got = integrate(&maps, &o).unwrap();
        for (g, w) in got.value.iter().zip(&want) {
            assert!((g - w).abs() < 1e-12 * w, "{method}: {g} vs {w}");
        }
        assert_eq!(got.kept, vec![16 * 32 - 2; 3]);
    }
}

#[test]
fn f32_maps_integrate_within_single_precision() {
    let maps = [
        positive_map(16, 3, 11),
        positive_map(16, 1, 12),
        positive_map(16, 3, 13),
    ];
    let want = pixel_sum(&maps);
    let single: Vec<LatLongMap<f32>> = maps
        .iter()
        .map(|m| LatLongMap::new(m.as_array().mapv(|v| v as f32)).unwrap())
        .collect();
    for &method in IntegralMethod::ALL {
        let o = IntegrateOptions {
            method,
            ..Default::default()
        };
        let got = integrate(&single, &o).unwrap();
        for (g, w) in got.value.iter().zip(&want) {
            let err = ((g - w) / w).abs();
            // f32 rounding of the maps and the weights (~1e-7 each), not f64's 1e-12.
            assert!(
                err < 1e-5 && err > 1e-12,
                "{method}: {g} vs {w} ({err:.1e})"
            );
        }
    }
}

#[test]
fn a_whole_column_yaw_of_every_map_leaves_the_integral_unchanged() {
    let maps = [
        positive_map(16, 3, 6),
        positive_map(16, 1, 7),
        positive_map(16, 3, 8),
    ];
    let turned = |m: &LatLongMap<f64>, k: usize| {
        let a = m.as_array();
        let w = a.dim().1;
        LatLongMap::new(Array3::from_shape_fn(a.dim(), |(i, j, c)| {
            a[[i, (j + k) % w, c]]
        }))
        .unwrap()
    };
    for &method in IntegralMethod::ALL {
        let o = IntegrateOptions {
            method,
            ..Default::default()
        };
        let want = integrate(&maps, &o).unwrap().value;
        // Whole columns within a face, across the seam between the faces, and half a turn
        // (the faces swap): each gives every method different trees.
        for k in [1, 5, 16, 31] {
            let yawed: Vec<_> = maps.iter().map(|m| turned(m, k)).collect();
            let got = integrate(&yawed, &o).unwrap().value;
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 1e-12 * w, "{method}, k = {k}: {g} vs {w}");
            }
        }
    }
}

#[test]
fn keeping_fewer_coefficients_changes_the_result() {
    let maps = [positive_map(16, 1, 4), positive_map(16, 1, 5)];
    let full = integrate(&maps, &IntegrateOptions::default()).unwrap();
    let o = IntegrateOptions {
        selections: vec![Selection::Largest(20)],
        ..Default::default()
    };
    let pruned = integrate(&maps, &o).unwrap();
    assert_eq!(pruned.kept, vec![20, 20]);
    assert!((pruned.value[0] - full.value[0]).abs() > 1e-6 * full.value[0]);
}

#[test]
fn the_cube_integral_of_one_times_one_is_four_pi() {
    let one = LatLongMap::<f64>::from_fn(16, 1, |_, o| o[0] = 1.0).unwrap();
    for (param, resolution) in [(ParamKind::Cube, None), (ParamKind::Cube, Some(16))] {
        let o = IntegrateOptions {
            param,
            resolution,
            ..Default::default()
        };
        let got = integrate(&[one.clone(), one.clone()], &o).unwrap();
        assert!((got.value[0] - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    }
}

#[test]
fn bad_requests_are_errors() {
    let (a, b) = (positive_map(16, 1, 6), positive_map(8, 1, 7));
    let d = IntegrateOptions::default();
    assert_err!(
        integrate(&[a.clone(), b], &d),
        InvalidShape { .. },
        "different sizes"
    );
    let three = IntegrateOptions {
        method: IntegralMethod::Triple,
        ..Default::default()
    };
    assert_err!(
        integrate(&[a.clone(), a.clone()], &three),
        InvalidParameter { name: "method", .. },
        "exactly 3 maps"
    );
    let deep = IntegrateOptions {
        depth: Some(4),
        ..Default::default()
    };
    assert_err!(
        integrate(&[a.clone(), a.clone()], &deep),
        InvalidParameter { name: "depth", .. },
        "detail level 4"
    );
    let many = IntegrateOptions {
        selections: vec![Selection::Largest(16 * 32)],
        ..Default::default()
    };
    assert_err!(
        integrate(&[a.clone(), a.clone()], &many),
        InvalidParameter { name: "keep", .. },
        "only 510 details"
    );
    let odd = LatLongMap::<f64>::from_fn(6, 1, |_, o| o[0] = 1.0).unwrap();
    assert_err!(
        integrate(&[odd.clone(), odd], &d),
        InvalidShape { .. },
        "height 6 is not a power of two"
    );
}
