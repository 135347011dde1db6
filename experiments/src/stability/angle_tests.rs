use super::*;
use crate::test_support::photo;
use haarshift::kernels::{KernelOptions, ShiftMethod};
fn figure(records: &[StabilityRecord], check: &str) -> f64 {
    let r = records
        .iter()
        .find(|r| r.check == check)
        .expect("check present");
    assert!(r.pass, "{check}: {}", r.detail);
    r.figure.expect("a measured check")
}

#[test]
fn quarter_turns_and_reductions_are_exact_and_tiny_angles_are_bounded() {
    let x = photo(32);
    let linear = ShiftMethod::Linear.kernel::<f64>();
    let r = kernel_checks(x.view(), "linear", linear.as_ref());
    for check in [
        "0 deg = quarter turn",
        "90 deg = quarter turn",
        "-180 deg = quarter turn",
    ] {
        assert_eq!(figure(&r, check), 0.0, "{check}");
    }
    assert_eq!(figure(&r, "1e6 deg = 280 deg"), 0.0);
    // A 1e-9-degree rotation moves samples by ~1e-10 px: visible, but within the bound.
    let tiny = figure(&r, "1e-9 deg ~ identity");
    assert!(tiny > 0.0 && tiny < angle_bound(x.view(), 1e-9));
    // On a ramp the two sides of the 45-degree switch differ by the ramp's own change.
    let jump = figure(&r, "45+-1e-6 deg continuous (ramp)");
    assert!(jump < 1e-6, "{jump}");
    assert!(
        r.iter()
            .all(|r| r.pass && r.parameters["kernel"] == "linear")
    );
    // Compact Haar at h = 3 rounds a 1e-10-pixel shear to 0: exactly the identity.
    let haar = ShiftMethod::Haar
        .kernel_with::<f64>(&KernelOptions::default())
        .unwrap();
    let r = kernel_checks(x.view(), "haar-compact", haar.as_ref());
    assert_eq!(figure(&r, "1e-9 deg ~ identity"), 0.0);
    assert!(r.iter().all(|r| r.pass), "{r:?}");
}

#[test]
fn exact_rotation_of_the_references_is_a_rotation() {
    let b = smooth_blob(32, 90.0);
    let q = quarter_turn(smooth_blob(32, 0.0).view(), 1);
    assert!(max_abs_diff(b.view(), q.view()) < 1e-9);
    let ramp = affine_ramp(5, 180.0);
    assert!((ramp[[0, 0]] - affine_ramp(5, 0.0)[[4, 4]]).abs() < 1e-12);
}
