//! Keys cubic convolution.

use super::taps::TapShifter;
use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::{Error, Result, Sample};

/// Keys' cubic convolution kernel with parameter `a` (R. Keys, 1981):
/// `(a+2)|x|^3 - (a+3)|x|^2 + 1` for `|x| <= 1`, `a|x|^3 - 5a|x|^2 + 8a|x| - 4a` for
/// `1 < |x| < 2`, zero beyond.
///
/// ```
/// use haarshift::kernels::keys_value;
/// assert_eq!(keys_value(-0.5, 0.0), 1.0);
/// assert_eq!(keys_value(-0.5, 1.0), 0.0);
/// assert_eq!(keys_value(-0.5, 0.5), 0.5625);
/// assert_eq!(keys_value(-0.5, 2.5), 0.0);
/// ```
pub fn keys_value(a: f64, x: f64) -> f64 {
    let x = x.abs();
    if x <= 1.0 {
        ((a + 2.0) * x - (a + 3.0)) * x * x + 1.0
    } else if x < 2.0 {
        ((a * x - 5.0 * a) * x + 8.0 * a) * x - 4.0 * a
    } else {
        0.0
    }
}

/// Cubic convolution (Keys), 4 taps; `a = -0.5` (the default) reproduces quadratics.
///
/// ```
/// use haarshift::kernels::{Keys, Outside, shear_rows};
/// use ndarray::array;
/// let keys = Keys::new(-0.5).unwrap();
/// let ramp = array![[0.0f64, 1.0, 2.0, 3.0, 4.0, 5.0]];
/// let out = shear_rows(ramp.view(), 6, &[0.5], &keys, Outside::Fill(0.0)).unwrap();
/// assert!((out[[0, 3]] - 2.5).abs() < 1e-12);
/// let nan = Keys::new(f64::NAN);
/// assert!(matches!(nan, Err(haarshift::Error::InvalidParameter { name: "keys a", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keys {
    a: f64,
}

impl Default for Keys {
    fn default() -> Self {
        Keys { a: -0.5 }
    }
}

impl Keys {
    /// Cubic convolution with parameter `a` (finite; the usual range is `[-1, 0)`).
    pub fn new(a: f64) -> Result<Self> {
        if !a.is_finite() {
            return Err(Error::parameter("keys a", format!("{a} is not finite")));
        }
        Ok(Keys { a })
    }

    /// The parameter `a`.
    ///
    /// ```
    /// assert_eq!(haarshift::kernels::Keys::default().a(), -0.5);
    /// ```
    pub fn a(&self) -> f64 {
        self.a
    }
}

impl<T: Sample> ShearKernel<T> for Keys {
    fn name(&self) -> String {
        if self.a == -0.5 {
            "keys".into()
        } else {
            format!("keys(a={})", self.a)
        }
    }

    fn support_radius(&self) -> usize {
        2
    }

    fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        let a = self.a;
        Box::new(TapShifter::new(
            4,
            move |x| keys_value(a, x),
            false,
            outside,
        ))
    }
}
