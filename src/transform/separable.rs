//! The separable ("standard decomposition") Haar transform of an N-D power-of-two array: a 1D
//! transform (layout of [`haar1d`]) along each axis in turn, Alnasser 2008's section
//! 2.5. Axis `i` gets `levels[i]` steps.

use ndarray::{ArrayViewMut, Axis, Dimension, Zip};
use rayon::prelude::*;

use super::{Normalization, haar1d};
use crate::{Error, Result, Sample};

/// Checks every axis length and level count.
fn check(shape: &[usize], levels: &[usize]) -> Result<()> {
    if levels.len() != shape.len() {
        return Err(Error::parameter(
            "levels",
            format!(
                "{} level counts given for a {}-D array",
                levels.len(),
                shape.len()
            ),
        ));
    }
    for (&n, &k) in shape.iter().zip(levels) {
        haar1d::check_length(n, k).map_err(|e| match e {
            Error::InvalidShape { .. } => {
                Error::shape(shape, "every side must be a non-zero power of two")
            }
            other => other,
        })?;
    }
    Ok(())
}

/// Applies a 1D transform to every lane along every axis, in parallel over lanes.
fn along_each_axis<T: Sample, D: Dimension>(
    mut array: ArrayViewMut<'_, T, D>,
    levels: &[usize],
    norm: Normalization,
    step: fn(&mut [T], usize, Normalization, &mut Vec<T>) -> Result<()>,
) -> Result<()> {
    check(array.shape(), levels)?;
    for (axis, &k) in levels.iter().enumerate() {
        if k == 0 {
            continue;
        }
        Zip::from(array.lanes_mut(Axis(axis)))
            .into_par_iter()
            .try_for_each_init(
                || (Vec::new(), Vec::new()),
                |(scratch, buffer), (lane,)| {
                    haar1d::with_contiguous(lane, buffer, |s| step(s, k, norm, scratch))
                },
            )?;
    }
    Ok(())
}

/// Forward separable transform in place, `levels[i]` steps along axis `i`.
///
/// ```
/// use haarshift::transform::{Normalization, separable};
/// use ndarray::array;
/// let mut a = array![[1.0, 3.0], [5.0, 7.0]];
/// separable::forward_in_place(a.view_mut(), &[1, 1], Normalization::Average).unwrap();
/// // For one level on a 2x2 block the separable and pyramid transforms coincide.
/// assert_eq!(a, array![[4.0, -1.0], [-2.0, 0.0]]);
/// ```
pub fn forward_in_place<T: Sample, D: Dimension>(
    array: ArrayViewMut<'_, T, D>,
    levels: &[usize],
    norm: Normalization,
) -> Result<()> {
    along_each_axis(array, levels, norm, haar1d::forward_in_place)
}

/// Inverse of [`forward_in_place`] with the same `levels`.
///
/// ```
/// use haarshift::transform::{Normalization, separable};
/// use ndarray::{Array3, ArrayD};
/// let x = Array3::from_shape_fn((2, 4, 8), |(i, j, k)| (i * 32 + j * 8 + k) as f64).into_dyn();
/// let mut c = x.clone();
/// separable::forward_in_place(c.view_mut(), &[1, 2, 3], Normalization::Orthonormal).unwrap();
/// separable::inverse_in_place(c.view_mut(), &[1, 2, 3], Normalization::Orthonormal).unwrap();
/// assert!(c.iter().zip(x.iter()).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn inverse_in_place<T: Sample, D: Dimension>(
    array: ArrayViewMut<'_, T, D>,
    levels: &[usize],
    norm: Normalization,
) -> Result<()> {
    along_each_axis(array, levels, norm, haar1d::inverse_in_place)
}
