//! The Haar-domain kernel: each row is shifted through its Haar coefficients with the
//! [`shift`](crate::shift) module, never by pixel-domain interpolation.
//!
//! * Compact (`retain = false`): the row's transform is upsampled by `h` zero-detail levels,
//!   shifted by `round(s * 2^h)` fine samples and read back at the original levels (Alnasser 2008's
//!   sections 2.4 and 2.6). In the pixel domain that is exactly linear interpolation with the
//!   shift rounded to `1/2^h` (ties toward +infinity), which the shift module documents and
//!   tests.
//! * Retained (`retain = true`): the kernel declares a `2^h`-finer working grid
//!   ([`grid_exponent`](ShearKernel::grid_exponent)), so the rotation drivers keep the `N + h`
//!   levels (as fine-grid samples) across all three shears and across successive rotations and
//!   box-average only at the end. On that grid every shift is a whole number of fine samples
//!   (rounded, ties up), made exactly in the Haar domain: the result is nearest-neighbour on the
//!   `2^h`-finer grid, box-averaged at the end.
//!
//! A row is continued by the rotation's [`Outside`] rule into a power-of-two buffer with two
//! samples of margin on each side, so the periodic Haar shift never wraps anything into view.

use super::shear::check_shift;
use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::shift::{GridShift, MAX_PRECISION, ShiftWorkspace, dense::shift_slice_in_place};
use crate::transform::{Normalization, haar1d};
use crate::{Error, Result, Sample};

/// Shifts rows in the Haar domain with precision `1/2^h`.
///
/// Compact (`retain = false`): each shift is made on the row's coefficients upsampled by `h`
/// zero-detail levels and read back at the original levels, which in the pixel domain is
/// linear interpolation with the shift rounded to `1/2^h` (ties toward +infinity). Retained
/// (`retain = true`): the kernel works on a `2^h`-finer grid that the rotation drivers keep
/// across shears and rotations, shifting by whole fine samples in the Haar domain, which is
/// nearest neighbour on that grid, box-averaged at the end.
///
/// ```
/// use haarshift::kernels::{HaarShift, Outside, RowGeometry, ShearKernel};
/// let kernel = HaarShift::new(2, false).unwrap();
/// let g = RowGeometry { len_in: 4, len_out: 4, min_shift: 0.0, max_shift: 1.0 };
/// let mut worker = ShearKernel::<f64>::row_shifter(&kernel, g, Outside::Fill(0.0));
/// let mut out = [0.0; 4];
/// worker.shift_row(&[0.0, 4.0, 8.0, 12.0], 0.25, &mut out).unwrap();
/// // Linear interpolation a quarter sample back.
/// assert_eq!(out, [0.0, 3.0, 7.0, 11.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HaarShift {
    precision: u32,
    retain: bool,
}

impl HaarShift {
    /// A Haar kernel with `precision` extra levels, compact or retained.
    pub fn new(precision: u32, retain: bool) -> Result<Self> {
        if precision > MAX_PRECISION {
            return Err(Error::parameter(
                "precision",
                format!("{precision} is above the maximum of {MAX_PRECISION}"),
            ));
        }
        Ok(HaarShift { precision, retain })
    }

    /// Extra levels `h`.
    pub fn precision(&self) -> u32 {
        self.precision
    }

    /// Whether the `N + h` levels are kept across shears and rotations.
    pub fn retains(&self) -> bool {
        self.retain
    }
}

impl<T: Sample> ShearKernel<T> for HaarShift {
    fn name(&self) -> String {
        let mode = if self.retain { "retained" } else { "compact" };
        format!("haar(h={}, {mode})", self.precision)
    }

    fn grid_exponent(&self) -> u32 {
        if self.retain { self.precision } else { 0 }
    }

    fn support_radius(&self) -> usize {
        1
    }

    fn row_shifter(&self, geometry: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        let len = (geometry.len_out + 2 * MARGIN).next_power_of_two();
        Box::new(HaarRowShifter {
            // On the retained fine grid the shifts are already in fine samples.
            precision: if self.retain { 0 } else { self.precision },
            outside,
            levels: len.trailing_zeros() as usize,
            buffer: vec![T::zero(); len],
            scratch: Vec::with_capacity(len),
            work: ShiftWorkspace::default(),
        })
    }
}

/// Samples of margin on each side of the output window.
const MARGIN: usize = 2;

/// The per-thread worker of [`HaarShift`].
struct HaarRowShifter<T> {
    precision: u32,
    outside: Outside,
    levels: usize,
    buffer: Vec<T>,
    scratch: Vec<T>,
    work: ShiftWorkspace<T>,
}

impl<T: Sample> RowShifter<T> for HaarRowShifter<T> {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()> {
        // out[n] = row(n - s) with s = q + f, q whole: take buffer[b] = row(b - q - MARGIN), shift
        // it by f in the Haar domain, and read out[n] = shifted[n + MARGIN]. A NaN, infinite or
        // absurd shift has no whole part to place the row by: refused before anything is written.
        check_shift(shift)?;
        let whole = shift.floor();
        let fraction = shift - whole;
        let grid = GridShift::new(fraction, self.precision)?;
        let needed = (out.len() + 2 * MARGIN).next_power_of_two();
        if needed > self.buffer.len() {
            self.buffer.resize(needed, T::zero());
            self.levels = needed.trailing_zeros() as usize;
        }
        let lo = -(whole as isize) - MARGIN as isize;
        self.outside.extend_into(row, lo, &mut self.buffer);
        let norm = Normalization::Average;
        // The buffer is a power of two long and the level count fits it; the shift module can
        // still refuse a period too fine for exact step counts (`len * 2^h` above 2^53), which
        // is passed on, never written as a wrong row.
        haar1d::forward_in_place(&mut self.buffer, self.levels, norm, &mut self.scratch)?;
        shift_slice_in_place(&mut self.buffer, self.levels, norm, grid, &mut self.work)?;
        haar1d::inverse_in_place(&mut self.buffer, self.levels, norm, &mut self.scratch)?;
        out.copy_from_slice(&self.buffer[MARGIN..MARGIN + out.len()]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
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
                    let mut worker =
                        ShearKernel::<f64>::row_shifter(&kernel, g, Outside::Fill(0.0));
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
                    let c =
                        haar1d::forward(ndarray::ArrayView1::from(&padded), levels, norm).unwrap();
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
}

#[cfg(test)]
mod rotation_tests {
    use super::*;
    use crate::kernels::{Nearest, shear_rows, shift_plane};
    use crate::rotate::{RotateOptions, RotationChain, RotationWorkspace};
    use ndarray::Array2;

    /// A kernel whose every row shift fails, to see that the drivers pass a kernel's error on.
    struct Refusing;
    struct RefusingRows;

    impl RowShifter<f64> for RefusingRows {
        fn shift_row(&mut self, _: &[f64], _: f64, _: &mut [f64]) -> Result<()> {
            Err(Error::parameter("shift", "refused on purpose"))
        }
    }

    impl ShearKernel<f64> for Refusing {
        fn name(&self) -> String {
            "refusing".into()
        }

        fn support_radius(&self) -> usize {
            1
        }

        fn row_shifter(&self, _: RowGeometry, _: Outside) -> Box<dyn RowShifter<f64> + '_> {
            Box::new(RefusingRows)
        }
    }

    /// Every driver (row shear, plane shift, one rotation, rotation into a buffer, a chain)
    /// returns a kernel's error instead of an image: a failed Haar shift is never swallowed.
    #[test]
    fn drivers_return_a_kernel_error() {
        let plane = Array2::from_shape_fn((9, 12), |(i, j)| (i * 12 + j) as f64);
        let refused = |r: Result<()>, what: &str| match r {
            Err(Error::InvalidParameter {
                name: "shift",
                reason,
            }) => {
                assert_eq!(reason, "refused on purpose", "{what}")
            }
            other => panic!("{what}: {other:?}"),
        };
        let fill = Outside::Fill(0.0);
        refused(
            shear_rows(plane.view(), 12, &[0.5; 9], &Refusing, fill).map(drop),
            "shear_rows",
        );
        refused(
            shift_plane(plane.view(), 0.5, 0.25, &Refusing, fill).map(drop),
            "shift_plane",
        );
        let options = RotateOptions::default();
        let mut workspace = RotationWorkspace::new();
        refused(
            workspace
                .rotate_plane(plane.view(), 17.0, &Refusing, &options)
                .map(drop),
            "rotate_plane",
        );
        let size = crate::rotate::rotated_size(9, 12, 17.0, &options).unwrap();
        let mut out = Array2::zeros(size);
        refused(
            workspace.rotate_plane_into(plane.view(), 17.0, &Refusing, &options, out.view_mut()),
            "rotate_plane_into",
        );
        let mut chain = RotationChain::new(plane.view(), &Refusing, options).unwrap();
        refused(chain.rotate(17.0).map(drop), "RotationChain::rotate");
    }

    /// The statement in the module docs, end to end: a chain of rotations with the retained Haar
    /// kernel equals nearest neighbour on the 2^h-finer grid, box-averaged at the end.
    #[test]
    fn retained_haar_rotation_equals_supersampled_nearest() {
        let plane = Array2::from_shape_fn((21, 26), |(i, j)| ((i * 37 + j * 101) % 23) as f64);
        for h in 1..=3u32 {
            let haar = HaarShift::new(h, true).unwrap();
            let mut chain =
                RotationChain::new(plane.view(), &haar, RotateOptions::default()).unwrap();
            let nn_options = RotateOptions {
                supersample: h,
                ..Default::default()
            };
            let mut reference = RotationChain::new(plane.view(), &Nearest, nn_options).unwrap();
            for deg in [17.3, -31.1, 8.9] {
                chain.rotate(deg).unwrap();
                reference.rotate(deg).unwrap();
            }
            let (a, b) = (chain.finish(), reference.finish());
            let err = a
                .iter()
                .zip(b.iter())
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            // Measured 0 for h = 1, 2, 3 (integer values, dyadic weights); 1e-12 allows a
            // reordered sum.
            assert!(err < 1e-12, "h={h}: {err}");
        }
    }
}
