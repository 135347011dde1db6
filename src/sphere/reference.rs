//! The ground truth: every pixel of `g` is the solid-angle mean of `f(R p)` over the pixel.
//!
//! `f` is taken as the bilinear interpolant of its pixels (continued over the seam and the
//! poles), and the mean over target pixel `[theta0, theta1] x [phi0, phi1]` is
//! `int f(R p) sin theta dtheta dphi / int sin theta dtheta dphi`, estimated with an
//! `n x n` grid of stratum midpoints, each weighted by its own `sin theta` (deterministic, so
//! results are reproducible; [`LatLongMap::from_fn_mean`]). Its error is the midpoint rule's, `O(1/n^2)` per pixel for a
//! smooth `f`. A pure whole-column yaw never gets here: it is an exact column shift for every
//! method ([`rotate_map`](super::rotate_map)).

use super::latlong::angles;
use super::{LatLongMap, SphereRotation};
use crate::{Result, Sample};

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
    LatLongMap::from_fn_mean(map.height(), map.channels(), samples, |d, out| {
        let (t, p) = angles(rotation.apply(d));
        map.bilinear(t, p, out);
    })
}
