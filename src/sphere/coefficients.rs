//! [`SphereCoefficients`]: the Haar pyramid of a lat-long map, one plane per channel.
//!
//! # How a 2:1 map maps onto square Haar pyramids
//!
//! An `H x 2H` map (`H` a power of two) is transformed to full depth with the non-separable
//! pyramid of [`transform::pyramid`](crate::transform::pyramid): `log2 H` detail levels
//! (level 0 coarsest) and a 1 x 2 block of scaling coefficients. That is exactly two square
//! pyramids side by side, one per hemisphere `phi in [0, pi)` and `[pi, 2 pi)`, with no
//! resampling: at detail level `l` the bands are `2^l x 2^(l+1)`, and band column `J` belongs
//! to the left pyramid when `J < 2^l`. The two scaling coefficients are the hemispheres' means
//! (in the `(theta, phi)` parameter plane, not weighted by solid angle). Coefficients use the
//! `average` normalisation (a parent is the mean of its children), in which a detail
//! coefficient is a finite difference (Alnasser 2008's section 4.5.2).
//!
//! The approximation at "resolution of level `L + 1`" (the inverse of levels `0..=L` only)
//! is the `2^(L+1) x 2^(L+2)` map of block means; the top-left `2^(L+1) x 2^(L+2)` block of
//! the coefficient array is its full pyramid.

use ndarray::{Array2, Array3, ArrayView2, ArrayView3, Axis, s};
use rayon::prelude::*;

use super::LatLongMap;
use crate::io::CoefficientFile;
use crate::transform::{Band, Coefficients, Layout, Normalization, TransformInfo, pyramid};
use crate::{BoundaryMode, Channels, Error, Result, Sample, SampleDepth, ensure_finite};

/// Full-depth, average-normalised Haar pyramids of a lat-long map: shape `(C, H, 2H)`.
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereCoefficients};
/// use haarshift::transform::Band;
/// let map = LatLongMap::<f64>::from_fn(8, 1, |_, out| out[0] = 3.0).unwrap();
/// let c = SphereCoefficients::from_map(&map).unwrap();
/// assert_eq!(c.levels(), 3);
/// assert_eq!(c.band(0, Band::Scaling, 0).unwrap().dim(), (1, 2));
/// assert_eq!(c.band(0, Band::Scaling, 0).unwrap()[[0, 1]], 3.0);
/// assert_eq!(c.to_map().unwrap(), map);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SphereCoefficients<T> {
    data: Array3<T>,
}

impl<T: Sample> SphereCoefficients<T> {
    /// Wraps a `(C, H, 2H)` coefficient array (`H` a power of two, finite values).
    ///
    /// ```
    /// use haarshift::sphere::SphereCoefficients;
    /// use ndarray::Array3;
    /// assert!(SphereCoefficients::from_array(Array3::<f32>::zeros((3, 4, 8))).is_ok());
    /// let odd = SphereCoefficients::from_array(Array3::<f32>::zeros((3, 3, 6)));
    /// assert!(matches!(odd, Err(haarshift::Error::InvalidShape { .. })));
    /// ```
    pub fn from_array(data: Array3<T>) -> Result<Self> {
        let (c, h, w) = data.dim();
        check_pyramid_shape(h, w, c)?;
        ensure_finite(&data)?;
        let data = if data.is_standard_layout() {
            data
        } else {
            data.as_standard_layout().into_owned()
        };
        Ok(SphereCoefficients { data })
    }

    /// Adds `shift` to channel `channel`'s mean (both scaling coefficients of the 1 x 2
    /// root), every detail kept; refused if the result is not finite.
    pub(crate) fn shift_mean(&mut self, channel: usize, shift: T) -> Result<()> {
        let (a, b) = (
            self.data[[channel, 0, 0]] + shift,
            self.data[[channel, 0, 1]] + shift,
        );
        if !(a.is_finite() && b.is_finite()) {
            return Err(Error::NonFinite {
                value: shift.as_f64(),
                index: vec![channel, 0, 0],
            });
        }
        (self.data[[channel, 0, 0]], self.data[[channel, 0, 1]]) = (a, b);
        Ok(())
    }

    /// Forward transform of every channel of `map` (`H` must be a power of two).
    pub fn from_map(map: &LatLongMap<T>) -> Result<Self> {
        let (h, w, c) = map.as_array().dim();
        check_pyramid_shape(h, w, c)?;
        let levels = h.trailing_zeros() as usize;
        let mut data = Array3::zeros((c, h, w));
        data.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .try_for_each(|(k, out)| {
                let plane = map.as_array().index_axis(Axis(2), k).to_owned();
                pyramid::forward_into(
                    plane.view(),
                    levels,
                    Normalization::Average,
                    out,
                    &mut Vec::new(),
                )
            })?;
        Ok(SphereCoefficients { data })
    }

    /// Inverse transform back to a map.
    pub fn to_map(&self) -> Result<LatLongMap<T>> {
        let (c, h, w) = self.data.dim();
        let levels = self.levels();
        let planes: Vec<Array2<T>> = (0..c)
            .into_par_iter()
            .map(|k| {
                pyramid::inverse(
                    self.data.index_axis(Axis(0), k),
                    levels,
                    Normalization::Average,
                )
            })
            .collect::<Result<_>>()?;
        let mut out = Array3::zeros((h, w, c));
        for (k, plane) in planes.iter().enumerate() {
            out.index_axis_mut(Axis(2), k).assign(plane);
        }
        LatLongMap::new(out)
    }

    /// The `(C, H, 2H)` array.
    pub fn as_array(&self) -> ArrayView3<'_, T> {
        self.data.view()
    }

    /// Channels.
    pub fn channels(&self) -> usize {
        self.data.dim().0
    }

    /// Rows `H` of the map these coefficients describe.
    pub fn height(&self) -> usize {
        self.data.dim().1
    }

    /// Detail levels: `log2 H`.
    pub fn levels(&self) -> usize {
        self.height().trailing_zeros() as usize
    }

    /// One band of one channel (see [`Band`]; [`Band::Scaling`] is the 1 x 2 block at level 0).
    pub fn band(&self, channel: usize, band: Band, level: usize) -> Result<ArrayView2<'_, T>> {
        if channel >= self.channels() {
            return Err(Error::parameter(
                "channel",
                format!("{channel} of {} channels", self.channels()),
            ));
        }
        let plane = self.data.index_axis(Axis(0), channel);
        let (rows, cols) = pyramid::band_ranges(plane.dim(), self.levels(), band, level)?;
        Ok(plane.slice_move(s![rows, cols]))
    }

    /// The coefficients of levels `0..=level` only, in a pyramid of the same height with the
    /// finer levels zero (the map's approximation at resolution `level + 1`).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereCoefficients};
    /// let map = LatLongMap::<f64>::from_fn(8, 1, |d, out| out[0] = d[0]).unwrap();
    /// let c = SphereCoefficients::from_map(&map).unwrap();
    /// let coarse = c.truncated(1).unwrap().to_map().unwrap();
    /// let want = map.downsample(2).unwrap();
    /// assert!((coarse.as_array()[[2, 5, 0]] - want.as_array()[[1, 2, 0]]).abs() < 1e-15);
    /// ```
    pub fn truncated(&self, level: usize) -> Result<Self> {
        let size = self.resolution_of(level)?;
        let mut out = Array3::zeros(self.data.dim());
        out.slice_mut(s![.., ..size, ..2 * size])
            .assign(&self.data.slice(s![.., ..size, ..2 * size]));
        Ok(SphereCoefficients { data: out })
    }

    /// The map's approximation at resolution `level + 1`: a `2^(level+1) x 2^(level+2)` map
    /// of block means, from the coefficients of levels `0..=level` only (cost proportional
    /// to its size, not the full map's).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereCoefficients};
    /// let map = LatLongMap::<f64>::from_fn(8, 2, |d, out| { out[0] = d[1]; out[1] = d[2] }).unwrap();
    /// let c = SphereCoefficients::from_map(&map).unwrap();
    /// let a = c.approximation(0).unwrap();
    /// let b = map.downsample(4).unwrap();
    /// assert!((&a.as_array() - &b.as_array()).iter().all(|v| v.abs() < 1e-15));
    /// ```
    pub fn approximation(&self, level: usize) -> Result<LatLongMap<T>> {
        let size = self.resolution_of(level)?;
        let top = self.data.slice(s![.., ..size, ..2 * size]).to_owned();
        SphereCoefficients { data: top }.to_map()
    }

    /// These coefficients as the top-left corner of a pyramid of height `height` (a power of
    /// two at least [`height`](Self::height)), the finer levels zero.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereCoefficients};
    /// let small = LatLongMap::<f64>::from_fn(2, 1, |d, out| out[0] = d[0]).unwrap();
    /// let c = SphereCoefficients::from_map(&small).unwrap().zero_padded(8).unwrap();
    /// let big = c.to_map().unwrap(); // each small pixel becomes a 4 x 4 block
    /// assert!((big.as_array()[[5, 13, 0]] - small.as_array()[[1, 3, 0]]).abs() < 1e-15);
    /// ```
    pub fn zero_padded(&self, height: usize) -> Result<Self> {
        let (c, h, w) = self.data.dim();
        check_pyramid_shape(height, 2 * height, c)?;
        if height < h {
            return Err(Error::parameter(
                "height",
                format!("{height} is smaller than the coefficients' {h}"),
            ));
        }
        let mut out = Array3::zeros((c, height, 2 * height));
        out.slice_mut(s![.., ..h, ..w]).assign(&self.data);
        Ok(SphereCoefficients { data: out })
    }

    /// The pyramids as a [`CoefficientFile`] (one plane per channel, `depth` recorded as the
    /// map's sample depth), so that they can be written as `.npy` plus sidecar and read back
    /// or inverted like any coefficient file: each plane is exactly what
    /// [`TransformSpec::default()`](crate::transform::TransformSpec) (pyramid layout, average
    /// normalisation, full depth) makes of the `H x 2H` channel, so the file's inverse is
    /// [`to_map`](Self::to_map) as an image.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, SphereCoefficients};
    /// use haarshift::SampleDepth;
    /// let map = LatLongMap::<f64>::from_fn(4, 3, |d, out| out.copy_from_slice(&d)).unwrap();
    /// let c = SphereCoefficients::from_map(&map).unwrap();
    /// let file = c.to_coefficient_file(SampleDepth::F32).unwrap();
    /// assert_eq!(file.metadata().transform.levels, [2, 2]);
    /// let back = file.inverse().unwrap();
    /// let want = map.to_image(SampleDepth::F32).unwrap();
    /// assert!((&back.planes() - &want.planes()).iter().all(|v| v.abs() < 1e-15));
    /// ```
    pub fn to_coefficient_file(&self, depth: SampleDepth) -> Result<CoefficientFile<T>> {
        let (_, h, w) = self.data.dim();
        let info = TransformInfo {
            layout: Layout::Pyramid,
            normalization: Normalization::Average,
            levels: [self.levels(); 2],
            padding: BoundaryMode::Zero,
            original_shape: [h, w],
        };
        let planes = self
            .data
            .outer_iter()
            .map(|plane| Coefficients::from_parts(plane.to_owned(), info))
            .collect::<Result<Vec<_>>>()?;
        CoefficientFile::from_parts(planes, Channels::from_count(self.channels())?, depth)
    }

    /// Rows of the approximation at resolution `level + 1`, after checking the level exists.
    fn resolution_of(&self, level: usize) -> Result<usize> {
        if level >= self.levels() {
            return Err(Error::parameter(
                "level",
                format!(
                    "detail level {level} does not exist: a {}-row map has levels 0..={}",
                    self.height(),
                    self.levels().saturating_sub(1)
                ),
            ));
        }
        Ok(2 << level)
    }
}

/// Checks a `(h, w, channels)` pyramid shape: `w = 2h`, `h` a power of two from 2 on.
fn check_pyramid_shape(h: usize, w: usize, channels: usize) -> Result<()> {
    if h < 2 || !h.is_power_of_two() || w != 2 * h || channels == 0 || channels > 64 {
        return Err(Error::shape(
            &[channels, h, w],
            "lat-long Haar pyramids need H a power of two from 2 on, W = 2 H and 1 to 64 \
             channels",
        ));
    }
    Ok(())
}
