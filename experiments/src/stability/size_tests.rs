use super::*;
use crate::rotation_cycle::NoMeter;
use crate::stability::Library;

#[test]
fn every_shape_passes_exactly_where_the_data_is_exact() {
    let x = Array2::from_shape_fn((131, 131), |(i, j)| ((i * 37 + j * 11) % 256) as f64);
    let r = shape_checks(x.slice(s![..13, ..17]), &Library);
    assert_eq!(r.len(), 4);
    assert!(r.iter().all(|r| r.pass), "{r:?}");
    // Round trip and whole shift of 8-bit data: bit-exact.
    assert_eq!(r[0].figure, Some(0.0));
    assert_eq!(r[1].figure, Some(0.0));
    for (h, w) in [(1, 1), (1, 17), (17, 1)] {
        assert!(
            shape_checks(x.slice(s![..h, ..w]), &Library)
                .iter()
                .all(|r| r.pass)
        );
    }
}

#[test]
fn the_largest_square_is_the_budget_boundary() {
    let budget = 1 << 20;
    let n = largest_square(budget).unwrap();
    assert!(rotation_bytes(n).unwrap() <= u128::from(budget));
    assert!(rotation_bytes(n + 1).unwrap() > u128::from(budget));
    // About 4.5 images' worth of f64 at 30 degrees.
    assert!((150..190).contains(&n), "{n}");
    let r = largest_affordable(&NoMeter);
    assert!(r.pass, "{}", r.detail);
    let r = largest_within_default(&NoMeter);
    assert!(r.pass && r.figure.is_none(), "{}", r.detail);
    assert!(r.detail.contains("needs"), "{}", r.detail);
}
