use super::*;
use haarshift_testkit::quadrature::sphere_grid;
use std::f64::consts::PI;

#[test]
fn gauss_legendre_integrates_polynomials_exactly() {
    for n in [1, 2, 5, 12, 23] {
        let rule = gauss_legendre(n);
        for p in 0..2 * n {
            let got: f64 = rule.iter().map(|(x, w)| w * x.powi(p as i32)).sum();
            let want = if p % 2 == 0 {
                2.0 / (p + 1) as f64
            } else {
                0.0
            };
            assert!(
                (got - want).abs() < 1e-14,
                "n = {n}, x^{p}: {got} vs {want}"
            );
        }
        // One degree more is not exact: the rule has exactly the order it claims (its error on
        // x^2n is 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^2): 1.8e-7 at n = 12, 4.5e-14 at 23).
        let p = 2 * n;
        let got: f64 = rule.iter().map(|(x, w)| w * x.powi(p as i32)).sum();
        assert!((got - 2.0 / (p + 1) as f64).abs() > 1e-14, "n = {n}");
    }
}

#[test]
fn coefficients_match_brute_force_integration() {
    // Every one of the 25^3 triples of 5 bands, on a fine grid (composite Boole in cos
    // theta, 1024 steps, error ~1e-13 here), not a Gauss rule: stored values and the zeros.
    let bands = 5;
    let g = Gaunt::new(bands).unwrap();
    let sh = SphericalHarmonics::new(bands).unwrap();
    let n = sh.len();
    let grid = sphere_grid(1024, 4 * bands);
    let mut table = vec![0.0; grid.len() * n];
    for ((d, _), y) in grid.iter().zip(table.chunks_exact_mut(n)) {
        sh.evaluate(*d, y);
    }
    let mut worst = 0.0f64;
    let mut non_zero = 0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let brute: f64 = table
                    .chunks_exact(n)
                    .zip(&grid)
                    .map(|(y, (_, w))| w * y[i] * y[j] * y[k])
                    .sum();
                let got = g.get(i, j, k);
                worst = worst.max((got - brute).abs());
                if brute.abs() > 1e-10 {
                    non_zero += 1;
                    assert!(selection_rules(i, j, k), "({i}, {j}, {k}) = {brute}");
                }
            }
        }
    }
    assert!(worst < 1e-10, "{worst:e}");
    assert_eq!(non_zero, g.entries().len());
    eprintln!(
        "5 bands: {non_zero} of {} non-zero, worst {worst:e}",
        n * n * n
    );
}

#[test]
fn the_constant_harmonic_couples_each_function_to_itself() {
    let g = Gaunt::new(8).unwrap();
    let n = 64;
    for i in 0..n {
        for j in 0..n {
            let want = if i == j { 0.5 / PI.sqrt() } else { 0.0 };
            for got in [g.get(i, j, 0), g.get(0, i, j), g.get(i, 0, j)] {
                assert!((got - want).abs() < 4e-15, "({i}, {j}): {got} vs {want}");
            }
        }
    }
}

#[test]
fn a_product_of_low_degrees_is_expanded_exactly() {
    // Y_i Y_j has degree l_i + l_j: when that is below B, sum_k G_ijk Y_k(w) = Y_i(w) Y_j(w)
    // at every direction, which checks all 8 bands' coefficients and their signs.
    let bands = 8;
    let g = Gaunt::new(bands).unwrap();
    let sh = SphericalHarmonics::new(bands).unwrap();
    let n = sh.len();
    let mut y = vec![0.0; n];
    let mut worst = 0.0f64;
    for (d, _) in sphere_grid(12, 7) {
        sh.evaluate(d, &mut y);
        for i in 0..n {
            for j in 0..n {
                if degree_order(i).0 + degree_order(j).0 >= bands {
                    continue;
                }
                let sum: f64 = (0..n).map(|k| g.get(i, j, k) * y[k]).sum();
                worst = worst.max((sum - y[i] * y[j]).abs());
            }
        }
    }
    assert!(worst < 1e-13, "{worst:e}");
    // The stored count quoted in the module docs.
    assert_eq!(g.entries().len(), 12_868);
}

#[test]
fn contraction_is_the_sum_over_the_middle_index() {
    let g = Gaunt::new(3).unwrap();
    let c: Vec<f64> = (0..9).map(|j| (j as f64 * 0.7).sin()).collect();
    let mut m = vec![0.0; 81];
    g.contract(&c, &mut m);
    for i in 0..9 {
        for k in 0..9 {
            let want: f64 = (0..9).map(|j| g.get(i, j, k) * c[j]).sum();
            assert!((m[i * 9 + k] - want).abs() < 1e-15);
        }
    }
}

#[test]
fn band_counts_out_of_range_are_errors() {
    assert_err!(
        Gaunt::new(0),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "0: Gaunt coefficients take 1 to 16 bands"
    );
    assert_err!(
        Gaunt::new(17),
        InvalidParameter {
            name: "sh-bands",
            ..
        },
        "17: Gaunt"
    );
}
