//! The ground truth: every pixel of `g` is the solid-angle mean of `f(R p)` over the pixel.
//!
//! `f` is taken as the bilinear interpolant of its pixels (continued over the seam and the
//! poles), and the mean over target pixel `[theta0, theta1] x [phi0, phi1]` is
//! `int f(R p) sin theta dtheta dphi / int sin theta dtheta dphi`, estimated with an
//! `n x n` grid of stratum midpoints, each weighted by its own `sin theta` (deterministic, so
//! results are reproducible). Its error is the midpoint rule's, `O(1/n^2)` per pixel for a
//! smooth `f`. A pure whole-column yaw never gets here: it is an exact column shift for every
//! method ([`rotate_map`](super::rotate_map)).

use super::latlong::{angles, direction, fill_pixels};
use super::{LatLongMap, SphereRotation};
use crate::{Error, Result, Sample};

/// The solid-angle mean of `f(R p)` over each pixel, with `samples x samples` midpoint
/// samples per pixel (1 to 64).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, reference::reference};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |_, out| out[0] = 2.0).unwrap();
/// let r = SphereRotation::from_degrees(10.0, 37.0, -5.0).unwrap();
/// let g = reference(&f, &r, 8).unwrap();
/// assert!(g.as_array().iter().all(|&v| (v - 2.0).abs() < 1e-12));
/// ```
pub fn reference<T: Sample>(
    map: &LatLongMap<T>,
    rotation: &SphereRotation,
    samples: usize,
) -> Result<LatLongMap<T>> {
    if !(1..=64).contains(&samples) {
        return Err(Error::parameter(
            "samples",
            format!("{samples} samples per axis (expected 1 to 64)"),
        ));
    }
    let (h, ch) = (map.height(), map.channels());
    let step = std::f64::consts::PI / h as f64;
    let sub = step / samples as f64;
    let data = fill_pixels(h, ch, |i, j, out| {
        let mut acc = [0.0f64; 64];
        let acc = &mut acc[..ch];
        let mut value = [T::zero(); 64];
        let value = &mut value[..ch];
        let mut total_weight = 0.0;
        for a in 0..samples {
            let theta = i as f64 * step + (a as f64 + 0.5) * sub;
            let weight = theta.sin();
            total_weight += weight * samples as f64;
            for b in 0..samples {
                let phi = j as f64 * step + (b as f64 + 0.5) * sub;
                let (t, p) = angles(rotation.apply(direction(theta, phi)));
                map.bilinear(t, p, value);
                for (s, v) in acc.iter_mut().zip(value.iter()) {
                    *s += weight * v.as_f64();
                }
            }
        }
        for (o, s) in out.iter_mut().zip(acc.iter()) {
            *o = T::from_f64(s / total_weight);
        }
    })?;
    LatLongMap::new(data)
}
