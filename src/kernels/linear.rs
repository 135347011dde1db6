//! Linear interpolation.

use super::taps::TapShifter;
use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::Sample;

/// Linear interpolation (the tent kernel `max(0, 1 - |x|)`).
///
/// ```
/// use haarshift::kernels::{Linear, Outside, shear_rows};
/// use ndarray::array;
/// let out = shear_rows(array![[0.0, 4.0, 8.0]].view(), 3, &[0.25], &Linear,
///                      Outside::Fill(0.0)).unwrap();
/// assert_eq!(out.row(0).to_vec(), vec![0.0, 3.0, 7.0]);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct Linear;

fn tent(x: f64) -> f64 {
    (1.0 - x.abs()).max(0.0)
}

impl<T: Sample> ShearKernel<T> for Linear {
    fn name(&self) -> String {
        "linear".into()
    }

    fn support_radius(&self) -> usize {
        1
    }

    fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        Box::new(TapShifter::new(2, tent, false, outside))
    }
}
