//! Oracle tests of the product algebra: everything against brute-force pixel sums.

use ndarray::{Array3, Array4, ArrayView4};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;

mod algebra;
mod fast_paths;
mod integrals;
mod trees;

/// Random `(faces, S, S, C)` values in `[lo, hi)`.
pub(super) fn random_faces(
    seed: u64,
    faces: usize,
    s: usize,
    c: usize,
    lo: f64,
    hi: f64,
) -> Array4<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    Array4::from_shape_fn((faces, s, s, c), |_| rng.random_range(lo..hi))
}

/// Random positive weights, one per pixel.
pub(super) fn random_weights(seed: u64, faces: usize, s: usize) -> Array3<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    Array3::from_shape_fn((faces, s, s), |_| rng.random_range(0.1..2.0))
}

/// The oracle: `sum over pixels of w x prod_k f_k`, per channel, and the same sum of absolute
/// values (the scale against which rounding is judged).
pub(super) fn pixel_oracle(
    weights: &Array3<f64>,
    maps: &[ArrayView4<'_, f64>],
) -> (Vec<f64>, Vec<f64>) {
    let (faces, s, _, c) = maps[0].dim();
    let (mut sum, mut abs) = (vec![0.0; c], vec![0.0; c]);
    for f in 0..faces {
        for i in 0..s {
            for j in 0..s {
                for ch in 0..c {
                    let p = maps
                        .iter()
                        .fold(weights[[f, i, j]], |acc, m| acc * m[[f, i, j, ch]]);
                    sum[ch] += p;
                    abs[ch] += p.abs();
                }
            }
        }
    }
    (sum, abs)
}

/// A transport and factor trees of `maps` (the first weighted) under one selection.
pub(super) fn trees_of<const C: usize>(
    weights: &Array3<f64>,
    maps: &[Array4<f64>],
    layout: FaceLayout,
    selection: Selection,
) -> (Transport<f64, C>, Vec<HaarTree<f64, C>>) {
    let w = WeightedPixels::new(maps[0].view(), weights.view()).unwrap();
    let t = Transport::new(&w, layout, selection).unwrap();
    let factors = maps[1..]
        .iter()
        .map(|m| HaarTree::from_pixels(m.view(), layout, selection).unwrap())
        .collect();
    (t, factors)
}

/// Asserts that with full trees `product_integral` of `maps` (the first weighted by
/// `weights`) equals the weighted pixel sum to 1e-12 relative to the sum of |products|.
pub(super) fn assert_full_integral_is_the_pixel_sum<const C: usize>(
    weights: &Array3<f64>,
    maps: &[Array4<f64>],
    layout: FaceLayout,
    what: &str,
) {
    let (t, f) = trees_of::<C>(weights, maps, layout, Selection::All);
    let refs: Vec<_> = f.iter().collect();
    let got = product_integral(&t, &refs, IntegralOptions::default()).unwrap();
    let views: Vec<_> = maps.iter().map(|m| m.view()).collect();
    let (want, scale) = pixel_oracle(weights, &views);
    assert_close(&got.value, &want, &scale, 1e-12, what);
}

/// Asserts `got` equals `want` to `tol` relative to `scale`, channel by channel.
pub(super) fn assert_close(got: &[f64], want: &[f64], scale: &[f64], tol: f64, what: &str) {
    for ch in 0..want.len() {
        let err = (got[ch] - want[ch]).abs();
        assert!(
            err <= tol * scale[ch].max(f64::MIN_POSITIVE),
            "{what}: channel {ch}: got {}, want {}, error {err:e} > {tol:e} x {}",
            got[ch],
            want[ch],
            scale[ch]
        );
    }
}
