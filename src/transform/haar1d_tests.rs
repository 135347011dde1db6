use super::*;
use crate::transform::basis::haar_basis_1d;

/// Each coefficient is the inner product of the signal with its Haar basis function.
#[test]
fn coefficients_are_inner_products_with_the_basis() {
    for depth in 0..=6usize {
        let len = 1 << depth;
        let x: Vec<f64> = (0..len).map(|i| ((i * 7919) % 113) as f64 - 50.3).collect();
        for levels in 0..=depth {
            for &norm in Normalization::ALL {
                let mut c = x.clone();
                forward_in_place(&mut c, levels, norm, &mut Vec::new()).unwrap();
                for (k, &ck) in c.iter().enumerate() {
                    let basis = haar_basis_1d(len, levels, k, norm);
                    let ip: f64 = basis.iter().zip(&x).map(|(b, v)| b * v).sum();
                    assert!(
                        (ip - ck).abs() < 1e-12,
                        "len {len} levels {levels} k {k} {norm:?}"
                    );
                }
                let mut back = c.clone();
                inverse_in_place(&mut back, levels, norm, &mut Vec::new()).unwrap();
                for (a, b) in back.iter().zip(&x) {
                    assert!((a - b).abs() < 1e-12);
                }
            }
        }
    }
}

#[test]
fn rejects_bad_lengths_and_levels() {
    let mut s = Vec::new();
    assert_err!(
        forward_in_place(&mut [1.0f64; 3], 1, Normalization::Average, &mut s),
        InvalidShape { .. },
        "[3]",
        "power of two"
    );
    assert_err!(
        forward_in_place(&mut [0.0f64; 0], 0, Normalization::Average, &mut s),
        InvalidShape { .. },
        "[0]",
        "non-zero power of two"
    );
    assert_err!(
        forward_in_place(&mut [1.0f64; 4], 3, Normalization::Average, &mut s),
        InvalidParameter { name: "levels", .. },
        "at most 2"
    );
    let mut s32: Vec<f32> = Vec::new();
    assert_err!(
        inverse_in_place(&mut [1.0f32; 4], 3, Normalization::Average, &mut s32),
        InvalidParameter { name: "levels", .. },
        "at most 2"
    );
}
