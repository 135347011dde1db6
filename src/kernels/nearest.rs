//! Nearest-neighbour shift.

use super::{Outside, RowGeometry, RowShifter, ShearKernel};
use crate::{Result, Sample};

/// Nearest neighbour: `out[n] = row(floor(n - shift + 1/2))` (halves round up), an integer
/// shift by the rounded amount.
///
/// ```
/// use haarshift::kernels::{Nearest, Outside, shear_rows};
/// use ndarray::array;
/// let out = shear_rows(array![[1.0, 2.0, 3.0]].view(), 3, &[0.5], &Nearest,
///                      Outside::Fill(0.0)).unwrap();
/// assert_eq!(out.row(0).to_vec(), vec![1.0, 2.0, 3.0]);
/// let out = shear_rows(array![[1.0, 2.0, 3.0]].view(), 3, &[0.6], &Nearest,
///                      Outside::Fill(0.0)).unwrap();
/// assert_eq!(out.row(0).to_vec(), vec![0.0, 1.0, 2.0]);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct Nearest;

struct NearestShifter(Outside);

impl<T: Sample> RowShifter<T> for NearestShifter {
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()> {
        // floor(n - shift + 1/2) = n + floor(1/2 - shift): one offset for the whole row.
        let offset = (0.5 - shift).floor() as isize;
        self.0.extend_into(row, offset, out);
        Ok(())
    }
}

impl<T: Sample> ShearKernel<T> for Nearest {
    fn name(&self) -> String {
        "nearest".into()
    }

    fn support_radius(&self) -> usize {
        1
    }

    fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_> {
        Box::new(NearestShifter(outside))
    }
}
