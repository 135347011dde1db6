//! One sample per target pixel: what renderers do today. Each pixel of `g` looks up `f` at
//! the pre-image `R p` of its centre, with a bilinear or bicubic (Catmull-Rom) kernel that is
//! continued over the seam and the poles ([`LatLongMap`]).

use super::latlong::{angles, direction, fill_pixels, pixel_centre};
use super::{LatLongMap, SphereRotation};
use crate::named::named_enum;
use crate::{Result, Sample};

named_enum! {
    /// The lookup kernel of a single-sample resampling.
    pub enum Interpolation ("interpolation") {
        /// The four nearest pixel centres.
        Bilinear = "bilinear",
        /// Catmull-Rom over the 4 x 4 nearest centres (may overshoot next to a peak).
        Bicubic = "bicubic",
    }
}

/// `g(p) = f(R p)` sampled once at every pixel centre of a map the size of `map`.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, resample::{Interpolation, resample}};
/// // f = x; a 90 degree yaw sends +Z to +X, so g = f(R p) = z at the horizon.
/// let f = LatLongMap::<f64>::from_fn(32, 1, |d, out| out[0] = d[0]).unwrap();
/// let r = SphereRotation::from_degrees(90.0, 0.0, 0.0).unwrap();
/// let g = resample(&f, &r, Interpolation::Bicubic).unwrap();
/// let want = LatLongMap::<f64>::from_fn(32, 1, |d, out| out[0] = d[2]).unwrap();
/// let err = (&g.as_array() - &want.as_array()).mapv(f64::abs).fold(0.0, |a: f64, &b| a.max(b));
/// assert!(err < 1e-3);
/// ```
pub fn resample<T: Sample>(
    map: &LatLongMap<T>,
    rotation: &SphereRotation,
    kernel: Interpolation,
) -> Result<LatLongMap<T>> {
    let h = map.height();
    let data = fill_pixels(h, map.channels(), |i, j, out| {
        let (t, p) = pixel_centre(h, i, j);
        let (theta, phi) = angles(rotation.apply(direction(t, p)));
        match kernel {
            Interpolation::Bilinear => map.bilinear(theta, phi, out),
            Interpolation::Bicubic => map.bicubic(theta, phi, out),
        }
    })?;
    LatLongMap::new(data)
}
