//! Rotating analytic Phong lobes: every method against the exactly rotated lobe.
//!
//! The lobe `f(w) = (e + 2) / (2 pi) max(0, r0 . w)^e` ([`phong`]) about an axis `r0` is
//! sampled at the texel centres of an `H x 2H` map ([`LatLongMap::from_fn`]) and rotated;
//! `g(p) = f(R p)` is the same lobe about `R^-1 r0`, so the truth is known in closed form.
//! Each result is compared with two versions of it:
//!
//! * **centres**: the analytic rotated lobe at the target texel centres (what the source
//!   holds, so a method that interpolated perfectly would score zero);
//! * **means**: its solid-angle mean over each target texel
//!   ([`LatLongMap::from_fn_mean`], 16 x 16 samples), what [`Method::Reference`] estimates.
//!
//! Errors are solid-angle weighted RMS differences ([`weighted_rms`]) divided by the weighted
//! RMS of the analytic rotated lobe (at the centres).

use std::time::Instant;

use super::map_error::{relative_energy_error, weighted_rms};
use super::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
use crate::Result;

/// Stratum samples per axis of the texel-mean truth.
const MEAN_SAMPLES: usize = 16;

/// The energy-normalised Phong lobe `(e + 2) / (2 pi) max(0, axis . d)^e` (with `0^0 = 1`).
///
/// ```
/// use haarshift::sphere::lobes::phong;
/// let peak = phong(10.0, [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]);
/// assert!((peak - 12.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-15);
/// assert_eq!(phong(10.0, [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]), 0.0);
/// ```
pub fn phong(exponent: f64, axis: [f64; 3], d: [f64; 3]) -> f64 {
    let c = axis[0] * d[0] + axis[1] * d[1] + axis[2] * d[2];
    (exponent + 2.0) / (2.0 * std::f64::consts::PI) * c.max(0.0).powf(exponent)
}

/// The lobe axes measured, with their names: the pole (+Y, where the map's rows crowd) and
/// a horizon direction at azimuth 30 degrees (where a texel is square on the sphere).
pub const AXES: [(&str, [f64; 3]); 2] = [
    ("pole", [0.0, 1.0, 0.0]),
    ("horizon", [0.5, 0.0, 0.866_025_403_784_438_6]),
];

/// The rotations measured, as `(yaw, pitch, roll)` in degrees: pitches of 30, 45, 60 and 90
/// degrees and the compound rotation of [`STANDARD_ROTATIONS`](super::map_error::STANDARD_ROTATIONS).
pub const ROTATIONS: [(f64, f64, f64); 5] = [
    (0.0, 30.0, 0.0),
    (0.0, 45.0, 0.0),
    (0.0, 60.0, 0.0),
    (0.0, 90.0, 0.0),
    (40.0, -25.0, 60.0),
];

/// One measurement: a lobe, a rotation, a method at a level, its errors and its time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LobeRecord {
    /// Map height `H` (the map is `H x 2H`).
    pub height: usize,
    /// Phong exponent.
    pub exponent: f64,
    /// Name of the lobe's axis ([`AXES`]).
    pub axis: String,
    /// Yaw, degrees.
    pub yaw: f64,
    /// Pitch, degrees.
    pub pitch: f64,
    /// Roll, degrees.
    pub roll: f64,
    /// The method.
    pub method: Method,
    /// The finest detail level computed.
    pub level: usize,
    /// Weighted RMS against the analytic lobe at the texel centres, over the lobe's RMS.
    pub error_centres: f64,
    /// Weighted RMS against the analytic lobe's texel means, over the lobe's RMS.
    pub error_means: f64,
    /// Relative change of the solid-angle integral against the source map.
    pub energy_error: f64,
    /// Wall-clock seconds of one [`rotate_map`] call (f64; use the criterion bench for
    /// speed claims).
    pub seconds: f64,
}

/// Rotates a Phong lobe of every exponent about every axis of [`AXES`] on an `height`-row
/// map by every rotation with every `(method, level)`, and compares with the analytic
/// rotated lobe (`reference_samples` per axis for [`Method::Reference`]).
///
/// ```
/// use haarshift::sphere::{Method, lobes::run};
/// let rows = run(16, &[10.0], &[(0.0, 30.0, 0.0)], &[(Method::Haar, None)], 4).unwrap();
/// assert_eq!(rows.len(), 2); // two axes
/// assert!(rows.iter().all(|r| r.error_centres > 0.0 && r.error_centres < 0.5));
/// ```
pub fn run(
    height: usize,
    exponents: &[f64],
    rotations: &[(f64, f64, f64)],
    methods: &[(Method, Option<usize>)],
    reference_samples: usize,
) -> Result<Vec<LobeRecord>> {
    let finest = height.trailing_zeros().saturating_sub(1) as usize;
    let mut records = Vec::new();
    for &exponent in exponents {
        for (name, axis) in AXES {
            let source = LatLongMap::<f64>::from_fn(height, 1, |d, out| {
                out[0] = phong(exponent, axis, d);
            })?;
            for &(yaw, pitch, roll) in rotations {
                let rotation = SphereRotation::from_degrees(yaw, pitch, roll)?;
                let turned = rotation.inverse().apply(axis);
                let lobe = |d: [f64; 3], out: &mut [f64]| out[0] = phong(exponent, turned, d);
                let centres = LatLongMap::from_fn(height, 1, lobe)?;
                let means = LatLongMap::from_fn_mean(height, 1, MEAN_SAMPLES, lobe)?;
                let zero = LatLongMap::from_fn(height, 1, |_, out| out[0] = 0.0)?;
                let scale = weighted_rms(&centres, &zero)?;
                for &(method, level) in methods {
                    let options = SphereOptions {
                        method,
                        level,
                        reference_samples,
                    };
                    let start = Instant::now();
                    let g = rotate_map(&source, &rotation, &options)?.map;
                    let seconds = start.elapsed().as_secs_f64();
                    records.push(LobeRecord {
                        height,
                        exponent,
                        axis: name.to_owned(),
                        yaw,
                        pitch,
                        roll,
                        method,
                        level: level.unwrap_or(finest),
                        error_centres: weighted_rms(&g, &centres)? / scale,
                        error_means: weighted_rms(&g, &means)? / scale,
                        energy_error: relative_energy_error(&g, &source),
                        seconds,
                    });
                }
            }
        }
    }
    Ok(records)
}
