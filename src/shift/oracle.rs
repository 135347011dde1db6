//! The definition of a Haar-domain shift, computed literally: upsample by adding `h`
//! zero-detail levels, invert, shift the fine samples periodically by a whole number of fine
//! steps, transform forward, keep the original levels. Memory and time grow by `2^h` per axis,
//! so this is the reference the fast paths are tested against, not something to run on
//! large inputs.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2, s};

use super::GridShift;
use crate::transform::{Normalization, haar1d, pyramid};
use crate::{Error, Result, Sample};

/// Refuses inputs whose upsampled size would not fit in memory at all.
fn upsampled_len(len: usize, precision: u32) -> Result<usize> {
    len.checked_mul(1usize << precision)
        .filter(|&n| n <= 1 << 32)
        .ok_or_else(|| {
            Error::parameter(
                "precision",
                format!("upsampling {len} values by 2^{precision} is too large for the oracle"),
            )
        })
}

/// The shifted 1D transform by definition (layout of [`haar1d`]).
///
/// ```
/// use haarshift::shift::{GridShift, oracle};
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::array;
/// let norm = Normalization::Average;
/// let c = haar1d::forward(array![1.0, 2.0, 3.0, 4.0].view(), 2, norm).unwrap();
/// let shifted = oracle::shift_signal(c.view(), 2, norm, GridShift::whole(1)).unwrap();
/// let x = haar1d::inverse(shifted.view(), 2, norm).unwrap();
/// assert_eq!(x, array![4.0, 1.0, 2.0, 3.0]); // out[n] = in[n - 1]
/// ```
pub fn shift_signal<T: Sample>(
    coeffs: ArrayView1<'_, T>,
    levels: usize,
    norm: Normalization,
    shift: GridShift,
) -> Result<Array1<T>> {
    let n = coeffs.len();
    haar1d::check_length(n, levels)?;
    let h = shift.precision();
    let fine_len = upsampled_len(n, h)?;
    let fine_levels = levels + h as usize;
    // Zero details at the h added finest levels: the coefficients keep their places.
    let mut fine = Array1::zeros(fine_len);
    fine.slice_mut(s![..n]).assign(&coeffs);
    let x = haar1d::inverse(fine.view(), fine_levels, norm)?;
    let (q, frac) = shift.split(n)?;
    let r = (q << h) + frac as usize;
    let moved = Array1::from_shape_fn(fine_len, |m| x[(m + fine_len - r) % fine_len]);
    let out = haar1d::forward(moved.view(), fine_levels, norm)?;
    Ok(out.slice(s![..n]).to_owned())
}

/// The shifted 2D pyramid transform by definition: `dx` moves columns (content to the right
/// for `dx > 0`), `dy` rows (content down). The two shifts are brought to the finer of their
/// precisions.
///
/// ```
/// use haarshift::shift::{GridShift, oracle};
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::array;
/// let norm = Normalization::Orthonormal;
/// let x = array![[1.0f64, 2.0], [3.0, 4.0]];
/// let c = pyramid::forward(x.view(), 1, norm).unwrap();
/// let (dx, dy) = (GridShift::whole(1), GridShift::whole(0));
/// let shifted = oracle::shift_pyramid(c.view(), 1, norm, dx, dy).unwrap();
/// let y = pyramid::inverse(shifted.view(), 1, norm).unwrap();
/// assert!((y[[0, 0]] - 2.0).abs() < 1e-12 && (y[[1, 1]] - 3.0).abs() < 1e-12);
/// ```
pub fn shift_pyramid<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    dx: GridShift,
    dy: GridShift,
) -> Result<Array2<T>> {
    let (rows, cols) = coeffs.dim();
    pyramid::check((rows, cols), levels)?;
    let h = dx.precision().max(dy.precision());
    let (dx, dy) = (dx.refine(h), dy.refine(h));
    let (fine_rows, fine_cols) = (upsampled_len(rows, h)?, upsampled_len(cols, h)?);
    upsampled_len(fine_rows, fine_cols.trailing_zeros())?;
    let mut fine = Array2::zeros((fine_rows, fine_cols));
    fine.slice_mut(s![..rows, ..cols]).assign(&coeffs);
    let fine_levels = levels + h as usize;
    let x = pyramid::inverse(fine.view(), fine_levels, norm)?;
    let (qy, fy) = dy.split(rows)?;
    let (qx, fx) = dx.split(cols)?;
    let (ry, rx) = ((qy << h) + fy as usize, (qx << h) + fx as usize);
    let moved = Array2::from_shape_fn((fine_rows, fine_cols), |(i, j)| {
        x[[
            (i + fine_rows - ry) % fine_rows,
            (j + fine_cols - rx) % fine_cols,
        ]]
    });
    let out = pyramid::forward(moved.view(), fine_levels, norm)?;
    Ok(out.slice(s![..rows, ..cols]).to_owned())
}
