use super::*;

#[test]
fn zone_plate_has_its_documented_values() {
    let z = zone_plate(33, 33).unwrap();
    assert_eq!(z[[16, 16]], 255.0); // r = 0
    // A lattice point at r^2 = 16: value from the formula.
    let v = 127.5 * (1.0 + (std::f64::consts::PI * 16.0 / 33.0).cos());
    assert!((z[[16, 20]] - v).abs() < 1e-12);
}

#[test]
fn siemens_star_is_half_white_and_binary_away_from_edges() {
    let s = siemens_star(128, 128, 18).unwrap();
    let mean = s.mean().unwrap();
    assert!((mean - 127.5).abs() < 3.0, "mean {mean}");
    // On the +x axis just above it (small positive angle): white; just below: black.
    assert_eq!(s[[63, 120]], 0.0); // y = -0.5 < 0: angle slightly negative
    assert_err!(
        siemens_star(0, 4, 3),
        InvalidShape { .. },
        "pattern is empty"
    );
    assert_err!(
        siemens_star(4, 4, 0),
        InvalidParameter { name: "spokes", .. },
        "at least 1"
    );
}
