//! The exact path for a yaw by whole columns: `g(theta, phi) = f(theta, phi + k 2 pi / W)`
//! is a periodic shift of the map's columns, in pixels and in Haar coefficients.
//!
//! In the coefficient domain ([`yaw_coefficients`]): write `k = odd * 2^s`. At every detail
//! level whose blocks are at most `2^s` columns wide, a shift by `k` moves whole blocks, so
//! those bands are permuted (their columns turn by `k / block width`) with no arithmetic.
//! The coarser levels and the scaling block are the pyramid of the approximation at the
//! resolution whose pixels are `2^s` columns wide; there the shift is the whole number
//! `k >> s` of pixels, so that small pyramid is inverted, turned and transformed again
//! (`O(N / 4^s)` arithmetic). Everything stays exact up to the rounding of that small
//! transform pair.
//!
//! This is one small function on purpose: a general Haar-domain shift can replace it.

use ndarray::{Array2, Axis, s};

use super::{LatLongMap, SphereCoefficients};
use crate::Result;
use crate::transform::{Band, Normalization, pyramid};

/// The pixels of `f` turned by `k` columns about +Y (see
/// [`LatLongMap::roll_columns`]).
///
/// ```
/// use haarshift::sphere::{LatLongMap, yaw::yaw_pixels};
/// let f = LatLongMap::<f64>::from_fn(2, 1, |d, out| out[0] = d[0]).unwrap();
/// assert_eq!(yaw_pixels(&f, 1).as_array()[[0, 0, 0]], f.as_array()[[0, 1, 0]]);
/// ```
pub fn yaw_pixels<T: crate::Sample>(map: &LatLongMap<T>, k: usize) -> LatLongMap<T> {
    map.roll_columns(k)
}

/// The coefficients of `f` turned by `k` columns, computed in the coefficient domain.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereCoefficients, yaw::yaw_coefficients};
/// let f = LatLongMap::<f64>::from_fn(8, 1, |d, out| out[0] = d[0] + d[1] * d[2]).unwrap();
/// let c = SphereCoefficients::from_map(&f).unwrap();
/// let got = yaw_coefficients(&c, 6).unwrap();
/// let want = SphereCoefficients::from_map(&f.roll_columns(6)).unwrap();
/// let err = (&got.as_array() - &want.as_array()).iter().fold(0.0f64, |a, v| a.max(v.abs()));
/// assert!(err < 1e-14);
/// ```
pub fn yaw_coefficients<T: crate::Sample>(
    coeffs: &SphereCoefficients<T>,
    k: usize,
) -> Result<SphereCoefficients<T>> {
    let (ch, h, w) = coeffs.as_array().dim();
    let levels = coeffs.levels();
    let k = k % w;
    if k == 0 {
        return Ok(coeffs.clone());
    }
    let s_bits = (k.trailing_zeros() as usize).min(levels);
    let src = coeffs.as_array();
    let mut out = src.to_owned();
    for c in 0..ch {
        let plane = src.index_axis(Axis(0), c);
        let mut dst = out.index_axis_mut(Axis(0), c);
        // Levels whose blocks (h >> level columns) divide k: permute band columns.
        for level in levels - s_bits..levels {
            let turn = k / (h >> level);
            for band in [Band::Horizontal, Band::Vertical, Band::Diagonal] {
                let (rows, cols) = pyramid::band_ranges((h, w), levels, band, level)?;
                let width = cols.len();
                let from = plane.slice(s![rows.clone(), cols.clone()]);
                let mut to = dst.slice_mut(s![rows, cols]);
                for j in 0..width {
                    to.column_mut(j).assign(&from.column((j + turn) % width));
                }
            }
        }
        // The rest: the pyramid of the approximation with 2^s-column pixels.
        let (sh, sw) = (h >> s_bits, w >> s_bits);
        let small_levels = levels - s_bits;
        let top = plane.slice(s![..sh, ..sw]);
        let approx = pyramid::inverse(top, small_levels, Normalization::Average)?;
        let turn = k >> s_bits;
        let turned = Array2::from_shape_fn((sh, sw), |(i, j)| approx[[i, (j + turn) % sw]]);
        let coarse = pyramid::forward(turned.view(), small_levels, Normalization::Average)?;
        dst.slice_mut(s![..sh, ..sw]).assign(&coarse);
    }
    SphereCoefficients::from_array(out)
}
