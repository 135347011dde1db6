//! Moving between the pixel grid and a `2^e`-finer working grid.

use ndarray::{Array2, ArrayView2, Zip};

use crate::{Error, Result, Sample};

/// Each sample replicated into a `2^e x 2^e` block (nearest-neighbour upsampling).
pub(crate) fn upsample_nearest<T: Sample>(plane: ArrayView2<'_, T>, e: u32) -> Result<Array2<T>> {
    let (h, w) = plane.dim();
    let too_large = || Error::shape(&[h, w], format!("too large for a 2^{e}-finer grid"));
    let f = 1usize
        .checked_shl(e)
        .filter(|f| *f <= 1 << 20)
        .ok_or_else(too_large)?;
    let (fh, fw) = (
        h.checked_mul(f).ok_or_else(too_large)?,
        w.checked_mul(f).ok_or_else(too_large)?,
    );
    fh.checked_mul(fw).ok_or_else(too_large)?;
    if e == 0 {
        return Ok(plane.to_owned());
    }
    Ok(Array2::from_shape_fn((fh, fw), |(r, c)| {
        plane[[r >> e, c >> e]]
    }))
}

/// The mean of each `2^e x 2^e` block (`e > 0`); the sides must be multiples of `2^e`.
pub(crate) fn box_average<T: Sample>(fine: ArrayView2<'_, T>, e: u32) -> Array2<T> {
    let (fh, fw) = fine.dim();
    let f = 1usize << e;
    let mut out = Array2::zeros((fh >> e, fw >> e));
    let scale = T::from_f64(1.0 / (f * f) as f64);
    Zip::indexed(&mut out).par_for_each(|(r, c), o| {
        let block = fine.slice(ndarray::s![r * f..(r + 1) * f, c * f..(c + 1) * f]);
        *o = block.sum() * scale;
    });
    out
}

#[cfg(test)]
#[path = "grid_tests.rs"]
mod tests;
