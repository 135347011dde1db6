//! Measurements for comparing rotation methods against the reference.
//!
//! * [`weighted_rms`]: the solid-angle weighted RMS difference of two maps,
//!   `sqrt(sum_ij w_i |a_ij - b_ij|^2 / (4 pi C))` with `w_i` the pixel solid angle
//!   (a pixel near a pole counts for what it covers on the sphere).
//! * [`coefficient_rms`]: the plain RMS difference of two coefficient pyramids (average
//!   normalisation), which weights coarse levels like fine ones.
//! * [`relative_energy_error`]: `(E(a) - E(b)) / E(b)` for the solid-angle integral `E`
//!   summed over channels; rotation preserves `E` exactly.
//! * [`Comparison`]: all of them at once, plus the RMS at the computed level's resolution.
//! * [`run`]: a table of [`Record`]s (map, method, rotation, level, errors, seconds).

use std::time::Instant;

use ndarray::Axis;

use super::latlong::pixel_solid_angle;
use super::{
    LatLongMap, Method, Rotated, SphereCoefficients, SphereOptions, SphereRotation, rotate_map,
};
use crate::{Error, Result, Sample};

/// The rotations `haarshift experiment sphere` measures, as `(yaw, pitch, roll)` in degrees:
/// pitches of 5, 30, 60 and 90 degrees (small to large tilts of the pole, where the map's
/// distortion changes fastest), a yaw of 10 degrees (`W / 36` columns, never a whole number for a
/// power-of-two width `W`, so a genuinely fractional azimuth shift) and a compound
/// rotation.
///
/// ```
/// use haarshift::sphere::map_error::STANDARD_ROTATIONS;
/// assert_eq!(STANDARD_ROTATIONS[1], (0.0, 30.0, 0.0));
/// assert_eq!(STANDARD_ROTATIONS.len(), 6);
/// ```
pub const STANDARD_ROTATIONS: [(f64, f64, f64); 6] = [
    (0.0, 5.0, 0.0),
    (0.0, 30.0, 0.0),
    (0.0, 60.0, 0.0),
    (0.0, 90.0, 0.0),
    (10.0, 0.0, 0.0),
    (40.0, -25.0, 60.0),
];

/// The maps `haarshift experiment sphere` measures when none are given, embedded in the
/// library so that it runs from any directory: `(name, .npy bytes)`
/// (`testdata/envmaps/SOURCES.md` has their sources and licences).
pub const DEFAULT_MAPS: [(&str, &[u8]); 1] = [(
    "rooitou_park_256x128",
    include_bytes!("../../testdata/envmaps/rooitou_park_256x128.npy"),
)];

/// The [`DEFAULT_MAPS`], decoded, as `(name, map)`.
///
/// ```
/// let maps = haarshift::sphere::map_error::default_maps::<f32>().unwrap();
/// assert_eq!(maps[0].0, "rooitou_park_256x128");
/// assert_eq!((maps[0].1.height(), maps[0].1.width()), (128, 256));
/// ```
pub fn default_maps<T: Sample>() -> Result<Vec<(String, LatLongMap<T>)>> {
    DEFAULT_MAPS
        .iter()
        .map(|&(name, bytes)| {
            let file = format!("{name}.npy");
            let image = crate::io::read_image_from_memory::<T>(
                bytes,
                file.as_ref(),
                &crate::io::ReadOptions::default(),
            )?;
            let map = LatLongMap::from_image(&image).map_err(|e| e.in_file(file.as_ref()))?;
            Ok((name.to_owned(), map))
        })
        .collect()
}

/// The solid-angle weighted RMS difference of two maps of the same shape.
///
/// ```
/// use haarshift::sphere::{LatLongMap, map_error::weighted_rms};
/// let a = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap();
/// let b = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 3.0).unwrap();
/// assert!((weighted_rms(&a, &b).unwrap() - 2.0).abs() < 1e-12);
/// ```
pub fn weighted_rms<T: Sample>(a: &LatLongMap<T>, b: &LatLongMap<T>) -> Result<f64> {
    let (x, y) = (a.as_array(), b.as_array());
    if x.dim() != y.dim() {
        let (h, w, c) = y.dim();
        return Err(Error::shape(
            &[h, w, c],
            "maps to compare must have the same shape",
        ));
    }
    let (h, _, c) = x.dim();
    let mut total = 0.0;
    for i in 0..h {
        let (p, q) = (x.index_axis(Axis(0), i), y.index_axis(Axis(0), i));
        let row: f64 = p
            .iter()
            .zip(q.iter())
            .map(|(p, q)| (p.as_f64() - q.as_f64()).powi(2))
            .sum();
        total += pixel_solid_angle(h, i) * row;
    }
    Ok((total / (4.0 * std::f64::consts::PI * c as f64)).sqrt())
}

/// The plain RMS difference of two coefficient pyramids of the same shape.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereCoefficients, map_error::coefficient_rms};
/// let a = LatLongMap::<f64>::from_fn(4, 1, |d, o| o[0] = d[0]).unwrap();
/// let c = SphereCoefficients::from_map(&a).unwrap();
/// assert_eq!(coefficient_rms(&c, &c).unwrap(), 0.0);
/// ```
pub fn coefficient_rms<T: Sample>(
    a: &SphereCoefficients<T>,
    b: &SphereCoefficients<T>,
) -> Result<f64> {
    let (x, y) = (a.as_array(), b.as_array());
    if x.dim() != y.dim() {
        let (c, h, w) = y.dim();
        return Err(Error::shape(
            &[c, h, w],
            "pyramids to compare must have the same shape",
        ));
    }
    let sum: f64 = x
        .iter()
        .zip(y.iter())
        .map(|(p, q)| (p.as_f64() - q.as_f64()).powi(2))
        .sum();
    Ok((sum / x.len() as f64).sqrt())
}

/// `(E(a) - E(b)) / E(b)`, `E` the solid-angle integral summed over channels.
///
/// ```
/// use haarshift::sphere::{LatLongMap, map_error::relative_energy_error};
/// let a = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.1).unwrap();
/// let b = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap();
/// assert!((relative_energy_error(&a, &b) - 0.1).abs() < 1e-12);
/// ```
pub fn relative_energy_error<T: Sample>(a: &LatLongMap<T>, b: &LatLongMap<T>) -> f64 {
    let ea: f64 = a.energy().iter().sum();
    let eb: f64 = b.energy().iter().sum();
    (ea - eb) / eb
}

/// How a rotated map compares with the reference rotation of the same map.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// [`weighted_rms`] of the pixels against the full-resolution reference.
    pub rms: f64,
    /// `rms` divided by the reference's own weighted RMS (its distance from zero).
    pub relative_rms: f64,
    /// [`weighted_rms`] against the reference reduced to the computed level (both sides'
    /// coefficients of levels `0..=level` only): the method's own error, without the detail
    /// it did not compute.
    pub rms_at_level: f64,
    /// [`coefficient_rms`] against the reference.
    pub coefficient_rms: f64,
    /// [`relative_energy_error`] against the *original* map (rotation preserves energy).
    pub energy_error: f64,
}

impl Comparison {
    /// Compares `result` (computed down to detail `level`) with `reference` (full
    /// resolution), both rotations of `original`.
    ///
    /// ```
    /// use haarshift::sphere::*;
    /// use haarshift::sphere::map_error::Comparison;
    /// let f = LatLongMap::<f64>::from_fn(16, 1, |d, o| o[0] = 2.0 + d[0]).unwrap();
    /// let r = SphereRotation::from_degrees(0.0, 30.0, 0.0).unwrap();
    /// let truth = rotate_map(&f, &r, &SphereOptions { method: Method::Reference, ..Default::default() }).unwrap();
    /// let cmp = Comparison::new(&truth, &truth, 3, &f).unwrap();
    /// assert_eq!(cmp.rms, 0.0);
    /// assert!(cmp.energy_error.abs() < 1e-3);
    /// ```
    pub fn new<T: Sample>(
        result: &Rotated<T>,
        reference: &Rotated<T>,
        level: usize,
        original: &LatLongMap<T>,
    ) -> Result<Self> {
        let rms = weighted_rms(&result.map, &reference.map)?;
        let zero = LatLongMap::new(reference.map.as_array().mapv(|_| T::zero()))?;
        let scale = weighted_rms(&reference.map, &zero)?;
        let reduced = |c: &SphereCoefficients<T>| c.truncated(level)?.to_map();
        Ok(Comparison {
            rms,
            relative_rms: if scale > 0.0 { rms / scale } else { 0.0 },
            rms_at_level: weighted_rms(
                &reduced(&result.coefficients)?,
                &reduced(&reference.coefficients)?,
            )?,
            coefficient_rms: coefficient_rms(&result.coefficients, &reference.coefficients)?,
            energy_error: relative_energy_error(&result.map, original),
        })
    }
}

/// One row of a method comparison: a map, a rotation, a method at a level, its errors
/// against the reference and its time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Record {
    /// Name of the map.
    pub map: String,
    /// The method.
    pub method: Method,
    /// Yaw, degrees.
    pub yaw: f64,
    /// Pitch, degrees.
    pub pitch: f64,
    /// Roll, degrees.
    pub roll: f64,
    /// The finest detail level computed (bands `2^level x 2^(level+1)`).
    pub level: usize,
    /// The same level in the thesis's numbering, where level `l` is a face `2^l` texels wide:
    /// `level + 1`.
    pub thesis_level: usize,
    /// The errors (see [`Comparison`]).
    #[serde(flatten)]
    pub comparison: Comparison,
    /// Wall-clock seconds of the [`rotate_map`] call.
    pub seconds: f64,
}

/// Rotates `map` by each `(yaw, pitch, roll)` with each `(method, level)` and compares with
/// the full-resolution [`Method::Reference`] (`reference_samples` per axis), which is also
/// reported (its own errors are zero, its energy error is its quadrature's).
///
/// ```
/// use haarshift::sphere::{LatLongMap, Method, map_error::run};
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, o| o[0] = 1.0 + d[0]).unwrap();
/// let rows = run("smooth", &f, &[(0.0, 30.0, 0.0)], &[(Method::Haar, None), (Method::Bilinear, Some(2))], 4).unwrap();
/// assert_eq!(rows.len(), 3);
/// assert_eq!((rows[2].method, rows[2].level, rows[2].thesis_level), (Method::Bilinear, 2, 3));
/// assert!(rows[1].comparison.rms < 0.05);
/// ```
pub fn run<T: Sample>(
    name: &str,
    map: &LatLongMap<T>,
    rotations: &[(f64, f64, f64)],
    methods: &[(Method, Option<usize>)],
    reference_samples: usize,
) -> Result<Vec<Record>> {
    let finest = map.height().trailing_zeros().saturating_sub(1) as usize;
    let mut records = Vec::new();
    for &(yaw, pitch, roll) in rotations {
        let rotation = SphereRotation::from_degrees(yaw, pitch, roll)?;
        let timed = |method: Method, level: Option<usize>| {
            let options = SphereOptions {
                method,
                level,
                reference_samples,
            };
            let start = Instant::now();
            let rotated = rotate_map(map, &rotation, &options)?;
            Ok::<_, Error>((rotated, start.elapsed().as_secs_f64()))
        };
        let (truth, seconds) = timed(Method::Reference, None)?;
        let record = |method, level, comparison, seconds| Record {
            map: name.to_string(),
            method,
            yaw,
            pitch,
            roll,
            level,
            thesis_level: level + 1,
            comparison,
            seconds,
        };
        let own = Comparison::new(&truth, &truth, finest, map)?;
        records.push(record(Method::Reference, finest, own, seconds));
        for &(method, level) in methods {
            let (rotated, seconds) = timed(method, level)?;
            let level = level.unwrap_or(finest);
            let comparison = Comparison::new(&rotated, &truth, level, map)?;
            records.push(record(method, level, comparison, seconds));
        }
    }
    Ok(records)
}
