//! Extending an array to power-of-two sides before a transform.

use ndarray::{Array2, ArrayView2, CowArray, Ix2};

use crate::{BoundaryMode, Error, Result, Sample};

/// Pads `image` at the bottom and right to the next power of two on each side, continuing it
/// by `mode`; the original stays at the top left, so cropping `[..rows, ..cols]` undoes it.
/// Returns a borrowed view when no padding is needed.
///
/// ```
/// use haarshift::{BoundaryMode, transform::pad_to_power_of_two};
/// use ndarray::array;
/// let row = array![[1.0, 2.0, 3.0]];
/// let p = pad_to_power_of_two(row.view(), BoundaryMode::Reflect).unwrap();
/// assert_eq!(p, array![[1.0, 2.0, 3.0, 3.0]]);
/// ```
pub fn pad_to_power_of_two<T: Sample>(
    image: ArrayView2<'_, T>,
    mode: BoundaryMode,
) -> Result<CowArray<'_, T, Ix2>> {
    let (rows, cols) = image.dim();
    let (h, w) = padded_size(rows, cols)?;
    if (h, w) == (rows, cols) {
        return Ok(CowArray::from(image));
    }
    let elements = h
        .checked_mul(w)
        .ok_or_else(|| Error::shape(&[rows, cols], "too large to pad to a power of two"))?;
    let mut data: Vec<T> = Vec::new();
    data.try_reserve_exact(elements)
        .map_err(|_| Error::MemoryBudget {
            what: format!("padding {rows}x{cols} to {h}x{w}"),
            needed: (elements as u128) * std::mem::size_of::<T>() as u128,
            budget: 0,
        })?;
    let row_index: Vec<Option<usize>> = (0..h)
        .map(|i| mode.source_index(i as isize, rows))
        .collect();
    let col_index: Vec<Option<usize>> = (0..w)
        .map(|j| mode.source_index(j as isize, cols))
        .collect();
    for ri in &row_index {
        data.extend(col_index.iter().map(|cj| match (ri, cj) {
            (Some(i), Some(j)) => image[[*i, *j]],
            _ => T::zero(),
        }));
    }
    let padded = Array2::from_shape_vec((h, w), data).expect("length is h * w");
    Ok(CowArray::from(padded))
}

/// The sides of a non-empty `rows x cols` array rounded up to powers of two.
pub(crate) fn padded_size(rows: usize, cols: usize) -> Result<(usize, usize)> {
    if rows == 0 || cols == 0 {
        return Err(Error::shape(&[rows, cols], "image is empty"));
    }
    let too_large = || Error::shape(&[rows, cols], "too large to pad to a power of two");
    let h = rows.checked_next_power_of_two().ok_or_else(too_large)?;
    let w = cols.checked_next_power_of_two().ok_or_else(too_large)?;
    Ok((h, w))
}
