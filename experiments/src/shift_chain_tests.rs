use super::*;
use haarshift::patterns::zone_plate;

fn haar(retain: bool) -> KernelOptions {
    KernelOptions {
        precision: 3,
        retain,
        ..Default::default()
    }
}

#[test]
fn integer_steps_with_haar_are_exact() {
    let plane = zone_plate(32, 32).unwrap();
    for retain in [false, true] {
        let r = run_chain(
            "z",
            plane.view(),
            ShiftMethod::Haar,
            &haar(retain),
            (8.0, -4.0),
            4,
        )
        .unwrap();
        // Exact up to f64 rounding of the coefficient arithmetic (measured ~1e-13, not 0).
        assert!(r.max_error < 1e-11, "retain {retain}: {}", r.max_error);
    }
}

#[test]
fn compact_haar_chain_is_the_linear_chain_with_rounded_shifts() {
    let plane = zone_plate(32, 32).unwrap();
    // 0.45625 and -0.29375 per step round to 0.5 and -0.25 at h = 3.
    let (dx, dy, steps) = (7.3, -4.7, 16);
    let got = shift_in_steps(
        plane.view(),
        ShiftMethod::Haar,
        &haar(false),
        (dx, dy),
        steps,
    )
    .unwrap();
    let linear = ShiftMethod::Linear.kernel::<f64>();
    let wrap = Outside::Boundary(BoundaryMode::Wrap);
    let mut want = plane.clone();
    for _ in 0..steps {
        want = shift_plane(want.view(), 0.5, -0.25, linear.as_ref(), wrap).unwrap();
    }
    let diff = (&got - &want).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(diff < 1e-9, "{diff}");
}

#[test]
fn pixel_kernels_chain_against_their_single_shift() {
    let plane = zone_plate(32, 32).unwrap();
    let o = KernelOptions::default();
    // Integer steps are exact for every interpolating kernel.
    let r = run_chain("z", plane.view(), ShiftMethod::Keys, &o, (4.0, 8.0), 4).unwrap();
    assert_eq!(r.rms, 0.0);
    // Linear interpolation blurs at every step: the chain must lose detail, and more than
    // the band-limited FFT shift does.
    let fft = run_chain("z", plane.view(), ShiftMethod::Fft, &o, (7.3, -4.7), 16).unwrap();
    let r = run_chain("z", plane.view(), ShiftMethod::Linear, &o, (7.3, -4.7), 16).unwrap();
    assert!(r.rms > 1.0 && fft.rms < r.rms, "{} {}", r.rms, fft.rms);
}
