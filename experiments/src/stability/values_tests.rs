use super::*;

#[test]
fn values_checks_pass_with_their_exact_figures() {
    let x = Array2::from_shape_fn((32, 32), |(i, j)| ((i * 37 + j * j * 11) % 256) as f64);
    let r = checks(x.view(), &Library);
    assert!(r.iter().all(|r| r.pass), "{:?}", r.iter().find(|r| !r.pass));
    let get = |name: &str| r.iter().find(|r| r.check == name).unwrap();
    // At scale 1 in f64 the compared computations are the same: exactly 0.
    assert_eq!(get("scale 1e0 f64").figure, Some(0.0));
    let f32_far = get("scale 1e30 f32").figure.unwrap();
    assert!(f32_far > 0.0 && f32_far < 64.0 * f64::from(f32::EPSILON));
    for name in [
        "checkerboard: shift by 1 negates",
        "checkerboard: half-pixel shift is 0",
    ] {
        assert_eq!(get(name).figure, Some(0.0), "{name}");
    }
    let nan = get("NaN pixel: transform");
    assert!(nan.figure.is_none() && nan.detail.contains("non-finite"));
    assert_eq!(
        r.iter()
            .filter(|r| r.check == "impulse centroid rotates")
            .count(),
        4
    );
}
