use super::*;

#[test]
fn whole_chains_are_exact_and_the_f32_drift_is_bounded() {
    let x = Array2::from_shape_fn((64, 64), |(i, j)| {
        ((i * 37 + j * j * 11 + i * j) % 256) as f64
    });
    let (r, drift) = checks(x.view(), 200, 50, &crate::stability::Library);
    assert!(r.iter().all(|r| r.pass), "{r:?}");
    for r in &r[..3] {
        assert_eq!(r.figure, Some(0.0), "{}", r.check);
    }
    let ks: Vec<usize> = drift.iter().map(|d| d.0).collect();
    assert_eq!(ks, [1, 2, 5, 10, 20, 50]);
    // f32 does round: the drift is visible, and within the stated bound.
    assert!(
        drift
            .iter()
            .all(|&(k, d)| d > 0.0 && d <= fractional_tolerance(k))
    );
}

#[test]
fn shifts_are_deterministic_multiples() {
    let s = whole_shifts(100, 5, 16);
    assert_eq!(s, whole_shifts(100, 5, 16));
    assert!(
        s.iter()
            .all(|&(a, b)| a % 16 == 0 && b % 16 == 0 && a.abs() <= 80)
    );
    assert!(logged(500) && !logged(300) && logged(1));
}
