//! Rotations at a coarser level than the map's finest: the Haar path against the reference
//! reduced to the same level, level 0 on a 2-row map, and whole-column yaws combined with a
//! level. The reduction (block means) and the column roll are written here from their
//! definitions, not with the module's `downsample`, `truncated` or `roll_columns`.

use crate::test_support::sphere_options;
use ndarray::Array3;

use super::{LatLongMap, Method, SphereRotation, rotate_map};

/// A smooth function on the sphere (degree-2 polynomial of the direction) in two channels.
fn smooth(h: usize) -> LatLongMap<f64> {
    LatLongMap::from_fn(h, 2, |[x, y, z], out| {
        let v = 1.0 + 0.6 * x - 0.3 * z + 0.4 * y * z + 0.2 * (3.0 * y * y - 1.0) + 0.3 * x * y;
        out[0] = v;
        out[1] = 2.0 - 0.5 * v;
    })
    .unwrap()
}

/// Every `b x b` block of the `(H, W, C)` array replaced by its mean: the map reduced to the
/// Haar approximation of blocks of `b` pixels.
pub(super) fn block_means(a: &Array3<f64>, b: usize) -> Array3<f64> {
    let (h, w, c) = a.dim();
    Array3::from_shape_fn((h, w, c), |(i, j, k)| {
        let (i0, j0) = (i / b * b, j / b * b);
        let mut sum = 0.0;
        for r in i0..i0 + b {
            for s in j0..j0 + b {
                sum += a[[r, s, k]];
            }
        }
        sum / (b * b) as f64
    })
}

/// `out[i][j] = a[i][(j + k) mod W]`: the yaw by `k` whole columns.
fn roll(a: &Array3<f64>, k: usize) -> Array3<f64> {
    let (h, w, c) = a.dim();
    Array3::from_shape_fn((h, w, c), |(i, j, ch)| a[[i, (j + k) % w, ch]])
}

/// The root mean square difference, every pixel alike.
fn rms(a: &Array3<f64>, b: &Array3<f64>) -> f64 {
    assert_eq!(a.dim(), b.dim());
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

/// The Haar path at levels 3 and 2 of a 32-row map (finest 4) against the reference
/// rotation (8 x 8 samples per pixel) at full resolution, reduced to block means of the same
/// level. Measured RMS: 2.30e-3 and 1.09e-2 (level 3, 2); the bounds are 1.5x those. A path
/// that computed one level coarser than asked would be off by 4.7x (level 2's figure at
/// level 3).
#[test]
fn coarse_haar_levels_match_the_reduced_reference() {
    let h = 32;
    let f = smooth(h);
    let r = SphereRotation::from_degrees(20.0, 35.0, 10.0).unwrap();
    let truth = rotate_map(&f, &r, &sphere_options(Method::Reference, None))
        .unwrap()
        .map
        .into_array();
    for (level, measured) in [(3usize, 2.30e-3), (2, 1.09e-2)] {
        let block = h >> (level + 1);
        let want = block_means(&truth, block);
        let got = rotate_map(&f, &r, &sphere_options(Method::Haar, Some(level)))
            .unwrap()
            .map
            .into_array();
        // The result is constant on the level's blocks.
        assert!(
            rms(&got, &block_means(&got, block)) < 1e-12,
            "level {level}"
        );
        let err = rms(&got, &want);
        assert!(err <= 1.5 * measured, "level {level}: {err:e}");
    }
}

/// A 2-row map (4 columns) has one detail level, 0: asking for it is the full computation
/// for every method; a constant stays constant; whole-column yaws (quarter turns) roll the
/// columns exactly; and the Haar result is within its measured distance of the reference
/// (RMS 4.18e-2; bound 1.5x).
#[test]
fn level_zero_on_a_two_row_map() {
    let f = smooth(2);
    let a = f.as_array().to_owned();
    let r = SphereRotation::from_degrees(20.0, 35.0, 10.0).unwrap();
    for &method in Method::ALL {
        let full = rotate_map(&f, &r, &sphere_options(method, None)).unwrap();
        let zero = rotate_map(&f, &r, &sphere_options(method, Some(0))).unwrap();
        assert_eq!(zero, full, "{method}");
        let constant = LatLongMap::<f64>::from_fn(2, 1, |_, out| out[0] = 3.5).unwrap();
        let c = rotate_map(&constant, &r, &sphere_options(method, Some(0))).unwrap();
        assert!(
            c.map.as_array().iter().all(|&v| (v - 3.5).abs() < 1e-12),
            "{method}: {:?}",
            c.map.as_array()
        );
        for k in 1..4usize {
            let yaw = SphereRotation::from_degrees(90.0 * k as f64, 0.0, 0.0).unwrap();
            let g = rotate_map(&f, &yaw, &sphere_options(method, Some(0))).unwrap();
            assert_eq!(g.map.as_array(), roll(&a, k), "{method} k={k}");
        }
    }
    let truth = rotate_map(&f, &r, &sphere_options(Method::Reference, None))
        .unwrap()
        .map
        .into_array();
    let haar = rotate_map(&f, &r, &sphere_options(Method::Haar, Some(0)))
        .unwrap()
        .map
        .into_array();
    let err = rms(&haar, &truth);
    assert!(err <= 1.5 * 4.18e-2, "{err:e}");
}

/// A whole-column yaw with a level: every method gives the rolled map reduced to the level's
/// block means (to rounding), for shifts that are and are not multiples of the block width.
#[test]
fn whole_column_yaws_with_a_level_are_the_reduced_rolled_map() {
    let h = 16;
    let f = smooth(h);
    let a = f.as_array().to_owned();
    for k in [1usize, 3, 8, 12, 31] {
        let r = SphereRotation::from_degrees(k as f64 * 360.0 / 32.0, 0.0, 0.0).unwrap();
        for level in 0..3usize {
            let want = block_means(&roll(&a, k), h >> (level + 1));
            for &method in Method::ALL {
                let got = rotate_map(&f, &r, &sphere_options(method, Some(level)))
                    .unwrap()
                    .map
                    .into_array();
                let err = got
                    .iter()
                    .zip(&want)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max);
                assert!(err < 1e-13, "{method} k={k} level {level}: {err:e}");
            }
        }
    }
}
