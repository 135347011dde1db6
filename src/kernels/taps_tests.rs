use super::*;

#[test]
fn split_shift_gives_floor_and_fraction() {
    assert_eq!(split_shift(2.25), (2, 0.25));
    assert_eq!(split_shift(-2.25), (-3, 0.75));
    assert_eq!(split_shift(-0.0), (0, 0.0));
}

#[test]
fn fir_matches_direct_sum() {
    let src: Vec<f64> = (0..10).map(|i| (i * i) as f64 * 0.3 - 1.0).collect();
    let w = [0.1, -0.2, 0.7, 0.4];
    let mut out = [0.0; 7];
    fir(&src, &w, &mut out);
    for (n, o) in out.iter().enumerate() {
        let direct: f64 = (0..4).map(|t| w[t] * src[n + t]).sum();
        assert!((o - direct).abs() < 1e-14);
    }
}

#[test]
fn normalised_weights_sum_to_one() {
    let mut w = [0.0f64; 6];
    weights_into(|x: f64| (-x * x).exp(), 0.3, true, &mut w);
    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    let ratio = (-0.7f64 * 0.7).exp() / (-0.3f64 * 0.3).exp();
    assert!((w[2] / w[3] - ratio).abs() < 1e-12);
}
