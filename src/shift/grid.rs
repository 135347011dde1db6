//! Shift amounts resolved onto the grid of `1 / 2^precision` samples.

use crate::{Error, Result};

/// The largest precision `h` accepted: shifts are resolved to `1 / 2^20` of a sample.
///
/// The compact shift costs nothing extra for a larger `h`, but the retained form grows by
/// `2^h` per axis and, beyond 20, a finer grid is below anything a Haar shift can represent
/// faithfully in f32 (24-bit mantissa).
///
/// ```
/// use haarshift::{Error, shift::{GridShift, MAX_PRECISION}};
/// let finer = GridShift::new(0.5, MAX_PRECISION + 1);
/// assert!(matches!(finer, Err(Error::InvalidParameter { name: "precision", .. })));
/// ```
pub const MAX_PRECISION: u32 = 20;

/// A shift of a whole number of `1 / 2^precision` samples.
///
/// Sign convention (that of `scipy.ndimage.shift`): a positive shift moves content towards
/// higher indices, `out[n] = in[n - s]`, periodically.
///
/// The amount is rounded to the nearest multiple of `1 / 2^precision`, **ties towards
/// `+infinity`** (`floor(x * 2^h + 1/2) / 2^h`, computed exactly). That rule commutes with
/// whole-sample translation, so shifting by `s + m` (`m` an integer) is always shifting by `s`
/// then by `m`, for negative amounts too; round-half-away-from-zero would not be.
///
/// ```
/// use haarshift::shift::GridShift;
/// assert_eq!(GridShift::new(0.3, 2).unwrap().amount(), 0.25);
/// assert_eq!(GridShift::new(0.125, 2).unwrap().amount(), 0.25); // tie: up
/// assert_eq!(GridShift::new(-0.125, 2).unwrap().amount(), 0.0); // tie: up, not away from 0
/// assert_eq!(GridShift::new(-1.125, 2).unwrap().amount(), -1.0); // = -1 + round(-0.125)
/// let nan = GridShift::new(f64::NAN, 0);
/// assert!(matches!(nan, Err(haarshift::Error::InvalidParameter { name: "shift", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridShift {
    /// `round(amount * 2^precision)`: an integer held exactly in an f64, so that any finite
    /// amount, however large, is representable and reduces exactly modulo a period.
    steps: f64,
    precision: u32,
}

impl GridShift {
    /// Rounds `amount` (samples, any finite value) to the grid of `1 / 2^precision`.
    pub fn new(amount: f64, precision: u32) -> Result<Self> {
        if precision > MAX_PRECISION {
            return Err(Error::parameter(
                "precision",
                format!("{precision} is above the maximum of {MAX_PRECISION}"),
            ));
        }
        if !amount.is_finite() {
            return Err(Error::parameter(
                "shift",
                format!("{amount} is not a finite number"),
            ));
        }
        let scaled = amount * (1u64 << precision) as f64;
        if !scaled.is_finite() {
            return Err(Error::parameter(
                "shift",
                format!("{amount} is too large for precision {precision}"),
            ));
        }
        // Exact round-half-up: `scaled - floor(scaled)` is exact in binary floating point.
        let floor = scaled.floor();
        let steps = if scaled - floor >= 0.5 {
            floor + 1.0
        } else {
            floor
        };
        Ok(GridShift { steps, precision })
    }

    /// A whole-sample shift (precision 0). Exact for `|samples| <= 2^53`.
    ///
    /// ```
    /// use haarshift::shift::GridShift;
    /// assert_eq!(GridShift::whole(-3).amount(), -3.0);
    /// ```
    pub fn whole(samples: i64) -> Self {
        GridShift {
            steps: samples as f64,
            precision: 0,
        }
    }

    /// The shift in samples, after rounding to the grid.
    pub fn amount(self) -> f64 {
        self.steps / (1u64 << self.precision) as f64
    }

    /// The number of `1 / 2^precision` steps (an integer value).
    ///
    /// ```
    /// use haarshift::shift::GridShift;
    /// assert_eq!(GridShift::new(1.5, 3).unwrap().steps(), 12.0);
    /// ```
    pub fn steps(self) -> f64 {
        self.steps
    }

    /// The precision `h`: the grid is `1 / 2^h` of a sample.
    pub fn precision(self) -> u32 {
        self.precision
    }

    /// The same shift counted in steps of the finer grid `1 / 2^h`, as a whole shift there:
    /// how a retained (upsampled) signal sees it.
    ///
    /// ```
    /// use haarshift::shift::GridShift;
    /// let s = GridShift::new(0.75, 2).unwrap();
    /// assert_eq!(s.in_grid_units(), GridShift::whole(3));
    /// ```
    pub fn in_grid_units(self) -> GridShift {
        GridShift {
            steps: self.steps,
            precision: 0,
        }
    }

    /// The same shift on a finer grid `precision >= self.precision()` (exact).
    pub(crate) fn refine(self, precision: u32) -> GridShift {
        let extra = precision.saturating_sub(self.precision);
        GridShift {
            steps: self.steps * (1u64 << extra) as f64,
            precision: self.precision.max(precision),
        }
    }

    /// The shift divided by `2^t` as a whole shift, when it is a whole multiple of `2^t`
    /// samples; `None` otherwise.
    pub(crate) fn whole_multiple_of(self, t: u32) -> Option<GridShift> {
        let unit = (1u64 << (self.precision + t)) as f64;
        let q = self.steps / unit;
        (q == q.trunc()).then_some(GridShift {
            steps: q,
            precision: 0,
        })
    }

    /// Splits the shift, reduced modulo a period of `n` samples, into whole samples
    /// `q in 0..n` and a fraction `frac / 2^precision`, `frac in 0..2^precision`.
    pub(crate) fn split(self, n: usize) -> Result<(usize, u64)> {
        let period = n as f64 * (1u64 << self.precision) as f64;
        if period > (1u64 << 53) as f64 {
            return Err(Error::parameter(
                "precision",
                format!("{} is too fine for a period of {n} samples", self.precision),
            ));
        }
        // Exact: fmod of binary floats is exact, and the result is an integer below 2^53.
        let r = self.steps.rem_euclid(period) as u64;
        Ok((
            (r >> self.precision) as usize,
            r & ((1 << self.precision) - 1),
        ))
    }

    /// The interpolation weight `frac / 2^precision` of [`split`](Self::split).
    pub(crate) fn weight(self, frac: u64) -> f64 {
        frac as f64 / (1u64 << self.precision) as f64
    }
}

impl std::ops::Add for GridShift {
    type Output = GridShift;
    /// The composition of two shifts, on the finer of the two grids.
    fn add(self, other: GridShift) -> GridShift {
        let p = self.precision.max(other.precision);
        GridShift {
            steps: self.refine(p).steps + other.refine(p).steps,
            precision: p,
        }
    }
}

impl std::ops::Neg for GridShift {
    type Output = GridShift;
    fn neg(self) -> GridShift {
        GridShift {
            steps: -self.steps,
            precision: self.precision,
        }
    }
}

#[cfg(test)]
#[path = "grid_tests.rs"]
mod tests;
