//! Haar transforms: 1D, 2D non-separable ("standard pyramid") and separable N-D.
//!
//! Most callers use [`TransformSpec`], which takes an image of any size, pads it to powers of
//! two, runs the chosen layout and remembers what it did in the returned [`Coefficients`], so
//! that [`Coefficients::inverse`] crops back to the input exactly. The modules underneath
//! ([`haar1d`], [`pyramid`], [`separable`]) are the raw transforms on power-of-two arrays, for
//! callers that manage their own buffers.
//!
//! # Normalisations
//!
//! * [`Normalization::Average`], the sources' convention: a parent is the mean of its children and
//!   a detail is `(first - second) / 2` per axis. On a 2x2 block `[[p, q], [r, s]]`:
//!   `A = (p+q+r+s)/4`, `a = (p-q+r-s)/4`, `b = (p+q-r-s)/4`, `c = (p-q-r+s)/4`.
//! * [`Normalization::Orthonormal`]: `1/sqrt(2)` per axis step (so `/2` on a 2x2 block); the
//!   transform is orthogonal and Parseval's identity holds.
//!
//! # Pyramid layout (Mallat, Alnasser 2008's Figure 3.1)
//!
//! For an `H x W` array (powers of two) transformed with `K` levels, the scaling coefficients
//! form the `H0 x W0` block at the top left (`H0 = H >> K`, `W0 = W >> K`); detail level `l`
//! (`l = 0` coarsest) has bands of `(H0 << l) x (W0 << l)` coefficients: `a` (horizontal, left
//! half minus right half of the block) to the right of the level's approximation, `b`
//! (vertical, top minus bottom) below it, `c` (diagonal) diagonally. For a square full
//! transform that is `a` at rows `[0, 2^l)` x cols `[2^l, 2^(l+1))` and so on. A 2:1 image
//! (a lat-long map) transformed to full depth keeps a 1x2 block of scaling coefficients: two
//! square pyramids side by side, with no resampling.

use std::ops::Range;

use ndarray::{Array2, ArrayView2, ArrayViewMut2, s};
use serde::{Deserialize, Serialize};

use crate::named::named_enum;
use crate::{BoundaryMode, Error, Result, Sample, ensure_finite};

pub mod basis;
pub mod haar1d;
mod padding;
pub mod pyramid;
pub mod separable;

pub use padding::pad_to_power_of_two;

named_enum! {
    /// How coefficients are scaled; see the [module docs](self).
    #[derive(Default)]
    pub enum Normalization ("normalisation") {
        #[default]
        /// Parent = mean of children, detail = (first - second) / 2 per axis (the sources').
        Average = "average",
        /// `1/sqrt(2)` per axis step: orthogonal, energy preserving.
        Orthonormal = "orthonormal",
    }
}

impl Normalization {
    /// The factor applied to sums and differences in one forward step along one axis.
    pub fn forward_factor<T: Sample>(self) -> T {
        match self {
            Normalization::Average => T::from_f64(0.5),
            Normalization::Orthonormal => T::from_f64(std::f64::consts::FRAC_1_SQRT_2),
        }
    }

    /// The factor applied in one inverse step along one axis.
    pub fn inverse_factor<T: Sample>(self) -> T {
        match self {
            Normalization::Average => T::one(),
            Normalization::Orthonormal => T::from_f64(std::f64::consts::FRAC_1_SQRT_2),
        }
    }

    /// The factor of one forward 2D (two-axis) step: the square of
    /// [`forward_factor`](Self::forward_factor), written exactly (`(1/sqrt 2)^2` is not `0.5`
    /// in floating point).
    pub fn forward_factor_2d<T: Sample>(self) -> T {
        match self {
            Normalization::Average => T::from_f64(0.25),
            Normalization::Orthonormal => T::from_f64(0.5),
        }
    }

    /// The factor of one inverse 2D step, exactly.
    pub fn inverse_factor_2d<T: Sample>(self) -> T {
        match self {
            Normalization::Average => T::one(),
            Normalization::Orthonormal => T::from_f64(0.5),
        }
    }
}

named_enum! {
    /// How a 2D array is decomposed.
    #[derive(Default)]
    pub enum Layout ("layout") {
        #[default]
        /// Non-separable "standard pyramid": each level splits 2x2 blocks into A, a, b, c.
        Pyramid = "pyramid",
        /// Separable "standard decomposition": a 1D transform along each axis in turn.
        Separable = "separable",
    }
}

/// How many transform steps to take.
///
/// ```
/// use haarshift::transform::Levels;
/// assert_eq!("full".parse::<Levels>().unwrap(), Levels::Full);
/// assert_eq!("3".parse::<Levels>().unwrap(), Levels::Count(3));
/// assert_eq!(Levels::Count(3).resolve(9).unwrap(), 3);
/// let too_many = Levels::Count(10).resolve(9).unwrap_err();
/// assert_eq!(too_many.to_string(), "invalid levels: 10 levels requested but this size allows at most 9");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Levels {
    /// As many as the array allows.
    #[default]
    Full,
    /// Exactly this many (a partial transform when fewer than full).
    Count(usize),
}

impl Levels {
    /// The number of steps for an array that allows at most `max`.
    pub fn resolve(self, max: usize) -> Result<usize> {
        match self {
            Levels::Full => Ok(max),
            Levels::Count(k) if k <= max => Ok(k),
            Levels::Count(k) => Err(Error::parameter(
                "levels",
                format!("{k} levels requested but this size allows at most {max}"),
            )),
        }
    }
}

impl std::str::FromStr for Levels {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        if s == "full" {
            return Ok(Levels::Full);
        }
        s.parse::<usize>().map(Levels::Count).map_err(|_| {
            Error::parameter(
                "levels",
                format!("{s:?} is neither \"full\" nor a whole number"),
            )
        })
    }
}

impl std::fmt::Display for Levels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Levels::Full => f.write_str("full"),
            Levels::Count(k) => write!(f, "{k}"),
        }
    }
}

/// The four kinds of coefficient of the 2D pyramid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Band {
    /// Block averages (`A`); only stored at the coarsest level.
    Scaling,
    /// `a`: left half minus right half.
    Horizontal,
    /// `b`: top half minus bottom half.
    Vertical,
    /// `c`: the checkerboard difference.
    Diagonal,
}

/// Which 1D band along one axis of a separable transform.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Band1d {
    /// The scaling coefficients (first `n >> levels` entries).
    Scaling,
    /// Detail level `l` (0 coarsest).
    Detail(usize),
}

/// What a forward transform did: everything [`Coefficients::inverse`] needs to undo it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TransformInfo {
    /// Pyramid or separable.
    pub layout: Layout,
    /// Coefficient scaling.
    pub normalization: Normalization,
    /// Steps taken along the rows axis and the columns axis (equal for the pyramid).
    pub levels: [usize; 2],
    /// How the input was padded to powers of two.
    pub padding: BoundaryMode,
    /// Rows and columns of the input before padding.
    pub original_shape: [usize; 2],
}

impl TransformInfo {
    /// Checks that coefficients of `shape` can be what this transform made: power-of-two sides,
    /// the original size padded to them, and levels that fit.
    ///
    /// ```
    /// use haarshift::transform::TransformSpec;
    /// let c = TransformSpec::default().forward(ndarray::Array2::<f64>::zeros((3, 5)).view()).unwrap();
    /// assert!(c.info().check_shape((4, 8)).is_ok());
    /// assert!(c.info().check_shape((8, 8)).is_err());
    /// ```
    pub fn check_shape(&self, shape: (usize, usize)) -> Result<()> {
        let (h, w) = shape;
        let [rows, cols] = self.original_shape;
        let fits = h.is_power_of_two()
            && w.is_power_of_two()
            && rows <= h
            && cols <= w
            && h == rows.max(1).next_power_of_two()
            && w == cols.max(1).next_power_of_two();
        if !fits {
            return Err(Error::shape(
                &[h, w],
                format!("coefficients do not match an original image of {rows}x{cols}"),
            ));
        }
        let max = [h.trailing_zeros() as usize, w.trailing_zeros() as usize];
        let levels_ok = match self.layout {
            Layout::Pyramid => {
                self.levels[0] == self.levels[1] && self.levels[0] <= max[0].min(max[1])
            }
            Layout::Separable => self.levels[0] <= max[0] && self.levels[1] <= max[1],
        };
        if !levels_ok {
            return Err(Error::parameter(
                "levels",
                format!(
                    "{:?} do not fit a {h}x{w} {} transform",
                    self.levels, self.layout
                ),
            ));
        }
        Ok(())
    }
}

/// The image whose coefficients (made as `info` says) are `coefficients`, cropped to
/// `info.original_shape` and written into `out` (of that size, any strides; a contiguous
/// row-major `out` of the coefficients' size is written directly).
///
/// ```
/// use haarshift::transform::{TransformSpec, inverse_into};
/// use ndarray::{Array2, array};
/// let image = array![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
/// let c = TransformSpec::default().forward(image.view()).unwrap();
/// let mut out = Array2::zeros((2, 3));
/// inverse_into(c.as_array(), c.info(), out.view_mut()).unwrap();
/// assert_eq!(out, image);
/// ```
pub fn inverse_into<T: Sample>(
    coefficients: ArrayView2<'_, T>,
    info: &TransformInfo,
    mut out: ArrayViewMut2<'_, T>,
) -> Result<()> {
    info.check_shape(coefficients.dim())?;
    let [rows, cols] = info.original_shape;
    if out.dim() != (rows, cols) {
        return Err(Error::shape(
            &[out.nrows(), out.ncols()],
            format!("the image is {rows}x{cols}"),
        ));
    }
    ensure_finite(&coefficients)?;
    let norm = info.normalization;
    let full = match info.layout {
        Layout::Pyramid if out.dim() == coefficients.dim() && out.is_standard_layout() => {
            return pyramid::inverse_into(coefficients, info.levels[0], norm, out, &mut Vec::new());
        }
        Layout::Pyramid => pyramid::inverse(coefficients, info.levels[0], norm)?,
        Layout::Separable => {
            let mut data = coefficients.to_owned();
            separable::inverse_in_place(data.view_mut(), &info.levels, norm)?;
            data
        }
    };
    out.assign(&full.slice(s![..rows, ..cols]));
    Ok(())
}

/// A recipe for a 2D Haar transform of an image of any size.
///
/// ```
/// use haarshift::transform::{Band, Layout, Levels, Normalization, TransformSpec};
/// use ndarray::array;
/// let image = array![[1.0, 3.0], [5.0, 7.0]];
/// let spec = TransformSpec::default(); // pyramid, average, full depth, zero padding
/// let c = spec.forward(image.view()).unwrap();
/// assert_eq!(c.get(Band::Scaling, 0, 0, 0), Some(4.0)); // the mean
/// assert_eq!(c.get(Band::Horizontal, 0, 0, 0), Some(-1.0)); // (1 - 3 + 5 - 7) / 4
/// assert_eq!(c.inverse().unwrap(), image);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TransformSpec {
    /// Pyramid (non-separable) or separable.
    pub layout: Layout,
    /// Coefficient scaling.
    pub normalization: Normalization,
    /// How many steps.
    pub levels: Levels,
    /// How a non-power-of-two input is extended before the transform.
    pub padding: BoundaryMode,
}

impl TransformSpec {
    /// Transforms `image` (any non-empty size, finite values).
    pub fn forward<T: Sample>(&self, image: ArrayView2<'_, T>) -> Result<Coefficients<T>> {
        let mut data = Array2::zeros(self.padded_shape(image.nrows(), image.ncols())?);
        let info = self.forward_into(image, data.view_mut(), &mut Vec::new())?;
        Ok(Coefficients { data, info })
    }

    /// The size of the coefficients of a `rows x cols` image: each side rounded up to a power of
    /// two. Errors on an empty image, or when the levels asked for do not fit.
    ///
    /// ```
    /// use haarshift::transform::{Levels, TransformSpec};
    /// assert_eq!(TransformSpec::default().padded_shape(3, 5).unwrap(), (4, 8));
    /// let deep = TransformSpec { levels: Levels::Count(3), ..Default::default() };
    /// assert!(deep.padded_shape(4, 8).is_err()); // a 4 x 8 pyramid has 2 levels
    /// ```
    pub fn padded_shape(&self, rows: usize, cols: usize) -> Result<(usize, usize)> {
        let (h, w) = padding::padded_size(rows, cols)?;
        self.resolve_levels(h, w)?;
        Ok((h, w))
    }

    /// [`forward`](Self::forward) into `out`, of [`padded_shape`](Self::padded_shape) and any
    /// strides (a contiguous row-major `out` is written directly, with no intermediate copy),
    /// with `work` as scratch that repeated calls reuse (as [`pyramid::forward_into`]).
    /// Returns what was done, for [`inverse_into`].
    ///
    /// ```
    /// use haarshift::transform::TransformSpec;
    /// use ndarray::{Array2, array};
    /// let spec = TransformSpec::default();
    /// let mut out = Array2::zeros((2, 2));
    /// let image = array![[1.0, 3.0], [5.0, 7.0]];
    /// let info = spec.forward_into(image.view(), out.view_mut(), &mut Vec::new()).unwrap();
    /// assert_eq!(out, array![[4.0, -1.0], [-2.0, 0.0]]);
    /// assert_eq!(info.original_shape, [2, 2]);
    /// ```
    pub fn forward_into<T: Sample>(
        &self,
        image: ArrayView2<'_, T>,
        mut out: ArrayViewMut2<'_, T>,
        work: &mut Vec<T>,
    ) -> Result<TransformInfo> {
        let (rows, cols) = image.dim();
        let (h, w) = self.padded_shape(rows, cols)?;
        if out.dim() != (h, w) {
            return Err(Error::shape(
                &[out.nrows(), out.ncols()],
                format!("the coefficients of a {rows}x{cols} image are {h}x{w}"),
            ));
        }
        let padded = pad_to_power_of_two(image, self.padding)?;
        let levels = self.resolve_levels(h, w)?;
        let norm = self.normalization;
        // The pyramid checks finiteness during its pass; padding puts no NaN or infinity
        // before the first one of the image in row-major order, so its error names the
        // image's index.
        match self.layout {
            Layout::Pyramid if out.is_standard_layout() => {
                pyramid::forward_into(padded.view(), levels[0], norm, out, work)?
            }
            Layout::Pyramid => out.assign(&pyramid::forward(padded.view(), levels[0], norm)?),
            Layout::Separable => {
                ensure_finite(&image)?;
                out.assign(&padded);
                separable::forward_in_place(out, &levels, norm)?;
            }
        }
        Ok(TransformInfo {
            layout: self.layout,
            normalization: self.normalization,
            levels,
            padding: self.padding,
            original_shape: [rows, cols],
        })
    }

    /// What this transform does to an image of `original` size whose coefficients are
    /// `coefficients` in size: the [`TransformInfo`] [`inverse_into`] needs, checked against
    /// both sizes.
    ///
    /// ```
    /// use haarshift::transform::TransformSpec;
    /// let info = TransformSpec::default().info_for((4, 8), (3, 5)).unwrap();
    /// assert_eq!((info.levels, info.original_shape), ([2, 2], [3, 5]));
    /// assert!(TransformSpec::default().info_for((4, 8), (3, 3)).is_err()); // 3 pads to 4
    /// ```
    pub fn info_for(
        &self,
        coefficients: (usize, usize),
        original: (usize, usize),
    ) -> Result<TransformInfo> {
        let (h, w) = coefficients;
        if !(h.is_power_of_two() && w.is_power_of_two()) {
            return Err(Error::shape(
                &[h, w],
                "coefficients have power-of-two sides",
            ));
        }
        let info = TransformInfo {
            layout: self.layout,
            normalization: self.normalization,
            levels: self.resolve_levels(h, w)?,
            padding: self.padding,
            original_shape: [original.0, original.1],
        };
        info.check_shape(coefficients)?;
        Ok(info)
    }

    /// Steps per axis for a padded `h x w` array.
    pub(crate) fn resolve_levels(&self, h: usize, w: usize) -> Result<[usize; 2]> {
        let (dh, dw) = (h.trailing_zeros() as usize, w.trailing_zeros() as usize);
        match self.layout {
            Layout::Pyramid => {
                let k = self.levels.resolve(dh.min(dw))?;
                Ok([k, k])
            }
            Layout::Separable => match self.levels {
                Levels::Full => Ok([dh, dw]),
                Levels::Count(_) => {
                    let k = self.levels.resolve(dh.min(dw))?;
                    Ok([k, k])
                }
            },
        }
    }
}

/// The Haar coefficients of one image plane, with what is needed to invert them.
#[derive(Clone, Debug, PartialEq)]
pub struct Coefficients<T> {
    data: Array2<T>,
    info: TransformInfo,
}

impl<T: Sample> Coefficients<T> {
    /// Wraps a coefficient array (read from a file, say), checking it against `info`.
    pub fn from_parts(data: Array2<T>, info: TransformInfo) -> Result<Self> {
        info.check_shape(data.dim())?;
        ensure_finite(&data)?;
        Ok(Coefficients { data, info })
    }

    /// Wraps an array made by a layout-preserving operation on coefficients described by
    /// `info` (same shape, finite by construction), skipping the checks of `from_parts`.
    pub(crate) fn from_trusted_parts(data: Array2<T>, info: TransformInfo) -> Self {
        Coefficients { data, info }
    }

    /// What the forward transform did.
    pub fn info(&self) -> &TransformInfo {
        &self.info
    }

    /// The whole coefficient array (padded size), in the layout of [`TransformInfo::layout`].
    pub fn as_array(&self) -> ArrayView2<'_, T> {
        self.data.view()
    }

    /// Mutable access to the coefficients (to threshold or edit them before inverting).
    pub fn as_array_mut(&mut self) -> ndarray::ArrayViewMut2<'_, T> {
        self.data.view_mut()
    }

    /// Splits into the array and the info.
    pub fn into_parts(self) -> (Array2<T>, TransformInfo) {
        (self.data, self.info)
    }

    /// The image these coefficients came from, cropped back to its original size.
    pub fn inverse(&self) -> Result<Array2<T>> {
        let [rows, cols] = self.info.original_shape;
        let mut out = Array2::zeros((rows, cols));
        inverse_into(self.data.view(), &self.info, out.view_mut())?;
        Ok(out)
    }

    /// A view of one pyramid band at detail `level` (0 coarsest). [`Band::Scaling`] is stored
    /// at level 0 only.
    ///
    /// ```
    /// use haarshift::transform::{Band, TransformSpec};
    /// use ndarray::Array2;
    /// let image = Array2::from_shape_fn((8, 16), |(i, j)| (i * 16 + j) as f64);
    /// let c = TransformSpec::default().forward(image.view()).unwrap();
    /// assert_eq!(c.band(Band::Scaling, 0).unwrap().dim(), (1, 2)); // 2:1 keeps two roots
    /// assert_eq!(c.band(Band::Diagonal, 2).unwrap().dim(), (4, 8));
    /// ```
    pub fn band(&self, band: Band, level: usize) -> Result<ArrayView2<'_, T>> {
        if self.info.layout != Layout::Pyramid {
            return Err(Error::parameter(
                "band",
                "pyramid bands exist only in the pyramid layout; use separable_band",
            ));
        }
        let (rows, cols) = pyramid::band_ranges(self.data.dim(), self.info.levels[0], band, level)?;
        Ok(self.data.slice(s![rows, cols]))
    }

    /// Coefficient `(i, j)` of a pyramid band, or `None` when out of range.
    pub fn get(&self, band: Band, level: usize, i: usize, j: usize) -> Option<T> {
        self.band(band, level).ok()?.get((i, j)).copied()
    }

    /// A view of one band of a separable transform: `rows` picks the band along axis 0,
    /// `cols` along axis 1.
    ///
    /// ```
    /// use haarshift::transform::{Band1d, Layout, TransformSpec};
    /// use ndarray::Array2;
    /// let spec = TransformSpec { layout: Layout::Separable, ..Default::default() };
    /// let c = spec.forward(Array2::<f64>::ones((4, 8)).view()).unwrap();
    /// let v = c.separable_band(Band1d::Scaling, Band1d::Detail(2)).unwrap();
    /// assert_eq!(v.dim(), (1, 4));
    /// ```
    pub fn separable_band(&self, rows: Band1d, cols: Band1d) -> Result<ArrayView2<'_, T>> {
        if self.info.layout != Layout::Separable {
            return Err(Error::parameter(
                "band",
                "separable bands exist only in the separable layout",
            ));
        }
        let (h, w) = self.data.dim();
        let r = band1d_range(h, self.info.levels[0], rows)?;
        let c = band1d_range(w, self.info.levels[1], cols)?;
        Ok(self.data.slice(s![r, c]))
    }
}

/// Index range of a 1D band in a length-`n` transform with `levels` steps.
fn band1d_range(n: usize, levels: usize, band: Band1d) -> Result<Range<usize>> {
    let n0 = n >> levels;
    match band {
        Band1d::Scaling => Ok(0..n0),
        Band1d::Detail(l) if l < levels => Ok(haar1d::detail_range(n0, l)),
        Band1d::Detail(l) => Err(Error::parameter(
            "level",
            format!("detail level {l} does not exist in a {levels}-level transform"),
        )),
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod pywavelets_tests;
