//! Error measures between a result and its reference: RMS, PSNR and maximum absolute error,
//! optionally over a mask (the rotation experiments measure inside a centred disk so that the
//! corners, which a rotation fills from outside, do not count), and the relighting error
//! relative to the scene's RMS radiance ([`relative_rms_error`]).

use ndarray::{Array2, ArrayView2, Zip};
use serde::{Deserialize, Serialize};

use crate::{Error, Result, Sample};

/// RMS, PSNR and maximum absolute error over the compared samples.
///
/// ```
/// use haarshift::metrics::ErrorStats;
/// use ndarray::array;
/// let s = ErrorStats::between(array![[1.0, 2.0]].view(), array![[1.0, 4.0]].view(), None, 255.0).unwrap();
/// assert_eq!(s.max_error, 2.0);
/// assert!((s.rms - 2f64.sqrt()).abs() < 1e-15);
/// assert!((s.psnr - 20.0 * (255.0 / 2f64.sqrt()).log10()).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Root of the mean squared difference.
    pub rms: f64,
    /// `20 log10(peak / rms)` in dB; infinite when the two agree exactly (serialised as null).
    #[serde(with = "infinite_as_null")]
    pub psnr: f64,
    /// Largest absolute difference.
    pub max_error: f64,
    /// How many samples were compared.
    pub count: usize,
}

impl ErrorStats {
    /// Compares `result` with `reference` where `mask` is true (everywhere without a mask);
    /// `peak` is the signal's full scale for PSNR (255 for 8-bit values).
    pub fn between<T: Sample>(
        result: ArrayView2<'_, T>,
        reference: ArrayView2<'_, T>,
        mask: Option<ArrayView2<'_, bool>>,
        peak: f64,
    ) -> Result<Self> {
        if result.dim() != reference.dim() || mask.is_some_and(|m| m.dim() != result.dim()) {
            return Err(Error::shape(
                &[result.nrows(), result.ncols()],
                "result, reference and mask must have one shape",
            ));
        }
        let (mut sum_sq, mut max_error, mut count) = (0.0f64, 0.0f64, 0usize);
        let mut add = |a: T, b: T| {
            let d = (a.as_f64() - b.as_f64()).abs();
            sum_sq += d * d;
            max_error = max_error.max(d);
            count += 1;
        };
        match mask {
            Some(m) => Zip::from(&result)
                .and(&reference)
                .and(&m)
                .for_each(|&a, &b, &inside| {
                    if inside {
                        add(a, b)
                    }
                }),
            None => Zip::from(&result)
                .and(&reference)
                .for_each(|&a, &b| add(a, b)),
        }
        if count == 0 {
            return Err(Error::parameter("mask", "selects no samples"));
        }
        let rms = (sum_sq / count as f64).sqrt();
        Ok(ErrorStats {
            rms,
            psnr: 20.0 * (peak / rms).log10(),
            max_error,
            count,
        })
    }
}

/// The RMS of `result - reference` over all samples divided by the RMS of `reference`: the
/// relighting error measure (per-vertex radiance `(V, 3)`, all vertices and channels
/// together), relative to the scene's RMS radiance and never per vertex, since a shadowed
/// vertex's radiance is near 0. An error when the shapes differ or the reference is 0
/// everywhere (no scale to be relative to).
///
/// ```
/// use haarshift::metrics::relative_rms_error;
/// use ndarray::array;
/// let reference = array![[3.0, 0.0], [0.0, 4.0]]; // RMS 2.5
/// let result = array![[3.0, 0.5], [0.0, 4.0]]; // RMS difference 0.25
/// assert!((relative_rms_error(result.view(), reference.view()).unwrap() - 0.1).abs() < 1e-15);
/// assert!(relative_rms_error(result.view(), reference.mapv(|_| 0.0).view()).is_err());
/// ```
pub fn relative_rms_error<T: Sample>(
    result: ArrayView2<'_, T>,
    reference: ArrayView2<'_, T>,
) -> Result<f64> {
    Ok(RelativeError::between(result, reference)?.rms_relative)
}

/// The per-vertex radiance error of a relighting method: RMS and largest absolute difference
/// over all vertices and channels, in radiance units and relative to the reference's RMS
/// (the scale of the scene, as [`relative_rms_error`] has it).
///
/// ```
/// use haarshift::metrics::RelativeError;
/// use ndarray::array;
/// let reference = array![[3.0, 0.0], [0.0, 4.0]]; // RMS 2.5
/// let e = RelativeError::between(array![[3.0, 0.5], [0.0, 4.0]].view(), reference.view()).unwrap();
/// assert!((e.rms - 0.25).abs() < 1e-15 && (e.rms_relative - 0.1).abs() < 1e-15);
/// assert!((e.max - 0.5).abs() < 1e-15 && (e.max_relative - 0.2).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RelativeError {
    /// RMS difference, radiance units.
    pub rms: f64,
    /// Largest absolute difference, radiance units.
    pub max: f64,
    /// `rms` over the reference's RMS.
    pub rms_relative: f64,
    /// `max` over the reference's RMS.
    pub max_relative: f64,
}

impl RelativeError {
    /// Compares `result` with `reference` (one shape); an error when the shapes differ or the
    /// reference is 0 everywhere.
    pub fn between<T: Sample>(
        result: ArrayView2<'_, T>,
        reference: ArrayView2<'_, T>,
    ) -> Result<Self> {
        let difference = ErrorStats::between(result, reference, None, 1.0)?;
        let scale = rms(reference);
        if scale == 0.0 {
            return Err(Error::parameter(
                "reference",
                "is 0 everywhere: an error relative to its RMS is undefined",
            ));
        }
        Ok(RelativeError {
            rms: difference.rms,
            max: difference.max_error,
            rms_relative: difference.rms / scale,
            max_relative: difference.max_error / scale,
        })
    }
}

/// The root mean square of every value of `a` (0 when it is empty).
///
/// ```
/// let a = ndarray::array![[3.0, 0.0], [0.0, 4.0]];
/// assert!((haarshift::metrics::rms(a.view()) - 2.5).abs() < 1e-15);
/// ```
pub fn rms<T: Sample>(a: ArrayView2<'_, T>) -> f64 {
    (a.iter().map(|v| v.as_f64() * v.as_f64()).sum::<f64>() / a.len().max(1) as f64).sqrt()
}

/// The pixels whose centres lie within `radius` of the array's centre `((h-1)/2, (w-1)/2)`.
///
/// ```
/// let m = haarshift::metrics::disk_mask(3, 3, 1.0);
/// assert_eq!(m.iter().filter(|&&v| v).count(), 5); // the centre and its 4 neighbours
/// ```
pub fn disk_mask(h: usize, w: usize, radius: f64) -> Array2<bool> {
    let (ci, cj) = ((h as f64 - 1.0) / 2.0, (w as f64 - 1.0) / 2.0);
    Array2::from_shape_fn((h, w), |(i, j)| {
        let (di, dj) = (i as f64 - ci, j as f64 - cj);
        di * di + dj * dj <= radius * radius
    })
}

/// Serialises infinities as JSON `null` (JSON has no infinity) and reads `null` back as +inf.
#[doc(hidden)] // For haarshift-experiments : public only for the sibling crates (crate docs).
pub mod infinite_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}

#[cfg(test)]
#[path = "metrics_tests.rs"]
mod tests;
