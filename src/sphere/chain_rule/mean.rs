//! Step 6: the scaling coefficients, chosen so that the rotation keeps the map's
//! solid-angle integral (plain or pole-corrected).

use std::f64::consts::PI;

use ndarray::{Axis, s};

use crate::sphere::latlong::pixel_solid_angle;
use crate::sphere::{LatLongMap, SphereCoefficients};
use crate::transform::{Band, pyramid};
use crate::{Error, Result, Sample};

/// Sets each channel's constant so that the solid-angle integral of the map equals
/// `energy` (step 6), keeping every difference.
///
/// The integral is computed from the coefficients by the row-sum recursion: the two rows of
/// children of a block with average `A` and vertical detail `b` sum to `2 (A + b)` and
/// `2 (A - b)`.
pub fn set_mean_from_energy<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    energy: &[f64],
) -> Result<()> {
    let solid = row_solid_angles(coeffs.height());
    set_mean(coeffs, energy, 0.0, &solid)
}

/// Sets each channel's constant so that [`sampled_integral`] of the map equals that of
/// `samples` (the [`Scheme::Cubic`](super::Scheme::Cubic) choice of step 6), keeping every difference.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereCoefficients, chain_rule::*};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = (4.0 * d[1]).exp()).unwrap();
/// let mut c = SphereCoefficients::from_map(&f).unwrap();
/// set_mean_from_sampled_integral(&mut c, &f).unwrap();
/// let back = c.to_map().unwrap();
/// assert!((sampled_integral(&back)[0] - sampled_integral(&f)[0]).abs() < 1e-12);
/// ```
pub fn set_mean_from_sampled_integral<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    samples: &LatLongMap<T>,
) -> Result<()> {
    let m = coeffs.height();
    let target = sampled_integral(samples);
    set_mean(coeffs, &target, pole_weight(m), &row_solid_angles(m))
}

/// The integral over the sphere of the function whose values at the texel centres the map
/// holds, to fourth order in the texel size `delta`: `sum_ij X_ij Omega_i` (the exact row
/// solid angles `Omega_i`) is off by `delta^2 / 24` times `(4 pi) mean(f)` (a factor common
/// to every rotation of `f`) minus `2 pi (f_N + f_S)`, the values at the two poles (the
/// Euler-Maclaurin end terms of the rows, `[f cos theta]` from 0 to `pi`). This returns the
/// sum with the pole terms removed, `sum_ij X_ij Omega_i - (delta^2 / 24) 2 pi (N + S)`, with
/// `N`, `S` the means of the first and last rows: a quantity a rotation preserves to
/// `O(delta^4)` (the plain sum changes by `O(delta^2)` when a peak moves onto a pole).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::sampled_integral};
/// // exp(4 y) about the pole and turned to the horizon: the plain sums differ by 3.9e-4
/// // relative, these by less than 1e-5.
/// let r = SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap();
/// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = (4.0 * d[1]).exp()).unwrap();
/// let g = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = (4.0 * r.apply(d)[1]).exp()).unwrap();
/// let rel = |a: f64, b: f64| (a - b).abs() / b;
/// assert!(rel(f.energy()[0], g.energy()[0]) > 3e-4);
/// assert!(rel(sampled_integral(&f)[0], sampled_integral(&g)[0]) < 1e-5);
/// ```
pub fn sampled_integral<T: Sample>(samples: &LatLongMap<T>) -> Vec<f64> {
    let a = samples.as_array();
    let (m, n, _) = a.dim();
    let w = pole_weight(m) * 2.0 * PI / n as f64;
    let row_mean = |i: usize, k: usize| -> f64 {
        a.index_axis(Axis(0), i)
            .index_axis(Axis(1), k)
            .iter()
            .map(|v| v.as_f64())
            .sum()
    };
    samples
        .energy()
        .iter()
        .enumerate()
        .map(|(k, e)| e - w * (row_mean(0, k) + row_mean(m - 1, k)))
        .collect()
}

/// `delta^2 / 24` for an `m`-row map: the weight of the pole terms of [`sampled_integral`].
pub(super) fn pole_weight(m: usize) -> f64 {
    let delta = PI / m as f64;
    delta * delta / 24.0
}

/// The solid angle `Omega_i` of a pixel in each row of an `m`-row map.
pub(super) fn row_solid_angles(m: usize) -> Vec<f64> {
    (0..m).map(|i| pixel_solid_angle(m, i)).collect()
}

/// Sets each channel's constant so that `sum_ij X_ij Omega_i - pole 2 pi (N + S)` (see
/// [`sampled_integral`]; `pole = 0`: the plain solid-angle integral) equals `target`, with
/// `solid` the map's [`row_solid_angles`].
pub(super) fn set_mean<T: Sample>(
    coeffs: &mut SphereCoefficients<T>,
    target: &[f64],
    pole: f64,
    solid: &[f64],
) -> Result<()> {
    let (ch, m, n) = coeffs.as_array().dim();
    if target.len() != ch {
        return Err(Error::parameter(
            "energy",
            format!("{} values for {ch} channels", target.len()),
        ));
    }
    let levels = coeffs.levels();
    let w = pole * 2.0 * PI / n as f64;
    for (k, &target) in target.iter().enumerate() {
        let data = coeffs.as_array();
        let plane = data.index_axis(Axis(0), k);
        let mut rows = vec![plane[[0, 0]].as_f64() + plane[[0, 1]].as_f64()];
        for level in 0..levels {
            let (r, c) = pyramid::band_ranges((m, n), levels, Band::Vertical, level)?;
            let b = plane.slice(s![r, c]);
            rows = rows
                .iter()
                .zip(b.axis_iter(Axis(0)))
                .flat_map(|(&sum, brow)| {
                    let sb: f64 = brow.iter().map(|v| v.as_f64()).sum();
                    [2.0 * (sum + sb), 2.0 * (sum - sb)]
                })
                .collect();
        }
        let current: f64 = rows
            .iter()
            .enumerate()
            .map(|(i, s)| solid[i] * s)
            .sum::<f64>()
            - w * (rows[0] + rows[m - 1]);
        // A constant c adds 4 pi c to the sum and 2 pi c to each pole mean.
        let shift = T::from_f64((target - current) / (4.0 * PI * (1.0 - pole)));
        coeffs.shift_mean(k, shift)?;
    }
    Ok(())
}
