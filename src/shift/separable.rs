//! N-D shifts of the separable ("standard decomposition") transform, Alnasser 2008's section 2.5:
//! the transform is a 1D transform along each axis in turn, and a shift along one axis
//! commutes with the 1D transforms along the others, so shifting every lane along an axis with
//! the 1D Haar-domain shift shifts the whole array along that axis.

use ndarray::{ArrayViewMut, Axis, Dimension, Zip};
use rayon::prelude::*;

use super::GridShift;
use super::dense::{ShiftWorkspace, shift_slice_in_place};
use crate::transform::{Normalization, haar1d};
use crate::{Error, Result, Sample};

/// Shifts a separable transform in place by `shifts[i]` samples along axis `i`, where axis
/// `i` was transformed with `levels[i]` steps. Lanes are processed in parallel.
///
/// A fractional shift along several axes is the multilinear interpolation of the
/// [module docs](super), one axis at a time.
///
/// ```
/// use haarshift::shift::{GridShift, separable};
/// use haarshift::transform::{Normalization, separable as sep};
/// use ndarray::Array3;
/// let norm = Normalization::Orthonormal;
/// let x = Array3::from_shape_fn((2, 4, 8), |(i, j, k)| (i * 32 + j * 8 + k) as f64);
/// let mut c = x.clone();
/// sep::forward_in_place(c.view_mut(), &[1, 2, 3], norm).unwrap();
/// let shifts = [GridShift::whole(1), GridShift::whole(-1), GridShift::whole(3)];
/// separable::shift_in_place(c.view_mut(), &[1, 2, 3], norm, &shifts).unwrap();
/// sep::inverse_in_place(c.view_mut(), &[1, 2, 3], norm).unwrap();
/// assert!((c[[0, 0, 3]] - x[[1, 1, 0]]).abs() < 1e-12); // out[n] = in[n - shift]
/// ```
pub fn shift_in_place<T: Sample, D: Dimension>(
    mut coeffs: ArrayViewMut<'_, T, D>,
    levels: &[usize],
    norm: Normalization,
    shifts: &[GridShift],
) -> Result<()> {
    let ndim = coeffs.ndim();
    if levels.len() != ndim || shifts.len() != ndim {
        return Err(Error::parameter(
            "shift",
            format!(
                "{} level counts and {} shifts given for a {ndim}-D array",
                levels.len(),
                shifts.len()
            ),
        ));
    }
    for (&n, &k) in coeffs.shape().iter().zip(levels) {
        haar1d::check_length(n, k)?;
    }
    for (&n, s) in coeffs.shape().iter().zip(shifts) {
        s.split(n)?;
    }
    for (axis, (&k, &shift)) in levels.iter().zip(shifts).enumerate() {
        if shift.steps() == 0.0 {
            continue;
        }
        Zip::from(coeffs.lanes_mut(Axis(axis)))
            .into_par_iter()
            .try_for_each_init(
                || (Vec::new(), ShiftWorkspace::default()),
                |(buffer, work), (lane,)| {
                    haar1d::with_contiguous(lane, buffer, |s| {
                        shift_slice_in_place(s, k, norm, shift, work)
                    })
                },
            )?;
    }
    Ok(())
}
