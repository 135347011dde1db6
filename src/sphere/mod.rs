//! Rotation of spherical functions stored as lat-long maps, in pixels and directly in the 2D
//! Haar domain (Alnasser 2008's chapter 4).
//!
//! One entry point, [`rotate_map`] (or [`rotate_coefficients`] when the map is already a
//! Haar pyramid), computes `g(p) = f(R p)` by a chosen [`Method`]:
//!
//! | method | what it does | cost |
//! |---|---|---|
//! | [`Method::Reference`] | ground truth: each target pixel is the solid-angle mean of `f(R p)` over the pixel, `n x n` stratified samples of the bilinear `f` ([`reference`](mod@reference)) | `n^2` lookups per pixel |
//! | [`Method::Bilinear`], [`Method::Bicubic`] | one lookup per target pixel at `R p` ([`resample`]) | 4 or 16 taps per pixel |
//! | [`Method::Haar`] | the chain rule on the detail coefficients at one level, exact recursive filters for the coarser ones ([`chain_rule`]) | two chain-rule evaluations per pixel of the working level |
//! | [`Method::HaarCubic`] | the same with four-point differences of `f`, Catmull-Rom derivatives at the pre-images, third-order-corrected differences of `g` and a pole-corrected integral for the constant ([`chain_rule::Scheme::Cubic`]): bicubic's accuracy (or better) without leaving the coefficients | the same evaluations, 16 taps each instead of 4, plus the two pole rows |
//!
//! Every method returns pixels and coefficients ([`Rotated`]); the pixel methods transform
//! their result forward, the Haar methods invert their coefficients. Measured on analytic
//! Phong lobes ([`lobes`]): at 64 x 128 `haar` is within 0.9x to 1.4x of `bilinear`'s error,
//! `haar-cubic` within 0.4x to 0.85x of `bicubic`'s (against the lobe at the texel centres;
//! against its texel means, where every method carries the same point-versus-mean
//! difference, 0.96x to 1.02x).
//!
//! **Level.** [`SphereOptions::level`] `= Some(L)` computes detail levels `0..=L` only, on the
//! `2^(L+1) x 2^(L+2)` approximation of `f` (its coefficients of levels `0..=L`); the finer
//! levels of the result are zero. Starting `k` levels below the finest costs `O(N / 4^k)`
//! (Alnasser 2008's section 4.5.3) for every method, so the methods can be compared at equal
//! cost. Individual coefficients: [`chain_rule::rotate_selected`]. The approximation at a
//! coarser level is a plain (not solid-angle weighted) block mean, so it carries its own
//! small energy change (0.1% to 0.6% on the test map for levels 5 to 3 of 6), the same for
//! every method.
//!
//! **Performance.** Everything runs on rayon (rows in parallel) and works in the map's own
//! precision (`f32` or `f64`) with the geometry in `f64`; per-pixel work allocates nothing.
//!
//! **Exact yaw.** When `R` is a yaw about +Y by a whole number of columns (`k * 360 / W`
//! degrees, the identity included), `g` is `f` with its columns turned, and every method
//! returns exactly that ([`yaw`]; the Haar methods shift coefficients).
//!
//! Conventions: [`latlong`] (map geometry, seam and poles), [`rotation`] (yaw, pitch, roll),
//! [`coefficients`] (how a 2:1 map maps onto two square Haar pyramids side by side).
//! Measurements: `experiment`.
//!
//! **Spherical harmonics.** [`harmonics`] (real spherical harmonics: evaluation, projection,
//! reconstruction, the Lambertian convolution) and [`gaunt`] (their triple products). Maps
//! stored as square faces, for product integrals, are [`crate::faces`]'s.

pub mod chain_rule;
pub mod coefficients;
pub mod gaunt;
pub mod harmonics;
pub mod latlong;
pub mod lobes;
pub mod map_error;
pub mod reference;
pub mod resample;
pub mod rotation;
pub mod yaw;

pub use coefficients::SphereCoefficients;
pub use latlong::LatLongMap;
pub use rotation::SphereRotation;

use crate::named::named_enum;
use crate::{Error, Result, Sample};
use resample::Interpolation;

named_enum! {
    /// How [`rotate_map`] computes the rotated map.
    #[derive(Default)]
    pub enum Method ("method") {
        /// Ground truth: per-pixel solid-angle integration ([`reference`](mod@reference)).
        Reference = "reference",
        /// One bilinear lookup per pixel ([`resample`]).
        Bilinear = "bilinear",
        /// One bicubic (Catmull-Rom) lookup per pixel ([`resample`]).
        Bicubic = "bicubic",
        #[default]
        /// The chain rule in the Haar domain ([`chain_rule`]).
        Haar = "haar",
        /// The higher-order chain rule in the Haar domain ([`chain_rule::Scheme::Cubic`]).
        HaarCubic = "haar-cubic",
    }
}

impl Method {
    /// The chain-rule scheme of a Haar-domain method, `None` for a pixel method.
    ///
    /// ```
    /// use haarshift::sphere::{Method, chain_rule::Scheme};
    /// assert_eq!(Method::HaarCubic.scheme(), Some(Scheme::Cubic));
    /// assert_eq!(Method::Bicubic.scheme(), None);
    /// ```
    pub fn scheme(self) -> Option<chain_rule::Scheme> {
        match self {
            Method::Haar => Some(chain_rule::Scheme::Linear),
            Method::HaarCubic => Some(chain_rule::Scheme::Cubic),
            Method::Reference | Method::Bilinear | Method::Bicubic => None,
        }
    }
}

/// What [`rotate_map`] does.
///
/// ```
/// use haarshift::sphere::{Method, SphereOptions};
/// let o = SphereOptions { method: Method::Bicubic, level: Some(4), ..Default::default() };
/// assert_eq!(o.reference_samples, 8);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SphereOptions {
    /// The method.
    pub method: Method,
    /// The finest detail level to compute (`None`: the finest the map has, `log2 H - 1`).
    pub level: Option<usize>,
    /// Samples per axis and pixel of [`Method::Reference`] (1 to 64).
    pub reference_samples: usize,
}

impl Default for SphereOptions {
    fn default() -> Self {
        SphereOptions {
            method: Method::default(),
            level: None,
            reference_samples: 8,
        }
    }
}

/// A rotated map, as pixels and as Haar coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotated<T> {
    /// The pixels (`H x 2H`; blocks of equal pixels above the computed level).
    pub map: LatLongMap<T>,
    /// The full-depth Haar pyramid (levels finer than the computed one are zero).
    pub coefficients: SphereCoefficients<T>,
}

/// `g(p) = f(R p)` by `options.method`, as pixels and coefficients. `map` must be
/// `H x 2H` with `H` a power of two from 2 on.
///
/// ```
/// use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
/// let f = LatLongMap::<f64>::from_fn(32, 3, |d, out| out.fill(1.0 + d[1])).unwrap();
/// let r = SphereRotation::from_degrees(30.0, 20.0, 10.0).unwrap();
/// let truth = rotate_map(&f, &r, &SphereOptions { method: Method::Reference, ..Default::default() }).unwrap();
/// let haar = rotate_map(&f, &r, &SphereOptions::default()).unwrap();
/// let rms = haarshift::sphere::map_error::weighted_rms(&haar.map, &truth.map).unwrap();
/// assert!(rms < 0.01);
/// ```
pub fn rotate_map<T: Sample>(
    map: &LatLongMap<T>,
    rotation: &SphereRotation,
    options: &SphereOptions,
) -> Result<Rotated<T>> {
    let h = map.height();
    let level = resolve_level(h, options.level)?;
    let finest = level + 1 == h.trailing_zeros() as usize;
    if let Some(k) = rotation.whole_column_yaw(map.width()) {
        let pixels = yaw::yaw_pixels(map, k);
        let coefficients = if options.method.scheme().is_some() {
            yaw::yaw_coefficients(&SphereCoefficients::from_map(map)?, k)?
        } else {
            SphereCoefficients::from_map(&pixels)?
        };
        if finest {
            return Ok(Rotated {
                map: pixels,
                coefficients,
            });
        }
        return with_pixels(coefficients.truncated(level)?);
    }
    let source = map.downsample(h >> (level + 1))?;
    if let Some(scheme) = options.method.scheme() {
        let coefficients = chain_rule::rotate(&source, rotation, scheme)?.zero_padded(h)?;
        return with_pixels(coefficients);
    }
    let pixels = rotate_pixels(&source, rotation, options)?;
    let coefficients = SphereCoefficients::from_map(&pixels)?;
    if finest {
        return Ok(Rotated {
            map: pixels,
            coefficients,
        });
    }
    with_pixels(coefficients.zero_padded(h)?)
}

/// `g(p) = f(R p)` from and to Haar coefficients. With `options.level = Some(L)` only `f`'s
/// levels `0..=L` are read and the work is `O(N / 4^k)`; a whole-column yaw whose shift is
/// not a multiple of the level's block width reads them all.
///
/// ```
/// use haarshift::sphere::*;
/// let f = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[0]).unwrap();
/// let c = SphereCoefficients::from_map(&f).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 45.0, 0.0).unwrap();
/// let o = SphereOptions { level: Some(2), ..Default::default() };
/// let g = rotate_coefficients(&c, &r, &o).unwrap();
/// let from_pixels = rotate_map(&f, &r, &o).unwrap().coefficients;
/// let diff = &g.as_array() - &from_pixels.as_array();
/// assert!(diff.iter().all(|v| v.abs() < 1e-13));
/// ```
pub fn rotate_coefficients<T: Sample>(
    coeffs: &SphereCoefficients<T>,
    rotation: &SphereRotation,
    options: &SphereOptions,
) -> Result<SphereCoefficients<T>> {
    let h = coeffs.height();
    let level = resolve_level(h, options.level)?;
    if let Some(k) = rotation.whole_column_yaw(2 * h) {
        return yaw::yaw_coefficients(coeffs, k)?.truncated(level);
    }
    let source = coeffs.approximation(level)?;
    let small = match options.method.scheme() {
        Some(scheme) => chain_rule::rotate(&source, rotation, scheme)?,
        None => SphereCoefficients::from_map(&rotate_pixels(&source, rotation, options)?)?,
    };
    small.zero_padded(h)
}

/// The pixel methods on `source`.
fn rotate_pixels<T: Sample>(
    source: &LatLongMap<T>,
    rotation: &SphereRotation,
    options: &SphereOptions,
) -> Result<LatLongMap<T>> {
    match options.method {
        Method::Reference => reference::reference(source, rotation, options.reference_samples),
        Method::Bilinear => resample::resample(source, rotation, Interpolation::Bilinear),
        Method::Bicubic => resample::resample(source, rotation, Interpolation::Bicubic),
        Method::Haar | Method::HaarCubic => Err(Error::parameter(
            "method",
            format!("{} is not a pixel method", options.method),
        )),
    }
}

/// Pairs coefficients with their pixels.
fn with_pixels<T: Sample>(coefficients: SphereCoefficients<T>) -> Result<Rotated<T>> {
    Ok(Rotated {
        map: coefficients.to_map()?,
        coefficients,
    })
}

/// The finest level to compute for an `h`-row map.
fn resolve_level(h: usize, level: Option<usize>) -> Result<usize> {
    if h < 2 || !h.is_power_of_two() {
        return Err(Error::shape(
            &[h, 2 * h],
            "rotating a lat-long map needs a height that is a power of two from 2 on",
        ));
    }
    let levels = h.trailing_zeros() as usize;
    match level {
        None => Ok(levels - 1),
        Some(l) if l < levels => Ok(l),
        Some(l) => Err(Error::parameter(
            "level",
            format!("{l}: a {h}-row map has detail levels 0..={}", levels - 1),
        )),
    }
}

#[cfg(test)]
mod level_tests;
#[cfg(test)]
mod lobe_tests;
#[cfg(test)]
mod tests;
