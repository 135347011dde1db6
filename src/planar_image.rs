//! [`PlanarImage`]: an image as planar float channels, the form every operation works on.

use ndarray::{Array2, Array3, ArrayView2, ArrayView3, ArrayViewMut2, Axis};

use crate::named::named_enum;
use crate::{Error, Result, Sample};

named_enum! {
    /// Which channels an image has, in plane order.
    pub enum Channels ("channels") {
        /// One plane: luminance.
        Gray = "gray",
        /// Luminance then alpha.
        GrayAlpha = "gray-alpha",
        /// Red, green, blue.
        Rgb = "rgb",
        /// Red, green, blue, alpha.
        Rgba = "rgba",
    }
}

impl Channels {
    /// Number of planes.
    pub fn count(self) -> usize {
        match self {
            Channels::Gray => 1,
            Channels::GrayAlpha => 2,
            Channels::Rgb => 3,
            Channels::Rgba => 4,
        }
    }

    /// Whether the last plane is alpha.
    pub fn has_alpha(self) -> bool {
        matches!(self, Channels::GrayAlpha | Channels::Rgba)
    }

    /// The usual layout for `count` planes (2 and 4 carry alpha).
    pub fn from_count(count: usize) -> Result<Self> {
        match count {
            1 => Ok(Channels::Gray),
            2 => Ok(Channels::GrayAlpha),
            3 => Ok(Channels::Rgb),
            4 => Ok(Channels::Rgba),
            n => Err(Error::parameter(
                "channels",
                format!("{n} channels (expected 1 to 4)"),
            )),
        }
    }
}

named_enum! {
    /// How sample values were stored in the file an image came from; it fixes the value scale
    /// (see [`PlanarImage`]) and what an output file of the same kind will hold.
    pub enum SampleDepth ("sample depth") {
        /// 8-bit integers; values 0..=255.
        U8 = "u8",
        /// 16-bit integers; values 0..=65535.
        U16 = "u16",
        /// Half floats.
        F16 = "f16",
        /// Single floats.
        F32 = "f32",
        /// Double floats (from `.npy`).
        F64 = "f64",
    }
}

impl SampleDepth {
    /// The largest code value of an integer depth, `None` for floats.
    pub fn integer_max(self) -> Option<f64> {
        match self {
            SampleDepth::U8 => Some(255.0),
            SampleDepth::U16 => Some(65535.0),
            _ => None,
        }
    }
}

/// An image stored as planes of float samples: `planes[[c, row, col]]`.
///
/// Values are the stored code values, unscaled: an 8-bit image holds 0..=255, a 16-bit one
/// 0..=65535, a float image its own values. So an integer image converts to float and back
/// exactly, and measurements on 8-bit images are in the familiar 0..255 units. Alpha, when
/// present, is the last plane and uses the same scale (255 is opaque for 8-bit).
///
/// ```
/// use haarshift::{Channels, PlanarImage, SampleDepth};
/// use ndarray::Array3;
/// let img = PlanarImage::new(Array3::<f32>::zeros((4, 2, 3)), Channels::Rgba, SampleDepth::U8).unwrap();
/// assert_eq!((img.height(), img.width()), (2, 3));
/// assert_eq!(img.color_planes().dim(), (3, 2, 3));
/// assert!(img.alpha().is_some());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarImage<T = f32> {
    planes: Array3<T>,
    channels: Channels,
    depth: SampleDepth,
}

impl<T: Sample> PlanarImage<T> {
    /// Wraps `planes` (channels, rows, columns); the plane count must match `channels` and the
    /// image must not be empty.
    pub fn new(planes: Array3<T>, channels: Channels, depth: SampleDepth) -> Result<Self> {
        let (c, h, w) = planes.dim();
        if c != channels.count() {
            return Err(Error::shape(
                &[c, h, w],
                format!("{c} planes for {channels} (needs {})", channels.count()),
            ));
        }
        if h == 0 || w == 0 {
            return Err(Error::shape(&[c, h, w], "image is empty"));
        }
        Ok(PlanarImage {
            planes,
            channels,
            depth,
        })
    }

    /// A one-plane gray image.
    pub fn from_gray(plane: Array2<T>, depth: SampleDepth) -> Result<Self> {
        Self::new(plane.insert_axis(Axis(0)), Channels::Gray, depth)
    }

    /// Rows.
    pub fn height(&self) -> usize {
        self.planes.dim().1
    }

    /// Columns.
    pub fn width(&self) -> usize {
        self.planes.dim().2
    }

    /// Channel layout.
    pub fn channels(&self) -> Channels {
        self.channels
    }

    /// How the samples were stored.
    pub fn depth(&self) -> SampleDepth {
        self.depth
    }

    /// The image relabelled as stored at `depth`, with samples rescaled as a file written at
    /// that depth would hold them: between the integer depths by 257 (8 -> 16) or 1/257
    /// (16 -> 8); nothing else is rescaled (float samples are code values). No rounding: an
    /// operation that ends at an integer depth (such as [`rotate_image`](crate::rotate::rotate_image))
    /// rounds once, at the new depth, so converting before it keeps the finer codes.
    ///
    /// ```
    /// use haarshift::{PlanarImage, SampleDepth};
    /// use ndarray::Array2;
    /// let eight = PlanarImage::from_gray(Array2::from_elem((1, 2), 2.0f32), SampleDepth::U8).unwrap();
    /// let wide = eight.with_depth(SampleDepth::U16);
    /// assert_eq!((wide.depth(), wide.plane(0)[[0, 0]]), (SampleDepth::U16, 514.0));
    /// assert_eq!(wide.with_depth(SampleDepth::F32).plane(0)[[0, 1]], 514.0);
    /// ```
    pub fn with_depth(mut self, depth: SampleDepth) -> Self {
        let scale = depth_scale(self.depth, depth);
        if scale != 1.0 {
            let scale = T::from_f64(scale);
            self.planes.par_mapv_inplace(|v| v * scale);
        }
        self.depth = depth;
        self
    }

    /// All planes, alpha last when present.
    pub fn planes(&self) -> ArrayView3<'_, T> {
        self.planes.view()
    }

    /// Plane `c`.
    pub fn plane(&self, c: usize) -> ArrayView2<'_, T> {
        self.planes.index_axis(Axis(0), c)
    }

    /// Plane `c`, mutable.
    pub fn plane_mut(&mut self, c: usize) -> ArrayViewMut2<'_, T> {
        self.planes.index_axis_mut(Axis(0), c)
    }

    /// The colour planes (all but alpha).
    pub fn color_planes(&self) -> ArrayView3<'_, T> {
        let n = self.channels.count() - usize::from(self.channels.has_alpha());
        self.planes.slice(ndarray::s![..n, .., ..])
    }

    /// The alpha plane, if any.
    pub fn alpha(&self) -> Option<ArrayView2<'_, T>> {
        self.channels
            .has_alpha()
            .then(|| self.plane(self.channels.count() - 1))
    }

    /// Splits into planes, channels and depth.
    pub fn into_parts(self) -> (Array3<T>, Channels, SampleDepth) {
        (self.planes, self.channels, self.depth)
    }

    /// A new image of the same channels and depth from planes computed one by one.
    ///
    /// ```
    /// use haarshift::{PlanarImage, SampleDepth};
    /// use ndarray::Array2;
    /// let img = PlanarImage::from_gray(Array2::<f64>::ones((2, 2)), SampleDepth::F32).unwrap();
    /// let doubled = img.map_planes(|p| Ok(p.mapv(|v| 2.0 * v))).unwrap();
    /// assert_eq!(doubled.plane(0)[[1, 1]], 2.0);
    /// ```
    pub fn map_planes(
        &self,
        mut f: impl FnMut(ArrayView2<'_, T>) -> Result<Array2<T>>,
    ) -> Result<Self> {
        let planes: Vec<Array2<T>> = self
            .planes
            .outer_iter()
            .map(&mut f)
            .collect::<Result<_>>()?;
        let views: Vec<ArrayView2<'_, T>> = planes.iter().map(|p| p.view()).collect();
        let stacked = ndarray::stack(Axis(0), &views)
            .map_err(|e| Error::shape(&[planes.len()], e.to_string()))?;
        Self::new(stacked, self.channels, self.depth)
    }
}

/// The factor a sample of depth `from` is multiplied by when stored at depth `to`: integer
/// depths are rescaled into each other, nothing else is.
pub(crate) fn depth_scale(from: SampleDepth, to: SampleDepth) -> f64 {
    match (from.integer_max(), to.integer_max()) {
        (Some(a), Some(b)) => b / a,
        _ => 1.0,
    }
}
