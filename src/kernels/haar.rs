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
#[path = "haar_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "haar_rotation_tests.rs"]
mod rotation_tests;
