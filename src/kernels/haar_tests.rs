use super::*;
use crate::shift::oracle;

/// Random-ish rows without a pattern.
fn row(n: usize, seed: u64) -> Vec<f64> {
    (0..n)
        .map(|i| (((i as u64 * 2654435761 + seed * 97) % 1000) as f64) / 7.0 - 50.0)
        .collect()
}

/// The compact kernel equals the shift module's Haar shift of the same buffer (the oracle
/// of the shifting issue), and hence linear interpolation with the rounded shift.
#[test]
fn compact_kernel_equals_the_shift_module_and_rounded_linear_interpolation() {
    for h in 0..=5u32 {
        let kernel = HaarShift::new(h, false).unwrap();
        for (n, seed) in [(5usize, 1u64), (16, 2), (37, 3)] {
            let x = row(n, seed);
            for k in -40..=40 {
                let s = k as f64 * 0.173;
                let g = RowGeometry {
                    len_in: n,
                    len_out: n,
                    min_shift: s,
                    max_shift: s,
                };
                let mut worker = ShearKernel::<f64>::row_shifter(&kernel, g, Outside::Fill(0.0));
                let mut out = vec![0.0; n];
                worker.shift_row(&x, s, &mut out).unwrap();
                // Independent pixel-domain statement: linear interpolation, shift rounded
                // to 1/2^h with ties up, zero outside.
                let r = GridShift::new(s, h).unwrap().amount();
                let at = |i: f64| {
                    if i >= 0.0 && (i as usize) < n && i.fract() == 0.0 {
                        x[i as usize]
                    } else {
                        0.0
                    }
                };
                for (m, &o) in out.iter().enumerate() {
                    let p = m as f64 - r;
                    let (f, t) = (p.floor(), p - p.floor());
                    let want = (1.0 - t) * at(f) + t * at(f + 1.0);
                    assert!(
                        (o - want).abs() < 1e-11,
                        "h={h} n={n} s={s} m={m}: {o} vs {want}"
                    );
                }
                // And the definition (the shift module's oracle) on a periodic buffer wide
                // enough that nothing wraps into view: the row sits `off` samples in.
                let off = s.abs().ceil() as usize + 2;
                let len = (n + 2 * off).next_power_of_two();
                let mut padded = vec![0.0; len];
                padded[off..off + n].copy_from_slice(&x);
                let levels = len.trailing_zeros() as usize;
                let norm = Normalization::Average;
                let c = haar1d::forward(ndarray::ArrayView1::from(&padded), levels, norm).unwrap();
                let shifted =
                    oracle::shift_signal(c.view(), levels, norm, GridShift::new(s, h).unwrap())
                        .unwrap();
                let z = haar1d::inverse(shifted.view(), levels, norm).unwrap();
                for (m, &o) in out.iter().enumerate() {
                    assert!(
                        (o - z[m + off]).abs() < 1e-11,
                        "oracle: h={h} n={n} s={s} m={m}"
                    );
                }
            }
        }
    }
}

/// On its fine grid the retained kernel is nearest neighbour (ties up).
#[test]
fn retained_kernel_is_nearest_on_its_grid() {
    let kernel = HaarShift::new(3, true).unwrap();
    assert_eq!(ShearKernel::<f64>::grid_exponent(&kernel), 3);
    let x = row(40, 9);
    for k in -60..=60 {
        let s = k as f64 * 0.25 + 0.01 * (k % 3) as f64;
        let g = RowGeometry {
            len_in: 40,
            len_out: 40,
            min_shift: s,
            max_shift: s,
        };
        let mut worker = ShearKernel::<f64>::row_shifter(&kernel, g, Outside::Fill(0.0));
        let mut out = vec![0.0; 40];
        worker.shift_row(&x, s, &mut out).unwrap();
        let q = (s - s.floor() >= 0.5) as i64 + s.floor() as i64;
        for (m, &o) in out.iter().enumerate() {
            let src = m as i64 - q;
            let want = if (0..40).contains(&src) {
                x[src as usize]
            } else {
                0.0
            };
            assert!((o - want).abs() < 1e-11, "s={s} m={m}");
        }
    }
}

/// A shift the kernel cannot place (NaN, infinite, beyond the drivers' limit) is an error
/// naming the shift, and the output row is left as it was: no panic and no wrong row. The
/// worker stays usable.
#[test]
fn refuses_a_shift_it_cannot_make_without_writing() {
    let x = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
    for retain in [false, true] {
        let kernel = HaarShift::new(3, retain).unwrap();
        let g = RowGeometry {
            len_in: 8,
            len_out: 8,
            min_shift: 0.0,
            max_shift: 1.0,
        };
        let mut worker = ShearKernel::<f32>::row_shifter(&kernel, g, Outside::Fill(0.0));
        for s in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -2e15] {
            let mut out = [-7.0f32; 8];
            let err = worker.shift_row(&x, s, &mut out).unwrap_err();
            assert!(
                matches!(err, Error::InvalidParameter { name: "shift", .. }),
                "retain={retain} s={s}: {err}"
            );
            assert_eq!(out, [-7.0; 8], "retain={retain} s={s}: the row was written");
        }
        let mut out = [0.0f32; 8];
        worker.shift_row(&x, 2.0, &mut out).unwrap();
        assert_eq!(out, [0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }
}

#[test]
fn rejects_absurd_precision_and_names_its_mode() {
    assert_err!(
        HaarShift::new(MAX_PRECISION + 1, false),
        InvalidParameter {
            name: "precision",
            ..
        },
        "above the maximum of 20"
    );
    assert_eq!(
        ShearKernel::<f32>::name(&HaarShift::new(3, true).unwrap()),
        "haar(h=3, retained)"
    );
}
