use super::*;

#[test]
fn split_reduces_exactly_for_any_size_and_sign() {
    let s = GridShift::new(-1.25, 2).unwrap();
    // -5 quarter steps mod 32 = 27 = 6 * 4 + 3.
    assert_eq!(s.split(8).unwrap(), (6, 3));
    assert_eq!(GridShift::new(1e300, 0).unwrap().split(8).unwrap(), (0, 0));
    assert_eq!(GridShift::whole(-9).split(8).unwrap(), (7, 0));
    assert_eq!(GridShift::new(2.5, 1).unwrap().split(2).unwrap(), (0, 1));
    assert_err!(
        GridShift::new(1.0, 20).unwrap().split(1 << 40),
        InvalidParameter {
            name: "precision",
            ..
        },
        "too fine for a period"
    );
}

#[test]
fn rounding_is_half_up_and_translation_consistent() {
    for p in 0..5u32 {
        let unit = 1.0 / (1u64 << p) as f64;
        for k in -40i32..40 {
            let tie = (k as f64 + 0.5) * unit;
            assert_eq!(
                GridShift::new(tie, p).unwrap().amount(),
                (k + 1) as f64 * unit
            );
            for m in -3..3 {
                let a = GridShift::new(tie + m as f64, p).unwrap();
                let b = GridShift::new(tie, p).unwrap() + GridShift::whole(m);
                assert_eq!(a, b);
            }
        }
    }
    assert_eq!(
        GridShift::new(0.49999999999999994, 0).unwrap().amount(),
        0.0
    );
}

#[test]
fn multiples_and_refinement() {
    let s = GridShift::new(12.0, 1).unwrap();
    assert_eq!(s.whole_multiple_of(2), Some(GridShift::whole(3)));
    assert_eq!(s.whole_multiple_of(3), None);
    assert_eq!(GridShift::new(0.5, 1).unwrap().whole_multiple_of(0), None);
    assert_eq!(s.refine(3).steps(), 96.0);
    assert_eq!((-s).amount(), -12.0);
}
