//! The 1D Haar transform of a length-2^N signal, full (N steps) or partial (k steps).
//!
//! Layout (Alnasser 2008's chapter 2): after k steps a length-L signal holds its `L / 2^k` scaling
//! coefficients first, then the details level by level, coarsest first. Detail level `l`
//! (`l = 0` coarsest stored) occupies indices `[n0 << l, n0 << (l + 1))` with `n0 = L >> k`.

use std::ops::Range;

use ndarray::{Array1, ArrayView1, ArrayViewMut1};

use super::Normalization;
use crate::{Error, Result, Sample};

/// Checks that `len` is a power of two and `levels` steps fit; returns `log2(len)`.
pub(crate) fn check_length(len: usize, levels: usize) -> Result<usize> {
    if len == 0 || !len.is_power_of_two() {
        return Err(Error::shape(
            &[len],
            "length must be a non-zero power of two",
        ));
    }
    let depth = len.trailing_zeros() as usize;
    if levels > depth {
        return Err(Error::parameter(
            "levels",
            format!("{levels} steps do not fit a length-{len} signal (at most {depth})"),
        ));
    }
    Ok(depth)
}

/// Index range of detail level `level` in a transform whose scaling block has length `n0`.
///
/// ```
/// use haarshift::transform::haar1d::detail_range;
/// // A full transform of length 8: [s, d0, d1 d1, d2 d2 d2 d2].
/// assert_eq!(detail_range(1, 0), 1..2);
/// assert_eq!(detail_range(1, 2), 4..8);
/// ```
pub fn detail_range(n0: usize, level: usize) -> Range<usize> {
    (n0 << level)..(n0 << (level + 1))
}

/// One analysis step on `data[..n]`: scaling coefficients to the first half, details to the
/// second half. `scratch` must hold at least `n / 2` values.
#[inline]
fn forward_step<T: Sample>(data: &mut [T], n: usize, f: T, scratch: &mut [T]) {
    let half = n / 2;
    for i in 0..half {
        let (x0, x1) = (data[2 * i], data[2 * i + 1]);
        // Writing index i never clobbers an unread input: 2i >= i.
        data[i] = f * (x0 + x1);
        scratch[i] = f * (x0 - x1);
    }
    data[half..n].copy_from_slice(&scratch[..half]);
}

/// One synthesis step on `data[..n]`, the inverse of [`forward_step`]. `scratch` must hold `n`.
#[inline]
fn inverse_step<T: Sample>(data: &mut [T], n: usize, g: T, scratch: &mut [T]) {
    let half = n / 2;
    scratch[..n].copy_from_slice(&data[..n]);
    let (s, d) = scratch[..n].split_at(half);
    for i in 0..half {
        data[2 * i] = g * (s[i] + d[i]);
        data[2 * i + 1] = g * (s[i] - d[i]);
    }
}

/// Forward transform of `data` in place with `levels` steps; `scratch` is grown as needed and
/// can be reused across calls so that the loop allocates nothing.
///
/// ```
/// use haarshift::transform::{Normalization, haar1d};
/// let mut x = vec![4.0, 2.0, 5.0, 5.0];
/// haar1d::forward_in_place(&mut x, 2, Normalization::Average, &mut Vec::new()).unwrap();
/// assert_eq!(x, [4.0, -1.0, 1.0, 0.0]);
/// ```
pub fn forward_in_place<T: Sample>(
    data: &mut [T],
    levels: usize,
    norm: Normalization,
    scratch: &mut Vec<T>,
) -> Result<()> {
    check_length(data.len(), levels)?;
    scratch.resize(data.len(), T::zero());
    let f = norm.forward_factor::<T>();
    let mut n = data.len();
    for _ in 0..levels {
        forward_step(data, n, f, scratch);
        n /= 2;
    }
    Ok(())
}

/// Inverse of [`forward_in_place`] with the same `levels` and normalisation.
///
/// ```
/// use haarshift::transform::{Normalization, haar1d};
/// let mut c = vec![4.0, -1.0, 1.0, 0.0];
/// haar1d::inverse_in_place(&mut c, 2, Normalization::Average, &mut Vec::new()).unwrap();
/// assert_eq!(c, [4.0, 2.0, 5.0, 5.0]);
/// ```
pub fn inverse_in_place<T: Sample>(
    data: &mut [T],
    levels: usize,
    norm: Normalization,
    scratch: &mut Vec<T>,
) -> Result<()> {
    check_length(data.len(), levels)?;
    scratch.resize(data.len(), T::zero());
    let g = norm.inverse_factor::<T>();
    let mut n = data.len() >> levels;
    for _ in 0..levels {
        n *= 2;
        inverse_step(data, n, g, scratch);
    }
    Ok(())
}

/// Applies `op` to `lane` as a contiguous slice, copying through `buffer` when the view is
/// strided (a column, say).
pub(crate) fn with_contiguous<T: Sample>(
    mut lane: ArrayViewMut1<'_, T>,
    buffer: &mut Vec<T>,
    op: impl FnOnce(&mut [T]) -> Result<()>,
) -> Result<()> {
    if let Some(slice) = lane.as_slice_mut() {
        return op(slice);
    }
    buffer.clear();
    buffer.extend(lane.iter().copied());
    op(buffer)?;
    lane.iter_mut()
        .zip(buffer.iter())
        .for_each(|(dst, &src)| *dst = src);
    Ok(())
}

/// Forward transform of a 1D array, returning its coefficients.
///
/// ```
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::array;
/// let c = haar1d::forward(array![1.0, 3.0].view(), 1, Normalization::Orthonormal).unwrap();
/// assert!((c[0] - 4.0 / 2f64.sqrt()).abs() < 1e-15);
/// ```
pub fn forward<T: Sample>(
    signal: ArrayView1<'_, T>,
    levels: usize,
    norm: Normalization,
) -> Result<Array1<T>> {
    let mut out = signal.to_owned();
    let mut scratch = Vec::new();
    forward_in_place(
        out.as_slice_mut().expect("owned arrays are contiguous"),
        levels,
        norm,
        &mut scratch,
    )?;
    Ok(out)
}

/// Inverse transform of a 1D coefficient array, returning the signal.
///
/// ```
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::array;
/// let x = array![1.0, 3.0, -2.0, 8.0];
/// let c = haar1d::forward(x.view(), 2, Normalization::Average).unwrap();
/// assert_eq!(haar1d::inverse(c.view(), 2, Normalization::Average).unwrap(), x);
/// ```
pub fn inverse<T: Sample>(
    coefficients: ArrayView1<'_, T>,
    levels: usize,
    norm: Normalization,
) -> Result<Array1<T>> {
    let mut out = coefficients.to_owned();
    let mut scratch = Vec::new();
    inverse_in_place(
        out.as_slice_mut().expect("owned arrays are contiguous"),
        levels,
        norm,
        &mut scratch,
    )?;
    Ok(out)
}

#[cfg(test)]
#[path = "haar1d_tests.rs"]
mod tests;
