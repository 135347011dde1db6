//! The texel product against the quadtree product and the pixel sums.

use ndarray::Array4;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::*;
use crate::product::multiply::product;
use crate::product::{FaceLayout, HaarTree};

/// A random sparse function on `faces x s^2`: the scaling coefficients and about `density`
/// of the details, `c` channels, ascending indices.
fn sparse(rng: &mut StdRng, faces: usize, s: usize, density: f64) -> Vec<u32> {
    (0..faces * s * s)
        .filter(|i| i % (s * s) == 0 || rng.random_bool(density))
        .map(|i| i as u32)
        .collect()
}

fn tree_of(faces: usize, s: usize, indices: &[u32], values: &[[f64; 3]]) -> HaarTree<f64, 3> {
    HaarTree::from_sparse(faces, s, FaceLayout::Stacked, indices, values).unwrap()
}

/// The dense `(faces, s, s, 3)` coefficients of a sparse RGB function.
fn dense(faces: usize, s: usize, indices: &[u32], values: &[[f64; 3]]) -> Array4<f64> {
    let mut out = Array4::zeros((faces, s, s, 3));
    for (&i, v) in indices.iter().zip(values) {
        let i = i as usize;
        for c in 0..3 {
            out[[i / (s * s), (i / s) % s, i % s, c]] = v[c];
        }
    }
    out
}

#[test]
fn the_texel_product_is_the_quadtree_product() {
    let mut rng = StdRng::seed_from_u64(7);
    for case in 0..24 {
        let (faces, s) = [(2, 8), (6, 4), (1, 16), (2, 1)][case % 4];
        let factors = 1 + case % 4;
        let mut p = TexelProduct::<f64>::new(faces, s).unwrap();
        let mut trees = Vec::new();
        for k in 0..factors {
            let indices = sparse(&mut rng, faces, s, 0.2);
            // Every other factor one channel (the same for every colour).
            let rgb = (k + case) % 2 == 0;
            let values: Vec<[f64; 3]> = indices
                .iter()
                .map(|_| {
                    let v: f64 = rng.random_range(-2.0..2.0);
                    if rgb {
                        std::array::from_fn(|_| rng.random_range(-2.0..2.0))
                    } else {
                        [v; 3]
                    }
                })
                .collect();
            if rgb {
                p.multiply(&indices, &values).unwrap();
            } else {
                let one: Vec<f64> = values.iter().map(|v| v[0]).collect();
                p.multiply(&indices, &one).unwrap();
            }
            trees.push(tree_of(faces, s, &indices, &values));
        }
        let refs: Vec<&HaarTree<f64, 3>> = trees.iter().collect();
        let want = product(&refs).unwrap().to_coefficients();
        let (mut indices, mut values) = (Vec::new(), Vec::new());
        p.sparse_coefficients(&mut indices, &mut values);
        let got = dense(faces, s, &indices, &values);
        let scale = want.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let err = (&got - &want).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(err < 1e-12 * scale, "case {case}: {err:e} of {scale}");
        // Nothing listed is zero, and every non-zero coefficient is listed.
        assert!(values.iter().all(|v| v.iter().any(|x| *x != 0.0)));
        let nonzero = want
            .as_slice()
            .unwrap()
            .chunks(3)
            .filter(|c| c.iter().any(|x| x.abs() > 1e-9 * scale))
            .count();
        assert!(indices.len() >= nonzero, "case {case}");
    }
}

#[test]
fn a_dot_with_the_product_is_the_weighted_pixel_sum() {
    let mut rng = StdRng::seed_from_u64(11);
    let (faces, s) = (2, 8);
    // Two one-channel factors and a transport g, all sparse, as pixels for the oracle.
    let mut pixels = Vec::new();
    let mut p = TexelProduct::<f64>::new(faces, s).unwrap();
    for _ in 0..2 {
        let indices = sparse(&mut rng, faces, s, 0.3);
        let values: Vec<f64> = indices.iter().map(|_| rng.random_range(0.0..1.0)).collect();
        p.multiply(&indices, &values).unwrap();
        let rgb: Vec<[f64; 3]> = values.iter().map(|&v| [v; 3]).collect();
        pixels.push(tree_of(faces, s, &indices, &rgb).to_pixels().unwrap());
    }
    let gi = sparse(&mut rng, faces, s, 0.5);
    let gv: Vec<[f64; 3]> = gi
        .iter()
        .map(|_| std::array::from_fn(|_| rng.random_range(-1.0..1.0)))
        .collect();
    let g = tree_of(faces, s, &gi, &gv).to_pixels().unwrap();
    let got = p.dot(&gi, &gv).unwrap();
    // Orthonormal coefficients: the coefficient dot is the pixel dot.
    for c in 0..3 {
        let want: f64 = ndarray::Zip::from(g.index_axis(ndarray::Axis(3), c))
            .and(pixels[0].index_axis(ndarray::Axis(3), c))
            .and(pixels[1].index_axis(ndarray::Axis(3), c))
            .fold(0.0, |acc, &a, &b, &d| acc + a * b * d);
        assert!(
            (got[c] - want).abs() < 1e-12 * want.abs().max(1.0),
            "{got:?} {want}"
        );
    }
    // A one-channel g takes every channel of the product.
    let one: Vec<f64> = gv.iter().map(|v| v[1]).collect();
    assert_eq!(p.dot(&gi, &one).unwrap(), [got[1]; 3]);
}

#[test]
fn the_empty_product_is_one_and_a_shared_factor_multiplies_once_transformed() {
    let (faces, s) = (2, 4);
    let mut p = TexelProduct::<f32>::new(faces, s).unwrap();
    let (mut indices, mut values) = (Vec::new(), Vec::new());
    p.sparse_coefficients(&mut indices, &mut values);
    // The constant 1: on each face only the scaling coefficient, the pixel sum over S.
    assert_eq!(indices, [0, 16]);
    assert_eq!(values, [[4.0f32; 3]; 2]);
    let mut shared = TexelProduct::<f32>::new(faces, s).unwrap();
    shared
        .multiply(
            &[0, 3, 16],
            &[[8.0f32, 4.0, 2.0], [1.0, 2.0, 3.0], [4.0, 4.0, 4.0]],
        )
        .unwrap();
    let mut direct = TexelProduct::<f32>::new(faces, s).unwrap();
    direct
        .multiply(
            &[0, 3, 16],
            &[[8.0f32, 4.0, 2.0], [1.0, 2.0, 3.0], [4.0, 4.0, 4.0]],
        )
        .unwrap();
    direct.multiply(&[0, 1, 16], &[2.0f32, 0.5, 1.0]).unwrap();
    p.multiply(&[0, 1, 16], &[2.0f32, 0.5, 1.0]).unwrap();
    p.multiply_by(&shared).unwrap();
    let (mut i2, mut v2) = (Vec::new(), Vec::new());
    p.sparse_coefficients(&mut indices, &mut values);
    direct.sparse_coefficients(&mut i2, &mut v2);
    assert_eq!((indices, values), (i2, v2));
    // After a reset the product is 1 again.
    p.reset();
    assert_eq!(p.dot(&[0, 16], &[1.0f32, 1.0]).unwrap(), [8.0; 3]);
}

#[test]
fn a_depth_limit_carries_over_exactly() {
    // Factors with details on levels 0 and 1 only (S = 8: rows and columns below 4).
    let mut rng = StdRng::seed_from_u64(3);
    let (faces, s) = (2, 8);
    let mut p = TexelProduct::<f32>::new(faces, s).unwrap();
    for _ in 0..3 {
        let indices: Vec<u32> = sparse(&mut rng, faces, s, 0.6)
            .into_iter()
            .filter(|&i| (i as usize / s) % s < 4 && (i as usize) % s < 4)
            .collect();
        let values: Vec<f32> = indices.iter().map(|_| rng.random_range(0.1..1.0)).collect();
        p.multiply(&indices, &values).unwrap();
    }
    let (mut indices, mut values) = (Vec::new(), Vec::new());
    p.sparse_coefficients(&mut indices, &mut values);
    assert!(indices.len() > 8);
    assert!(
        indices
            .iter()
            .all(|&i| (i as usize / s) % s < 4 && (i as usize) % s < 4)
    );
}

#[test]
fn bad_factors_and_faces_are_refused() {
    assert_err!(
        TexelProduct::<f64>::new(0, 4),
        InvalidShape { .. },
        "[0, 4, 4, 1]"
    );
    assert_err!(
        TexelProduct::<f64>::new(2, 6),
        InvalidShape { .. },
        "[2, 6, 6, 1]"
    );
    assert_err!(
        TexelProduct::<f64>::new(2, 0),
        InvalidShape { .. },
        "[2, 0, 0, 1]"
    );
    let mut p = TexelProduct::<f64>::new(2, 4).unwrap();
    assert_err!(
        p.multiply(&[32], &[1.0]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "below 32"
    );
    assert_err!(
        p.multiply(&[1, 2], &[1.0]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "2 indices and 1 values"
    );
    assert_err!(
        p.multiply(&[1], &[f64::NAN]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "finite"
    );
    assert_err!(
        p.multiply(&[1], &[[1.0, f64::INFINITY, 0.0]]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "finite"
    );
    assert_err!(
        p.dot(&[40], &[1.0]),
        InvalidParameter {
            name: "coefficients",
            ..
        },
        "below 32"
    );
    assert_err!(
        p.multiply_by(&TexelProduct::new(6, 4).unwrap()),
        InvalidShape { .. },
        "different faces"
    );
    // A refused factor left the product as it was.
    assert_eq!(p.dot(&[0], &[1.0]).unwrap(), [4.0; 3]);
}
