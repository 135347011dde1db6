//! The solid-angle-weighted downsample of a lat-long map: the working resolution an
//! environment is brought to.
//!
//! [`downsample_solid_angle`] gives each target texel the mean of the source over the texel
//! *on the sphere*: `sum_s v_s |s and t| / |t|`, where `|.|` is solid angle. The overlaps are
//! exact for any source height `H` and target height `N`, multiples or not: a texel is a
//! rectangle in `(theta, phi)`, so the overlap of two is a rectangle too, of solid angle
//! `(cos theta_0 - cos theta_1) (phi_1 - phi_0)`, and its edges are found in integer units of
//! `pi / (H N)` (no rounding decides which texels meet). So every source texel's solid angle is
//! shared out in full, and the integral over the sphere (the map's energy, [`LatLongMap::energy`])
//! is unchanged to rounding (tested to 1e-12 relative). [`LatLongMap::downsample`] instead takes
//! the plain mean of each block, which is what a Haar pyramid holds but weighs a texel next to
//! a pole as much as one at the equator, so it moves energy wherever the map is not constant
//! along a block's rows (tested: a bright pole cap changes the energy by percents).

use ndarray::{Array2, Array3, Axis, s};
use rayon::prelude::*;

use crate::{Error, Result};
use haarshift::Sample;
use haarshift::sphere::LatLongMap;

/// `map` at `n x 2n`, each texel the solid-angle-weighted mean of the source texels it
/// overlaps (exact overlaps; see the [module docs](self)). `n` runs from 1 to the map's
/// height `H` and need not divide it.
///
/// ```
/// use haarshift_relight::light::downsample::downsample_solid_angle;
/// use haarshift::sphere::LatLongMap;
/// let f = LatLongMap::<f64>::from_fn(48, 2, |d, o| { o[0] = d[1].exp(); o[1] = 1.0 }).unwrap();
/// let g = downsample_solid_angle(&f, 20).unwrap(); // 48 is not a multiple of 20
/// assert_eq!((g.height(), g.width()), (20, 40));
/// assert!((f.energy()[0] - g.energy()[0]).abs() < 1e-12 * f.energy()[0]);
/// assert!(g.as_array().iter().skip(1).step_by(2).all(|&v| (v - 1.0).abs() < 1e-14));
/// assert!(downsample_solid_angle(&f, 49).is_err());
/// ```
pub fn downsample_solid_angle<T: Sample>(map: &LatLongMap<T>, n: usize) -> Result<LatLongMap<T>> {
    let (h, w, ch) = map.as_array().dim();
    if n == 0 || n > h {
        return Err(Error::parameter(
            "resolution",
            format!("{n}: the working height must be from 1 to the map's height {h}"),
        ));
    }
    if n == h {
        return Ok(map.clone());
    }
    // Edges in integer units: a row edge in units of pi / (h n) (source edge r at r n, target
    // edge i at i h), a column edge in units of 2 pi / (2h 2n).
    let row_unit = std::f64::consts::PI / (h * n) as f64;
    let col_unit = std::f64::consts::TAU / (w * 2 * n) as f64;
    let rows = overlaps(h, n);
    let cols = overlaps(w, 2 * n);
    // Columns first: for every source row, the phi integral over each target column.
    let src = map.as_array();
    let src = src.as_slice().expect("standard layout");
    let mut by_column = Array3::<f64>::zeros((h, 2 * n, ch));
    by_column
        .axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(r, mut out)| {
            let line = &src[r * w * ch..][..w * ch];
            for (j, pieces) in cols.iter().enumerate() {
                let mut acc = out.slice_mut(s![j, ..]);
                for &(c, _, len) in pieces {
                    let dphi = len as f64 * col_unit;
                    for (a, v) in acc.iter_mut().zip(&line[c * ch..][..ch]) {
                        *a += dphi * v.as_f64();
                    }
                }
            }
        });
    // Then rows: the theta integral (with its sin theta) over each target row, divided by
    // the target texel's solid angle.
    let mut out = Array3::<T>::zeros((n, 2 * n, ch));
    out.axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(i, mut target)| {
            let mut acc = Array2::<f64>::zeros((2 * n, ch));
            let mut band = 0.0;
            for &(r, start, len) in &rows[i] {
                let (t0, t1) = (start as f64 * row_unit, (start + len) as f64 * row_unit);
                let weight = t0.cos() - t1.cos();
                band += weight;
                acc.scaled_add(weight, &by_column.index_axis(Axis(0), r));
            }
            let area = band * std::f64::consts::PI / n as f64;
            target.zip_mut_with(&acc, |o, &a| *o = T::from_f64(a / area));
        });
    Ok(LatLongMap::new(out)?)
}

/// For each of `targets` equal intervals of `[0, sources x targets)` (target `t` spans
/// `[t sources, (t + 1) sources)`), the source intervals (of width `targets`) it overlaps, as
/// `(source, start, length)` in those integer units.
fn overlaps(sources: usize, targets: usize) -> Vec<Vec<(usize, usize, usize)>> {
    (0..targets)
        .map(|t| {
            let (lo, hi) = (t * sources, (t + 1) * sources);
            (lo / targets..hi.div_ceil(targets))
                .filter_map(|s| {
                    let a = lo.max(s * targets);
                    let b = hi.min((s + 1) * targets);
                    (b > a).then_some((s, a, b - a))
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
#[path = "downsample_tests.rs"]
pub(crate) mod tests;
