//! Interpolating B-splines of degree 3 and 5 with the exact recursive prefilter (M. Unser,
//! "Splines: a perfect fit for signal and image processing", 1999; the boundary handling of
//! P. Thevenaz, T. Blu, M. Unser, "Interpolation revisited", 2000).

use super::taps::{split_shift, weights_into};
use super::{Outside, ROW_GROUP, RowGeometry, RowShifter, ShearKernel};
use crate::{Error, Result, Sample};

/// Interpolating B-spline of degree 3 or 5: the row is first turned into spline coefficients
/// `c` with `sum_k c_k beta(i - k) = row(i)` for every integer `i` (the row continued by the
/// [`Outside`] rule), by the causal/anticausal IIR filters of the poles of the sampled
/// B-spline (`sqrt(3) - 2` for the cubic, two poles for the quintic); then
/// `row(x) = sum_k c_k beta(x - k)` is evaluated with `degree + 1` taps.
///
/// Boundaries: the filters run over the row continued by the rule for `horizon` extra samples
/// on each side, where `|z|^horizon` is below a tenth of the sample type's epsilon, so the
/// initial values' truncation error is below rounding: the coefficients are those of the
/// infinite continued signal.
///
/// ```
/// use haarshift::kernels::{BSpline, Outside, shear_rows};
/// use ndarray::array;
/// let cubic = BSpline::cubic();
/// assert_eq!(cubic.value(0.0), 2.0 / 3.0);
/// // The cubic spline interpolant reproduces polynomials up to degree 3 (here far from the
/// // edges, where the zero outside no longer matters).
/// let row = ndarray::Array2::from_shape_fn((1, 80), |(_, i)| (i as f64 - 40.0).powi(2));
/// let out = shear_rows(row.view(), 80, &[0.25], &cubic, Outside::Fill(0.0)).unwrap();
/// assert!((out[[0, 40]] - 0.0625).abs() < 1e-9);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct BSpline {
    degree: usize,
    poles: &'static [f64],
}

/// The pole of the cubic: root of `z + 4 + 1/z` inside the unit circle.
const CUBIC_POLES: [f64; 1] = [-0.267_949_192_431_122_7];
/// The poles of the quintic: roots of `z^2 + 26z + 66 + 26/z + 1/z^2` inside the unit circle.
const QUINTIC_POLES: [f64; 2] = [-0.430_575_347_099_973_8, -0.043_096_288_203_264_65];

impl BSpline {
    /// The cubic B-spline (4 taps, one pole).
    pub fn cubic() -> Self {
        BSpline {
            degree: 3,
            poles: &CUBIC_POLES,
        }
    }

    /// The quintic B-spline (6 taps, two poles).
    pub fn quintic() -> Self {
        BSpline {
            degree: 5,
            poles: &QUINTIC_POLES,
        }
    }

    /// The B-spline of `degree` 3 or 5.
    ///
    /// ```
    /// use haarshift::kernels::BSpline;
    /// assert_eq!(BSpline::new(5).unwrap(), BSpline::quintic());
    /// let quartic = BSpline::new(4);
    /// assert!(matches!(quartic, Err(haarshift::Error::InvalidParameter { name: "spline degree", .. })));
    /// ```
    pub fn new(degree: usize) -> Result<Self> {
        match degree {
            3 => Ok(Self::cubic()),
            5 => Ok(Self::quintic()),
            d => Err(Error::parameter(
                "spline degree",
                format!("{d} (supported: 3, 5)"),
            )),
        }
    }

    /// The degree, 3 or 5.
    ///
    /// ```
    /// assert_eq!(haarshift::kernels::BSpline::cubic().degree(), 3);
    /// ```
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The poles of the prefilter, `|z| < 1`.
    ///
    /// ```
    /// let z = haarshift::kernels::BSpline::cubic().poles()[0];
    /// assert!((z - (3f64.sqrt() - 2.0)).abs() < 1e-15);
    /// ```
    pub fn poles(&self) -> &'static [f64] {
        self.poles
    }

    /// The centred B-spline `beta^n(x)` of this degree.
    ///
    /// ```
    /// use haarshift::kernels::BSpline;
    /// let q = BSpline::quintic();
    /// assert!((q.value(1.0) - 26.0 / 120.0).abs() < 1e-16);
    /// assert_eq!(q.value(3.0), 0.0);
    /// ```
    pub fn value(&self, x: f64) -> f64 {
        bspline_value(self.degree, x)
    }

    /// Filter run-in, in samples, for sample type `T` (see the type docs).
    fn horizon<T: Sample>(&self) -> usize {
        let tolerance = T::epsilon().as_f64() * 0.1;
        let slowest = self.poles[0].abs();
        (tolerance.ln() / slowest.ln()).ceil() as usize
    }
}

/// The centred B-spline of degree 3 or 5 at `x` (zero for other degrees).
///
/// ```
/// use haarshift::kernels::bspline_value;
/// assert_eq!(bspline_value(3, 1.0), 1.0 / 6.0);
/// assert_eq!(bspline_value(5, 0.0), 0.55);
/// ```
pub fn bspline_value(degree: usize, x: f64) -> f64 {
    let x = x.abs();
    match degree {
        3 if x < 1.0 => 2.0 / 3.0 - x * x * (1.0 - 0.5 * x),
        3 if x < 2.0 => (2.0 - x).powi(3) / 6.0,
        5 if x < 1.0 => {
            let x2 = x * x;
            0.55 - x2 * (0.5 - x2 * (0.25 - x / 12.0))
        }
        5 if x < 2.0 => {
            17.0 / 40.0
                + x * (5.0 / 8.0 + x * (-7.0 / 4.0 + x * (5.0 / 4.0 + x * (-3.0 / 8.0 + x / 24.0))))
        }
        5 if x < 3.0 => (3.0 - x).powi(5) / 120.0,
        _ => 0.0,
    }
}

/// Taps of the highest degree supported (the quintic).
const MAX_TAPS: usize = 6;

/// Up to [`ROW_GROUP`] rows side by side: sample `i` of every row, one lane per row, so that
/// the recursive filters, which are serial along a row, vectorise across rows.
type Lanes<T> = [T; ROW_GROUP];

/// Turns samples into B-spline coefficients in place (each lane a row), treating the samples
/// beyond the buffer as zero (callers extend the buffer by the horizon so that this truncation
/// is invisible).
fn prefilter<T: Sample>(c: &mut [Lanes<T>], poles: &[f64]) {
    let n = c.len();
    if n < 2 {
        return;
    }
    // Gain: the product of (1 - z)(1 - 1/z) over the poles makes the filter's DC gain one.
    let gain: f64 = poles.iter().map(|z| (1.0 - z) * (1.0 - 1.0 / z)).product();
    let gain = T::from_f64(gain);
    for v in c.iter_mut().flatten() {
        *v *= gain;
    }
    for &z in poles {
        let zt = T::from_f64(z);
        for i in 1..n {
            let prev = c[i - 1];
            for (v, p) in c[i].iter_mut().zip(prev) {
                *v += zt * p;
            }
        }
        // Anticausal start for a signal that is zero beyond the end: c-[n-1] = z/(z^2-1) c+[n-1].
        let start = T::from_f64(z / (z * z - 1.0));
        for v in c[n - 1].iter_mut() {
            *v *= start;
        }
        for i in (0..n - 1).rev() {
            let next = c[i + 1];
            for (v, x) in c[i].iter_mut().zip(next) {
                *v = zt * (x - *v);
            }
        }
    }
}

struct BSplineShifter<'k, T> {
    spline: &'k BSpline,
    horizon: usize,
    outside: Outside,
    /// Tap `t`'s weight for each lane.
    weights: Vec<Lanes<T>>,
    /// One row continued by the rule, before it goes into its lane.
    extended: Vec<T>,
    /// Samples, then coefficients, then shifted samples, lane by lane.
    lanes: Vec<Lanes<T>>,
}

impl<T: Sample> BSplineShifter<'_, T> {
    /// At most [`ROW_GROUP`] rows through the lanes.
    fn shift_group(&mut self, rows: &[&[T]], shifts: &[f64], outs: &mut [&mut [T]]) {
        let degree = self.spline.degree;
        let taps = degree + 1;
        let h = self.horizon;
        let len_out = outs[0].len();
        // Coefficients needed: positions -k - taps/2 .. + len_out + taps - 1, plus the horizon
        // on each side for the filters to settle.
        let len = len_out + taps - 1 + 2 * h;
        self.lanes.resize(len, [T::zero(); ROW_GROUP]);
        self.extended.resize(len, T::zero());
        let mut column = [T::zero(); MAX_TAPS];
        for (lane, (row, &shift)) in rows.iter().zip(shifts).enumerate() {
            let (k, f) = split_shift(shift);
            weights_into(|x| bspline_value(degree, x), f, false, &mut column[..taps]);
            for (w, c) in self.weights.iter_mut().zip(column) {
                w[lane] = c;
            }
            let lo = -k - (taps / 2) as isize - h as isize;
            self.outside.extend_into(row, lo, &mut self.extended);
            for (l, v) in self.lanes.iter_mut().zip(&self.extended) {
                l[lane] = *v;
            }
        }
        prefilter(&mut self.lanes, self.spline.poles);
        // The FIR of `taps::fir`, lane-wise and in place: output n reads coefficients h + n
        // onwards, never an output already written.
        let (first, rest) = self.weights.split_first().expect("at least one tap");
        for n in 0..len_out {
            let mut acc = self.lanes[h + n];
            for (a, w) in acc.iter_mut().zip(first) {
                *a = *w * *a;
            }
            for (t, w) in rest.iter().enumerate() {
                for ((a, w), c) in acc.iter_mut().zip(w).zip(&self.lanes[h + n + t + 1]) {
                    *a += *w * *c;
                }
            }
            self.lanes[n] = acc;
        }
        for (lane, out) in outs.iter_mut().enumerate() {
            for (o, l) in out.iter_mut().zip(&self.lanes) {
                *o = l[lane];
            }
        }
    }
}

impl<T: Sample> RowShifter<T> for BSplineShifter<'_, T> {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()> {
        self.shift_group(&[row], &[shift], &mut [out]);
        Ok(())
    }

    fn shift_rows(&mut self, rows: &[&[T]], shifts: &[f64], outs: &mut [&mut [T]]) -> Result<()> {
        for ((rows, shifts), outs) in rows
            .chunks(ROW_GROUP)
            .zip(shifts.chunks(ROW_GROUP))
            .zip(outs.chunks_mut(ROW_GROUP))
        {
            self.shift_group(rows, shifts, outs);
        }
        Ok(())
    }
}

impl<T: Sample> ShearKernel<T> for BSpline {
    fn name(&self) -> String {
        format!("bspline{}", self.degree)
    }

    fn support_radius(&self) -> usize {
        self.degree.div_ceil(2) + self.horizon::<T>()
    }

    fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        Box::new(BSplineShifter {
            spline: self,
            horizon: self.horizon::<T>(),
            outside,
            weights: vec![[T::zero(); ROW_GROUP]; self.degree + 1],
            extended: Vec::new(),
            lanes: Vec::new(),
        })
    }
}
