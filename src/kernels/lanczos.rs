//! Lanczos windowed sinc.

use std::f64::consts::PI;

use super::taps::TapShifter;
use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::Sample;

/// The Lanczos kernel `sinc(x) sinc(x/a)` for `|x| < a`, zero beyond (`sinc(x) =
/// sin(pi x)/(pi x)`).
///
/// ```
/// use haarshift::kernels::lanczos_value;
/// assert_eq!(lanczos_value(3, 0.0), 1.0);
/// assert!(lanczos_value(3, 1.0).abs() < 1e-16);
/// assert_eq!(lanczos_value(3, 3.0), 0.0);
/// ```
pub fn lanczos_value(a: usize, x: f64) -> f64 {
    let a = a as f64;
    if x == 0.0 {
        1.0
    } else if x.abs() < a {
        let px = PI * x;
        a * px.sin() * (px / a).sin() / (px * px)
    } else {
        0.0
    }
}

/// Lanczos windowed sinc with `2a` taps, weights normalised to sum to one per row (so a
/// constant stays constant exactly up to rounding).
///
/// ```
/// use haarshift::kernels::{Lanczos, Outside, shear_rows};
/// use ndarray::Array2;
/// let ones = Array2::<f64>::ones((1, 16));
/// let out = shear_rows(ones.view(), 16, &[0.3], &Lanczos::new(3), Outside::Fill(1.0)).unwrap();
/// assert!(out.iter().all(|v| (v - 1.0).abs() < 1e-15));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanczos {
    a: usize,
}

impl Lanczos {
    /// Lanczos-`a`; `a` is clamped to at least 1.
    pub fn new(a: usize) -> Self {
        Lanczos { a: a.max(1) }
    }
}

impl<T: Sample> ShearKernel<T> for Lanczos {
    fn name(&self) -> String {
        format!("lanczos{}", self.a)
    }

    fn support_radius(&self) -> usize {
        self.a
    }

    fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        let a = self.a;
        Box::new(TapShifter::new(
            2 * a,
            move |x| lanczos_value(a, x),
            true,
            outside,
        ))
    }
}
