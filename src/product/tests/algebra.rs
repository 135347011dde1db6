//! Basis products and integral coefficients against brute-force pixel sums.

use proptest::prelude::*;

use crate::product::basis::{self, BasisFunction};
use crate::product::coefficient::{
    discrete_integral_coefficient, integral_coefficient, integral_coefficient_by_products,
};
use crate::transform::{Band, Normalization, basis::pyramid_basis};

/// The restricted basis of a `2^n` face: the face's scaling function and every wavelet.
fn restricted(n: u32) -> Vec<BasisFunction> {
    let mut all = vec![BasisFunction::SCALING];
    for level in 0..n as usize {
        for band in basis::WAVELETS {
            for row in 0..1 << level {
                for col in 0..1 << level {
                    all.push(BasisFunction::new(band, level, row, col));
                }
            }
        }
    }
    all
}

#[test]
fn discrete_basis_is_the_transforms_orthonormal_basis() {
    let n = 3;
    for f in restricted(n) {
        let want = pyramid_basis(
            (8, 8),
            3,
            f.band,
            f.level,
            f.row,
            f.col,
            Normalization::Orthonormal,
        );
        assert_eq!(f.discrete(n), want, "{f:?}");
    }
}

#[test]
fn product_of_two_basis_functions_is_their_pointwise_product() {
    // Every band (child scaling functions included) on every node of an 8x8 face.
    let mut all = Vec::new();
    for level in 0..3 {
        for band in basis::BANDS {
            for row in 0..1 << level {
                for col in 0..1 << level {
                    all.push(BasisFunction::new(band, level, row, col));
                }
            }
        }
    }
    let centres: Vec<(f64, f64)> = (0..64)
        .map(|k| (((k % 8) as f64 + 0.5) / 8.0, ((k / 8) as f64 + 0.5) / 8.0))
        .collect();
    for a in &all {
        for b in &all {
            let p = basis::product(a, b);
            for &(x, y) in &centres {
                let want = a.value(x, y) * b.value(x, y);
                let got = p.map_or(0.0, |p| p.magnitude * p.function.value(x, y));
                assert_eq!(got, want, "{a:?} x {b:?} at ({x}, {y})");
            }
        }
    }
}

/// The pixel sum of the product of the discrete functions.
fn brute_force(functions: &[BasisFunction], tables: &[(BasisFunction, Vec<f64>)]) -> f64 {
    let rows: Vec<&Vec<f64>> = functions
        .iter()
        .map(|f| &tables.iter().find(|(g, _)| g == f).unwrap().1)
        .collect();
    (0..rows[0].len())
        .map(|p| rows.iter().map(|r| r[p]).product::<f64>())
        .sum()
}

fn tables(n: u32) -> Vec<(BasisFunction, Vec<f64>)> {
    restricted(n)
        .into_iter()
        .map(|f| (f, f.discrete(n).into_iter().collect()))
        .collect()
}

/// Checks the closed form, the pairwise products and the brute force on one tuple.
fn check(functions: &[BasisFunction], n: u32, tables: &[(BasisFunction, Vec<f64>)]) {
    let closed = integral_coefficient(functions);
    assert_eq!(
        closed,
        integral_coefficient_by_products(functions),
        "{functions:?}"
    );
    let discrete = discrete_integral_coefficient(functions, n);
    let brute = brute_force(functions, tables);
    assert!(
        (discrete - brute).abs() <= 1e-12 * brute.abs().max(1e-300),
        "{functions:?}: closed form {discrete}, pixel sum {brute}"
    );
}

#[test]
fn integral_coefficients_exhaustively_for_two_and_three_functions() {
    for n in [2, 3] {
        let t = tables(n);
        let all = restricted(n);
        let mut nonzero = 0;
        for a in &all {
            for b in &all {
                check(&[*a, *b], n, &t);
                for c in &all {
                    check(&[*a, *b, *c], n, &t);
                    nonzero += usize::from(integral_coefficient(&[*a, *b, *c]) != 0.0);
                }
            }
        }
        // Not vacuous: many triples are non-zero (all three cases of Ng's theorem occur).
        assert!(nonzero > all.len(), "n = {n}: {nonzero} non-zero triples");
    }
}

#[test]
fn integral_coefficients_exhaustively_for_four_functions_on_4x4() {
    let t = tables(2);
    let all = restricted(2);
    for a in &all {
        for b in &all {
            for c in &all {
                for d in &all {
                    check(&[*a, *b, *c, *d], 2, &t);
                }
            }
        }
    }
}

/// A function from a random draw: on the path to `leaf` (at a level no finer) or anywhere.
fn draw(
    n: u32,
    leaf: (usize, usize),
    on_path: bool,
    level: usize,
    band: usize,
    k: usize,
) -> BasisFunction {
    let level = level % n as usize;
    if band == 3 && !on_path {
        return BasisFunction::SCALING;
    }
    let band = basis::WAVELETS[band % 3];
    let (row, col) = if on_path {
        (
            leaf.0 >> (n as usize - 1 - level),
            leaf.1 >> (n as usize - 1 - level),
        )
    } else {
        let side = 1usize << level;
        ((k / side) % side, k % side)
    };
    BasisFunction::new(band, level, row, col)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn integral_coefficients_of_up_to_six_functions(
        n in 3u32..=4,
        leaf in (0usize..16, 0usize..16),
        items in prop::collection::vec((prop::bool::weighted(0.85), 0usize..4, 0usize..4, 0usize..256), 1..=6),
    ) {
        let side = 1usize << (n - 1);
        let leaf = (leaf.0 % side, leaf.1 % side);
        let functions: Vec<_> = items
            .iter()
            .map(|&(on_path, level, band, k)| draw(n, leaf, on_path, level, band, k))
            .collect();
        let t: Vec<_> = functions.iter().map(|f| (*f, f.discrete(n).into_iter().collect())).collect();
        check(&functions, n, &t);
    }
}

#[test]
fn scaling_functions_multiply_to_the_face_area() {
    // N scaling functions: (1/S)^N summed over S^2 pixels.
    for n in 0..5u32 {
        let s = BasisFunction::SCALING;
        let got = discrete_integral_coefficient(&[s; 4], n);
        assert_eq!(got, 4f64.powi(n as i32) / 16f64.powi(n as i32));
    }
    assert_eq!(basis::quadrant_sign(Band::Vertical, 2), -1.0);
}
