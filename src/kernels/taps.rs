//! Shared machinery of the finite kernels: within one row every output sample sits at the same
//! fractional offset from the input grid, so the weights are computed once per row and the
//! shift is a short FIR filter with constant taps (vectorised).

use super::{Outside, RowShifter};
use crate::{Result, Sample};

/// Splits `shift` into the integer `k = floor(shift)` and the fraction `f = shift - k` in
/// `[0, 1)`; then `out[n] = row(n - k - f)`.
#[inline]
pub(crate) fn split_shift(shift: f64) -> (isize, f64) {
    let k = shift.floor();
    (k as isize, shift - k)
}

/// Weights of a symmetric kernel `value` with `w.len()` taps (even) for fraction `f`:
/// `out[n] = sum_t w[t] * row(n - k - taps/2 + t)` with `w[t] = value(taps/2 - t - f)`, the
/// kernel at the tap's distance from the sampling point `n - k - f`. With `normalise`, the
/// weights are scaled to sum to one.
pub(crate) fn weights_into<T: Sample>(
    value: impl Fn(f64) -> f64,
    f: f64,
    normalise: bool,
    w: &mut [T],
) {
    let half = (w.len() / 2) as f64;
    let tap = |t: usize| value(half - t as f64 - f);
    let scale = if normalise {
        1.0 / (0..w.len()).map(tap).sum::<f64>()
    } else {
        1.0
    };
    for (t, wt) in w.iter_mut().enumerate() {
        *wt = T::from_f64(tap(t) * scale);
    }
}

/// `out[n] = sum_t w[t] * src[n + t]`; `src` must hold `out.len() + w.len() - 1` samples.
/// One pass per tap keeps every loop a plain vectorisable axpy over a row that stays in L1.
pub(crate) fn fir<T: Sample>(src: &[T], w: &[T], out: &mut [T]) {
    let n = out.len();
    debug_assert!(src.len() + 1 >= n + w.len());
    let (first, rest) = w.split_first().expect("at least one tap");
    for (o, s) in out.iter_mut().zip(&src[..n]) {
        *o = *first * *s;
    }
    for (t, wt) in rest.iter().enumerate() {
        for (o, s) in out.iter_mut().zip(&src[t + 1..t + 1 + n]) {
            *o += *wt * *s;
        }
    }
}

/// The [`RowShifter`] of a finite symmetric kernel given by its continuous `value`.
pub(crate) struct TapShifter<T, F> {
    value: F,
    normalise: bool,
    outside: Outside,
    weights: Vec<T>,
    extended: Vec<T>,
}

impl<T: Sample, F: Fn(f64) -> f64 + Send> TapShifter<T, F> {
    /// A shifter with `taps` (even) taps of `value`, optionally normalised to sum one.
    pub(crate) fn new(taps: usize, value: F, normalise: bool, outside: Outside) -> Self {
        TapShifter {
            value,
            normalise,
            outside,
            weights: vec![T::zero(); taps],
            extended: Vec::new(),
        }
    }
}

impl<T: Sample, F: Fn(f64) -> f64 + Send> RowShifter<T> for TapShifter<T, F> {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()> {
        let (k, f) = split_shift(shift);
        weights_into(&self.value, f, self.normalise, &mut self.weights);
        let taps = self.weights.len();
        self.extended.resize(out.len() + taps - 1, T::zero());
        self.outside
            .extend_into(row, -k - (taps / 2) as isize, &mut self.extended);
        fir(&self.extended, &self.weights, out);
        Ok(())
    }
}

#[cfg(test)]
#[path = "taps_tests.rs"]
mod tests;
