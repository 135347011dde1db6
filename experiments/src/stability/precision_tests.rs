use super::*;
use crate::rotation_cycle::NoMeter;
use crate::stability::Library;

#[test]
fn every_precision_matches_and_the_limits_are_refused() {
    let x = ndarray::Array2::from_shape_fn((32, 32), |(i, j)| ((i * 37 + j * 11) % 256) as f64);
    let r = checks(x.view(), &NoMeter, &Library);
    assert!(r.iter().all(|r| r.pass), "{:?}", r.iter().find(|r| !r.pass));
    assert_eq!(r.len(), COMPACT.len() + 1 + RETAINED.len() + 1);
    assert!(r[COMPACT.len()].detail.contains("above the maximum"));
    let last = r.last().unwrap();
    assert_eq!(last.check, "retained h=10");
    assert!(
        last.detail.contains("h=9 is the largest"),
        "{}",
        last.detail
    );
    assert_eq!(retained_bytes(16, 9), 1 << 30);
}
