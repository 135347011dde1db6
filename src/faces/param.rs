//! The two ways haarshift cuts the sphere into square faces, and functions stored that way.
//!
//! A [`Parameterization`] is a set of `F` square faces of `S x S` texels, each texel with a
//! centre direction and an exact solid angle:
//!
//! | [`ParamKind`] | faces | texel `(face, row, col)` | solid angle |
//! |---|---|---|---|
//! | [`ParamKind::LatLong`] | 2 of `H x H` | lat-long pixel `(row, face H + col)` of the `H x 2H` map: face 0 is `phi in [0, pi)`, face 1 `[pi, 2 pi)` ([`latlong`](crate::sphere::latlong)) | `(2 pi / W)(cos theta_row - cos theta_row+1)` |
//! | [`ParamKind::Cube`] | 6 of `S x S` | texel `(row, col)` of cube face `face` ([`cube`]) | the spherical quadrilateral's, exact |
//!
//! The lat-long faces are the halves of the map, the same two square pyramids that
//! [`SphereCoefficients`](crate::sphere::SphereCoefficients) holds side by side. A [`SphereMap`]
//! stores a function as one `(faces, S, S, C)` array: the face array of the product module
//! (`crate::product`). Its integral over the sphere is the sum over texels of value x solid
//! angle ([`SphereMap::energy`]); [`Parameterization::solid_angles`] is that per-texel weight
//! array, to be folded into exactly one factor of a product integral.

use ndarray::{Array3, Array4, ArrayView4};

use super::cube;
use crate::named::named_enum;
use crate::sphere::LatLongMap;
use crate::sphere::latlong::{angles, direction, fill_grid, pixel_centre, pixel_solid_angle};
use crate::{Channels, Error, PlanarImage, Result, Sample, SampleDepth, ensure_finite};

named_enum! {
    /// Which parameterisation: the user-facing choice (`--param`).
    #[derive(Default)]
    pub enum ParamKind ("param") {
        #[default]
        /// Lat-long: two `H x H` faces, the halves of an `H x 2H` map.
        LatLong = "latlong",
        /// The cube map: six `S x S` faces.
        Cube = "cube",
    }
}

/// The largest face side accepted (`2^15`: a cube map of `6 x 2^30` texels).
const MAX_FACE_SIZE: usize = 1 << 15;

/// A parameterisation of the sphere by square faces: its kind and face side `S` (a power of
/// two; for lat-long `S = H`, the map's height).
///
/// ```
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// let p = Parameterization::new(ParamKind::Cube, 16).unwrap();
/// assert_eq!((p.faces(), p.face_size(), p.texels()), (6, 16, 1536));
/// let total: f64 = p.solid_angles().sum();
/// assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12);
/// let twelve = Parameterization::new(ParamKind::LatLong, 12); // not a power of two
/// assert!(matches!(twelve, Err(haarshift::Error::InvalidParameter { name: "resolution", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Parameterization {
    kind: ParamKind,
    size: usize,
}

impl Parameterization {
    /// `kind` with faces of `size x size` texels (`size` a power of two, at most `2^15`).
    pub fn new(kind: ParamKind, size: usize) -> Result<Self> {
        if !size.is_power_of_two() || size > MAX_FACE_SIZE {
            return Err(Error::parameter(
                "resolution",
                format!(
                    "{size}: a face side must be a power of two from 1 to {MAX_FACE_SIZE} \
                     (the Haar pyramid of a face needs it)"
                ),
            ));
        }
        Ok(Parameterization { kind, size })
    }

    /// Which parameterisation.
    pub fn kind(&self) -> ParamKind {
        self.kind
    }

    /// Faces: 2 (lat-long) or 6 (cube).
    pub fn faces(&self) -> usize {
        match self.kind {
            ParamKind::LatLong => 2,
            ParamKind::Cube => 6,
        }
    }

    /// The face side `S`.
    pub fn face_size(&self) -> usize {
        self.size
    }

    /// Texels in all: `faces x S^2`.
    pub fn texels(&self) -> usize {
        self.faces() * self.size * self.size
    }

    /// The centre direction of texel `(face, row, col)`.
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// let p = Parameterization::new(ParamKind::LatLong, 4).unwrap();
    /// // face 1, column 0 is lat-long column 4: phi just past pi, towards -Z
    /// let d = p.texel_direction(1, 2, 0);
    /// assert!(d[2] < -0.8 && d[0] < 0.0);
    /// ```
    pub fn texel_direction(&self, face: usize, row: usize, col: usize) -> [f64; 3] {
        match self.kind {
            ParamKind::LatLong => {
                let (theta, phi) = pixel_centre(self.size, row, face * self.size + col);
                direction(theta, phi)
            }
            ParamKind::Cube => cube::texel_direction(self.size, face, row, col),
        }
    }

    /// The exact solid angle of texel `(face, row, col)` (the same on every face).
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// let p = Parameterization::new(ParamKind::LatLong, 8).unwrap();
    /// let step = std::f64::consts::PI / 8.0;
    /// let want = step * (1.0 - step.cos()); // (2 pi / W)(cos 0 - cos step)
    /// assert!((p.texel_solid_angle(1, 0, 5) - want).abs() < 1e-16);
    /// ```
    pub fn texel_solid_angle(&self, _face: usize, row: usize, col: usize) -> f64 {
        match self.kind {
            ParamKind::LatLong => pixel_solid_angle(self.size, row),
            ParamKind::Cube => cube::texel_solid_angle(self.size, row, col),
        }
    }

    /// The texel `(face, row, col)` that the direction `d` (unit length) falls in.
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// for kind in [ParamKind::LatLong, ParamKind::Cube] {
    ///     let p = Parameterization::new(kind, 8).unwrap();
    ///     assert_eq!(p.texel_of(p.texel_direction(1, 3, 6)), (1, 3, 6));
    /// }
    /// ```
    pub fn texel_of(&self, d: [f64; 3]) -> (usize, usize, usize) {
        match self.kind {
            ParamKind::LatLong => {
                let (theta, phi) = angles(d);
                let step = std::f64::consts::PI / self.size as f64;
                let row = ((theta / step) as usize).min(self.size - 1);
                let col = ((phi / step) as usize).min(2 * self.size - 1);
                (col / self.size, row, col % self.size)
            }
            ParamKind::Cube => cube::texel_of(self.size, d),
        }
    }

    /// The direction of the point at row `row`, column `col` of face `face`, both in texel
    /// units of the face's parameter plane (`(theta, phi)` for lat-long, the face plane for the
    /// cube): texel `(r, c)` spans `[r, r + 1] x [c, c + 1]`.
    #[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
    pub fn point(&self, face: usize, row: f64, col: f64) -> [f64; 3] {
        let s = self.size;
        match self.kind {
            ParamKind::LatLong => {
                let step = std::f64::consts::PI / s as f64;
                direction(row * step, ((face * s) as f64 + col) * step)
            }
            ParamKind::Cube => cube::face_direction(face, cube::edge(s, col), cube::edge(s, row)),
        }
    }

    /// The exact solid angle of the rectangle `rows x cols` (texel units, as in
    /// [`point`](Self::point)) of a face: rectangles that tile a texel add up to its solid
    /// angle.
    pub(crate) fn cell_solid_angle(&self, (r0, r1): (f64, f64), (c0, c1): (f64, f64)) -> f64 {
        let s = self.size;
        match self.kind {
            ParamKind::LatLong => {
                let step = std::f64::consts::PI / s as f64;
                ((r0 * step).cos() - (r1 * step).cos()) * (c1 - c0) * step
            }
            ParamKind::Cube => cube::rectangle_solid_angle(
                cube::edge(s, c0),
                cube::edge(s, c1),
                cube::edge(s, r0),
                cube::edge(s, r1),
            ),
        }
    }

    /// The per-texel weight array: every texel's exact solid angle, `(faces, S, S)`. It sums
    /// to `4 pi` to rounding.
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// let w = Parameterization::new(ParamKind::LatLong, 4).unwrap().solid_angles();
    /// assert_eq!(w.dim(), (2, 4, 4));
    /// assert!((w.sum() - 4.0 * std::f64::consts::PI).abs() < 1e-13);
    /// ```
    pub fn solid_angles(&self) -> Array3<f64> {
        let s = self.size;
        Array3::from_shape_fn((self.faces(), s, s), |(f, r, c)| {
            self.texel_solid_angle(f, r, c)
        })
    }
}

/// A function on the sphere stored in a [`Parameterization`]: a `(faces, S, S, C)` array,
/// texel `(face, row, col)` as the parameterisation places it, `C` channels per texel.
///
/// ```
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// let p = Parameterization::new(ParamKind::Cube, 8).unwrap();
/// let m = SphereMap::<f64>::from_fn(p, 1, |d, out| out[0] = d[1] * d[1]).unwrap();
/// // the integral of y^2 over the sphere is 4 pi / 3
/// assert!((m.energy()[0] - 4.0 * std::f64::consts::PI / 3.0).abs() < 0.01);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SphereMap<T> {
    param: Parameterization,
    data: Array4<T>,
}

impl<T: Sample> SphereMap<T> {
    /// Wraps a `(faces, S, S, C)` array laid out as `param` says (1 to 64 channels, finite
    /// values).
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// use ndarray::Array4;
    /// let p = Parameterization::new(ParamKind::Cube, 2).unwrap();
    /// assert!(SphereMap::new(p, Array4::<f32>::zeros((6, 2, 2, 3))).is_ok());
    /// let two_faces = SphereMap::new(p, Array4::<f32>::zeros((2, 2, 2, 3)));
    /// assert!(matches!(two_faces, Err(haarshift::Error::InvalidShape { .. })));
    /// ```
    pub fn new(param: Parameterization, data: Array4<T>) -> Result<Self> {
        let (f, s, s2, c) = data.dim();
        if f != param.faces() || s != param.face_size() || s2 != s || c == 0 || c > 64 {
            return Err(Error::shape(
                &[f, s, s2, c],
                format!(
                    "a {} map of face side {} is ({}, {2}, {2}, 1 to 64 channels)",
                    param.kind(),
                    param.face_size(),
                    param.faces()
                ),
            ));
        }
        ensure_finite(&data)?;
        Ok(SphereMap {
            param,
            data: data.as_standard_layout().into_owned(),
        })
    }

    /// Samples `f(direction, channels_out)` at every texel centre.
    pub fn from_fn(
        param: Parameterization,
        channels: usize,
        f: impl Fn([f64; 3], &mut [T]) + Sync,
    ) -> Result<Self> {
        SphereMap::from_texels(param, channels, |t, out| {
            f(param.texel_direction(t.0, t.1, t.2), out)
        })
    }

    /// Fills texel `(face, row, col)` with `f((face, row, col), channels_out)`, in parallel.
    pub(crate) fn from_texels(
        param: Parameterization,
        channels: usize,
        f: impl Fn((usize, usize, usize), &mut [T]) + Sync,
    ) -> Result<Self> {
        let s = param.face_size();
        if channels == 0 || channels > 64 {
            return Err(Error::parameter(
                "channels",
                format!("{channels} (expected 1 to 64)"),
            ));
        }
        let rows = fill_grid((param.faces() * s, s, channels), |i, j, out| {
            f((i / s, i % s, j), out)
        });
        let data = rows
            .into_shape_with_order((param.faces(), s, s, channels))
            .expect("rows of faces are faces");
        SphereMap::new(param, data)
    }

    /// A lat-long map as its two faces (an exact reshuffle; the height must be a power of two).
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// use haarshift::faces::param::SphereMap;
    /// let m = LatLongMap::<f64>::from_fn(4, 2, |d, out| out.copy_from_slice(&d[..2])).unwrap();
    /// let s = SphereMap::from_lat_long(&m).unwrap();
    /// assert_eq!(s.as_array()[[1, 2, 3, 1]], m.as_array()[[2, 7, 1]]);
    /// assert_eq!(s.to_lat_long().unwrap(), m);
    /// ```
    pub fn from_lat_long(map: &LatLongMap<T>) -> Result<Self> {
        let (h, w, c) = map.as_array().dim();
        let param = Parameterization::new(ParamKind::LatLong, h)?;
        let faces = map
            .as_array()
            .into_shape_with_order((h, 2, h, c))
            .expect("standard layout")
            .permuted_axes([1, 0, 2, 3]);
        debug_assert_eq!(w, 2 * h);
        SphereMap::new(param, faces.to_owned())
    }

    /// The lat-long map whose halves these faces are (only for [`ParamKind::LatLong`]).
    pub fn to_lat_long(&self) -> Result<LatLongMap<T>> {
        if self.param.kind() != ParamKind::LatLong {
            return Err(Error::parameter(
                "param",
                format!("a {} map is not a lat-long map", self.param.kind()),
            ));
        }
        let (_, s, _, c) = self.data.dim();
        let hwc = self.data.view().permuted_axes([1, 0, 2, 3]);
        let data = hwc
            .as_standard_layout()
            .into_owned()
            .into_shape_with_order((s, 2 * s, c))
            .expect("standard layout");
        LatLongMap::new(data)
    }

    /// The map as one image with samples of `depth` (values not rescaled; 1 to 4 channels):
    /// lat-long faces side by side (the `H x 2H` map itself), cube faces stacked from the top
    /// in face order `+X, -X, +Y, -Y, +Z, -Z` (an `S` wide, `6 S` high strip).
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// use haarshift::SampleDepth;
    /// let p = Parameterization::new(ParamKind::Cube, 4).unwrap();
    /// let data = ndarray::Array4::from_shape_fn((6, 4, 4, 1), |(f, r, c, _)| (100 * f + 10 * r + c) as f32);
    /// let m = SphereMap::new(p, data).unwrap();
    /// let image = m.to_image(SampleDepth::F32).unwrap();
    /// assert_eq!((image.width(), image.height()), (4, 24));
    /// assert_eq!(image.planes()[[0, 4 * 5 + 2, 3]], 523.0); // face 5, row 2, column 3
    /// ```
    pub fn to_image(&self, depth: SampleDepth) -> Result<PlanarImage<T>> {
        let (f, s, _, c) = self.data.dim();
        let (planes, h, w) = match self.param.kind() {
            // (C, row, face, col): each row runs through the faces side by side.
            ParamKind::LatLong => (self.data.view().permuted_axes([3, 1, 0, 2]), s, f * s),
            ParamKind::Cube => (self.data.view().permuted_axes([3, 0, 1, 2]), f * s, s),
        };
        let planes = planes
            .as_standard_layout()
            .into_owned()
            .into_shape_with_order((c, h, w))
            .expect("standard layout");
        PlanarImage::new(planes, Channels::from_count(c)?, depth)
    }

    /// The parameterisation.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// Channels per texel.
    pub fn channels(&self) -> usize {
        self.data.dim().3
    }

    /// The `(faces, S, S, C)` face array.
    pub fn as_array(&self) -> ArrayView4<'_, T> {
        self.data.view()
    }

    /// The `(faces, S, S, C)` face array, owned.
    pub fn into_array(self) -> Array4<T> {
        self.data
    }

    /// The error of this map against `reference` on the sphere: the solid-angle weighted RMS
    /// difference over the reference's weighted RMS, every channel alike,
    /// `sqrt(sum w (a - b)^2 / sum w b^2)`. The measure of a map, where
    /// [`relative_rms_error`](crate::metrics::relative_rms_error) is that of an image or of
    /// per-vertex radiance.
    ///
    /// ```
    /// use haarshift::faces::{ParamKind, Parameterization, SphereMap};
    /// let param = Parameterization::new(ParamKind::Cube, 4).unwrap();
    /// let one = SphereMap::<f64>::from_fn(param, 1, |_, o| o[0] = 1.0).unwrap();
    /// let brighter = SphereMap::<f64>::from_fn(param, 1, |_, o| o[0] = 1.25).unwrap();
    /// assert!((brighter.relative_rms_error(&one).unwrap() - 0.25).abs() < 1e-15);
    /// let black = SphereMap::<f64>::from_fn(param, 1, |_, o| o[0] = 0.0).unwrap();
    /// assert!(one.relative_rms_error(&black).is_err()); // no scale to be relative to
    /// ```
    ///
    /// An error when the two differ in parameterisation or channels, or the reference is 0
    /// everywhere.
    pub fn relative_rms_error(&self, reference: &SphereMap<T>) -> Result<f64> {
        if self.param != reference.param || self.channels() != reference.channels() {
            return Err(Error::shape(
                &[reference.param.texels(), reference.channels()],
                format!(
                    "the map compared has {} texels of {} channels",
                    self.param.texels(),
                    self.channels()
                ),
            ));
        }
        let weights = self.param.solid_angles();
        let weights = weights.as_slice().expect("fresh array is contiguous");
        let c = self.channels();
        let (mut difference, mut scale) = (0.0, 0.0);
        let pairs = self.data.iter().zip(reference.data.iter());
        for (k, (&a, &b)) in pairs.enumerate() {
            let (a, b) = (a.as_f64(), b.as_f64());
            let w = weights[k / c];
            difference += w * (a - b) * (a - b);
            scale += w * b * b;
        }
        if scale == 0.0 {
            return Err(Error::parameter(
                "reference",
                "is 0 everywhere: no scale to be relative to",
            ));
        }
        Ok((difference / scale).sqrt())
    }

    /// The integral over the sphere of each channel: `sum over texels of value x solid angle`.
    ///
    /// ```
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// let p = Parameterization::new(ParamKind::Cube, 4).unwrap();
    /// let one = SphereMap::<f32>::from_fn(p, 1, |_, out| out[0] = 1.0).unwrap();
    /// assert!((one.energy()[0] - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn energy(&self) -> Vec<f64> {
        let weights = self.param.solid_angles();
        let c = self.channels();
        let mut total = vec![0.0; c];
        let flat = self.data.as_slice().expect("standard layout");
        for (texel, &w) in flat.chunks_exact(c).zip(weights.iter()) {
            for (t, &v) in total.iter_mut().zip(texel) {
                *t += w * v.as_f64();
            }
        }
        total
    }
}

#[cfg(test)]
#[path = "param_tests.rs"]
mod tests;
