//! Band-limited shift by FFT phase ramp.

use std::any::{Any, TypeId};
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, FftNum, RealFftPlanner, RealToComplex};

use super::taps::split_shift;
use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::{Result, Sample};

/// Samples of padding beyond the content and the view on each side of the FFT window.
const PAD: usize = 32;

/// Band-limited (sinc) shift by multiplying the row's spectrum by a phase ramp.
///
/// Each row is placed in a window of `P` samples that covers the row itself, every position the
/// output reads, and [`PAD`](Self::PAD) more samples on both sides, all continued by the
/// [`Outside`] rule; so no periodic copy of the row falls into view. `P` is the smallest
/// `2^a 3^b 5^c` that fits all rows of a shear, and its realfft plans are built once and
/// shared by all threads. The shifted row is the trigonometric interpolant of the window,
/// `y(x) = 1/P [sum_{|q| < P/2} X_q e^{2 pi i q x / P} + X_{P/2} cos(pi x)]`: for even `P`
/// the Nyquist term is split evenly between `+P/2` and `-P/2`, so it shifts as `cos(pi x)` and
/// the result of a real row stays real; an integer shift is an exact copy (the drivers copy
/// those rows, and the phase ramp is 1 at a zero fraction).
///
/// With [`Outside::Boundary`]`(`[`BoundaryMode::Wrap`]`)` the row is one period of a periodic
/// signal, and the window is the row itself (`P` = the row's length): the shift is then the
/// exact band-limited shift of that periodic signal, so successive shifts compose (up to
/// rounding, and up to the Nyquist term, which shifts as `cos(pi x)`).
///
/// [`BoundaryMode::Wrap`]: crate::BoundaryMode::Wrap
///
/// ```
/// use haarshift::kernels::{FftShift, Outside, shear_rows};
/// use ndarray::Array2;
/// // A sampled sinusoid well below Nyquist shifts like the continuous one.
/// let row = Array2::from_shape_fn((1, 256), |(_, i)| {
///     let x = i as f64 - 128.0;
///     (0.3 * x).sin() * (-(x / 30.0).powi(2)).exp()
/// });
/// let out = shear_rows(row.view(), 256, &[0.5], &FftShift::new(), Outside::Fill(0.0)).unwrap();
/// let x: f64 = 130.0 - 0.5 - 128.0;
/// assert!((out[[0, 130]] - (0.3 * x).sin() * (-(x / 30.0).powi(2)).exp()).abs() < 1e-9);
/// ```
pub struct FftShift<T: Sample + FftNum> {
    planner: Mutex<RealFftPlanner<T>>,
}

impl<T: Sample + FftNum> Default for FftShift<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Sample + FftNum> FftShift<T> {
    /// Padding beyond content and view on each side of the window, in samples.
    pub const PAD: usize = PAD;

    /// A new FFT shift kernel with its own plan cache.
    pub fn new() -> Self {
        FftShift {
            planner: Mutex::new(RealFftPlanner::new()),
        }
    }

    fn plans(&self, len: usize) -> (Arc<dyn RealToComplex<T>>, Arc<dyn ComplexToReal<T>>) {
        // A poisoned lock only means another thread panicked while planning; the planner's
        // cache is still a valid cache.
        let mut planner = self.planner.lock().unwrap_or_else(|e| e.into_inner());
        (planner.plan_fft_forward(len), planner.plan_fft_inverse(len))
    }
}

/// Whether rows are single periods of periodic signals (see [`FftShift`]).
fn is_periodic(outside: Outside) -> bool {
    outside == Outside::Boundary(crate::BoundaryMode::Wrap)
}

/// The smallest `2^a 3^b 5^c >= n`.
pub(crate) fn fast_len(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r.is_multiple_of(p) {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

/// The window for a row of `len_in` samples read at positions `n - k - f` for `n` in
/// `0..len_out`: its first position `lo` and the length it needs.
pub(crate) fn window(len_in: usize, len_out: usize, k: isize) -> (isize, usize) {
    let lo = (-k - 1).min(0) - PAD as isize;
    let hi = (len_out as isize - k).max(len_in as isize) + PAD as isize;
    (lo, (hi - lo) as usize)
}

/// Multiplies the half spectrum of a length-`len` real signal by `scale e^{-2 pi i q f / len}`,
/// with the Nyquist bin (even `len`) shifted by `cos(pi f)` so the signal stays real.
///
/// The ramp is `seed_b * table_j` for bin `q = 64 b + j`: seeds from `sin_cos` every 64 bins
/// and a table of the first 64 ramp values (by recurrence in f64, error far below `T`'s), so
/// that the per-bin work is two independent complex products in `T`, which vectorise.
pub(crate) fn apply_phase_ramp<T: Sample + FftNum>(
    spectrum: &mut [Complex<T>],
    len: usize,
    f: f64,
    scale: f64,
) {
    const BLOCK: usize = 64;
    let even = len.is_multiple_of(2);
    let (ramped, nyquist) = spectrum.split_at_mut(if even { len / 2 } else { len / 2 + 1 });
    let step = -2.0 * PI * f / len as f64;
    let rot = Complex::new(step.cos(), step.sin());
    let mut table = [Complex::new(T::zero(), T::zero()); BLOCK];
    let mut w = Complex::new(scale, 0.0);
    for t in table.iter_mut() {
        *t = Complex::new(<T as Sample>::from_f64(w.re), <T as Sample>::from_f64(w.im));
        w *= rot;
    }
    for (block, chunk) in ramped.chunks_mut(BLOCK).enumerate() {
        let (s, c) = (step * (block * BLOCK) as f64).sin_cos();
        let seed = Complex::new(<T as Sample>::from_f64(c), <T as Sample>::from_f64(s));
        for (v, t) in chunk.iter_mut().zip(&table) {
            *v = *v * (seed * *t);
        }
    }
    ramped[0].im = T::zero();
    if let Some(v) = nyquist.first_mut() {
        *v = Complex::new(
            v.re * <T as Sample>::from_f64((PI * f).cos() * scale),
            T::zero(),
        );
    }
}

struct FftShifter<'k, T: Sample + FftNum> {
    kernel: &'k FftShift<T>,
    outside: Outside,
    len: usize,
    forward: Arc<dyn RealToComplex<T>>,
    inverse: Arc<dyn ComplexToReal<T>>,
    window: Vec<T>,
    spectrum: Vec<Complex<T>>,
    scratch: Vec<Complex<T>>,
}

impl<'k, T: Sample + FftNum> FftShifter<'k, T> {
    fn new(kernel: &'k FftShift<T>, len: usize, outside: Outside) -> Self {
        let (forward, inverse) = kernel.plans(len);
        let scratch = forward.get_scratch_len().max(inverse.get_scratch_len());
        FftShifter {
            kernel,
            outside,
            len,
            window: forward.make_input_vec(),
            spectrum: forward.make_output_vec(),
            scratch: vec![Complex::default(); scratch],
            forward,
            inverse,
        }
    }
}

impl<T: Sample + FftNum> RowShifter<T> for FftShifter<'_, T> {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()> {
        let (k, f) = split_shift(shift);
        let periodic = is_periodic(self.outside);
        let (lo, len) = if periodic {
            (0, row.len())
        } else {
            let (lo, needed) = window(row.len(), out.len(), k);
            // Keep the current (larger) plan when the window fits.
            (
                lo,
                if needed > self.len {
                    fast_len(needed)
                } else {
                    self.len
                },
            )
        };
        if len != self.len {
            *self = FftShifter::new(self.kernel, len, self.outside);
        }
        self.outside.extend_into(row, lo, &mut self.window);
        self.forward
            .process_with_scratch(&mut self.window, &mut self.spectrum, &mut self.scratch)
            .expect("buffer sizes come from the plan");
        // The inverse transform is unnormalised: its 1/len goes into the ramp.
        apply_phase_ramp(&mut self.spectrum, len, f, 1.0 / len as f64);
        self.inverse
            .process_with_scratch(&mut self.spectrum, &mut self.window, &mut self.scratch)
            .expect("DC and Nyquist bins are real");
        if periodic {
            // out[n] = y(n - k - f): the window shifted by f, read from n - k modulo the period.
            let start = (-k).rem_euclid(len as isize) as usize;
            let period = self.window[start..]
                .iter()
                .chain(&self.window[..start])
                .cycle();
            for (o, v) in out.iter_mut().zip(period) {
                *o = *v;
            }
        } else {
            let start = (-k - lo) as usize;
            out.copy_from_slice(&self.window[start..start + out.len()]);
        }
        Ok(())
    }
}

impl<T: Sample + FftNum> ShearKernel<T> for FftShift<T> {
    fn name(&self) -> String {
        "fft".into()
    }

    /// The sinc never ends; this is the reach used to size intermediate images (tails beyond
    /// it are below about 1% of an edge step).
    fn support_radius(&self) -> usize {
        PAD
    }

    fn row_shifter(&self, g: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        if is_periodic(outside) {
            return Box::new(FftShifter::new(self, g.len_in, outside));
        }
        // The window length grows away from k = 0 both ways, so the extremes bound it.
        let needed = |shift: f64| window(g.len_in, g.len_out, split_shift(shift).0).1;
        let len = needed(g.min_shift).max(needed(g.max_shift));
        Box::new(FftShifter::new(self, fast_len(len), outside))
    }
}

/// The FFT kernel for any [`Sample`] type (f32 or f64), without an `FftNum` bound on the
/// caller: `Sample` is implemented for exactly those two types.
pub(crate) fn boxed<T: Sample>() -> Box<dyn ShearKernel<T>> {
    let kernel: Box<dyn Any> = if TypeId::of::<T>() == TypeId::of::<f32>() {
        Box::new(Box::new(FftShift::<f32>::new()) as Box<dyn ShearKernel<f32>>)
    } else {
        Box::new(Box::new(FftShift::<f64>::new()) as Box<dyn ShearKernel<f64>>)
    };
    *kernel
        .downcast::<Box<dyn ShearKernel<T>>>()
        .expect("Sample is implemented for f32 and f64 only")
}
