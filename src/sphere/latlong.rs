//! [`LatLongMap`]: a spherical function stored as a latitude-longitude (equirectangular) map,
//! with the geometry of its pixels and continuous lookups across the seam and the poles.
//!
//! # Conventions (Alnasser 2008's section 4.5.1)
//!
//! Row `i` is the elevation `theta` measured from +Y (up), column `j` the azimuth `phi`;
//! pixel `(i, j)` of an `H x W` map has its centre at
//! `theta = (i + 0.5) pi / H`, `phi = (j + 0.5) 2 pi / W`, and the direction of `(theta, phi)`
//! is `(sin theta sin phi, cos theta, sin theta cos phi)` (right-handed, Y up, Z the depth).
//! Maps are 2:1 (`W = 2 H`), so a pixel spans the same angle `pi / H` along both axes.
//!
//! # Continuing the map past its edges
//!
//! * The seam: `phi` is periodic, column `-1` is column `W - 1`.
//! * The poles: the point `(-theta, phi)` is the point `(theta, phi + pi)`, so row `-1 - r`
//!   is row `r` half a turn away (column `j + W / 2`), and likewise past the south pole. A
//!   lookup near a pole therefore interpolates between pixels on both sides of the pole, which
//!   is what they are on the sphere. (Tangent-vector components flip sign there; see
//!   [`chain_rule`](super::chain_rule).)

use ndarray::{Array3, ArrayView3, Axis, s};
use rayon::prelude::*;

use crate::{Channels, Error, PlanarImage, Result, Sample, SampleDepth, ensure_finite};

/// The unit direction of elevation `theta` (from +Y) and azimuth `phi`.
///
/// ```
/// use haarshift::sphere::latlong::direction;
/// let d = direction(std::f64::consts::FRAC_PI_2, 0.0);
/// assert!((d[2] - 1.0).abs() < 1e-15 && d[0].abs() < 1e-15); // the horizon at phi = 0 is +Z
/// ```
#[inline]
pub fn direction(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * sp, ct, st * cp]
}

/// The angles `(theta, phi)` of a unit direction, `theta` in `[0, pi]`, `phi` in `[0, 2 pi)`.
///
/// The azimuth is `atan2(x, z)`: Alnasser 2008's (4.13) prints `tan^-1(x / z)`, which loses the
/// quadrant. The elevation is `atan2(sqrt(x^2 + z^2), y)`, which is `acos y` for a unit
/// direction and stays accurate next to the poles; both come from [`atan2`].
///
/// ```
/// use haarshift::sphere::latlong::{angles, direction};
/// let (t, p) = angles(direction(1.0, 5.0));
/// assert!((t - 1.0).abs() < 1e-12 && (p - 5.0).abs() < 1e-12);
/// ```
#[inline]
pub fn angles(d: [f64; 3]) -> (f64, f64) {
    (
        atan2((d[0] * d[0] + d[2] * d[2]).sqrt(), d[1]),
        azimuth(d[0], d[2]),
    )
}

/// The azimuth `atan2(x, z)` of a direction with components `x` and `z`, in `[0, 2 pi)`.
#[inline]
pub(crate) fn azimuth(x: f64, z: f64) -> f64 {
    let phi = atan2(x, z);
    let phi = if phi < 0.0 {
        phi + std::f64::consts::TAU
    } else {
        phi
    };
    // A tiny negative angle plus TAU can round to exactly TAU.
    if phi >= std::f64::consts::TAU {
        0.0
    } else {
        phi
    }
}

/// `atan2(y, x)` in `[-pi, pi]`, within 9e-16 (two ulp of pi) of the C library's, by octant
/// reduction to `[0, 1]`, one more reduction to `[0, tan(pi / 12)]` (`atan t = pi / 6 +
/// atan((sqrt 3 t - 1) / (sqrt 3 + t))`) and a degree-15 odd polynomial there (a Chebyshev fit
/// of `atan(t) / t` in `t^2`): several times faster than the C library's, which matters where
/// every pixel of a rotation asks for two angles. The diagonals (`|y| = |x|`) are exact;
/// signed zeros and infinities follow
/// `f64::atan2` (`atan2(0, -1) = pi`, `atan2(-0, -1) = -pi`); NaN in, NaN out.
///
/// ```
/// use haarshift::sphere::latlong::atan2;
/// for (y, x) in [(1.0, 2.0), (-3.0, -0.5), (0.0, -1.0), (1e-300, 1.0), (5.0, 0.0)] {
///     assert!((atan2(y, x) - f64::atan2(y, x)).abs() < 1e-15);
/// }
/// ```
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    let den = y.abs().max(x.abs());
    if den > 0.0 && den.is_finite() {
        atan2_finite(y, x)
    } else {
        // Zeros, infinities and NaN: rare, and the C library's conventions.
        y.atan2(x)
    }
}

/// [`atan2`] for finite `(y, x)` not both zero, branch-free (selects only), so that loops
/// over many angles vectorise. In `f32` (the chain rule's geometry for `f32` maps) the same
/// polynomial is evaluated in `f32`: within a few ulp of `f32`.
#[inline(always)]
pub(crate) fn atan2_finite<F: Sample>(y: F, x: F) -> F {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, FRAC_PI_6, PI};
    const SQRT_3: f64 = 1.732_050_807_568_877_2;
    const TAN_PI_12: f64 = 0.267_949_192_431_122_7;
    // atan(t) / t as a polynomial in t^2 on [0, tan^2(pi / 12)], max error 3e-16.
    const C: [f64; 8] = [
        0.999_999_999_999_999_2,
        -0.333_333_333_331_666_65,
        0.199_999_999_498_046_73,
        -0.142_857_085_979_423_93,
        0.111_107_952_311_751_93,
        -0.090_813_549_009_494_98,
        0.075_307_565_684_610_06,
        -0.052_086_075_603_399_89,
    ];
    let k = F::from_f64;
    let c = C.map(k);
    let (ay, ax) = (y.abs(), x.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    // One division, of the reduced or the plain quotient (a vector of angles pays for each
    // division every lane takes).
    let reduce = num > k(TAN_PI_12) * den;
    let (top, bottom) = if reduce {
        (k(SQRT_3) * num - den, k(SQRT_3) * den + num)
    } else {
        (num, den)
    };
    // The diagonals exactly, as the C library rounds them: they are texel edges.
    let diagonal = num == den;
    let t = if diagonal { F::zero() } else { top / bottom };
    let base = if diagonal {
        k(FRAC_PI_4)
    } else if reduce {
        k(FRAC_PI_6)
    } else {
        F::zero()
    };
    // Estrin's scheme: three levels of dependent products instead of seven. In f32 the two
    // highest terms (below 3e-9 on the reduced range, a fifth of an ulp) are left out.
    let u = t * t;
    let (u2, u4) = (u * u, u * u * u * u);
    let high = if std::mem::size_of::<F>() == 4 {
        c[4] + c[5] * u
    } else {
        c[4] + c[5] * u + u2 * (c[6] + c[7] * u)
    };
    let poly = (c[0] + c[1] * u + u2 * (c[2] + c[3] * u)) + u4 * high;
    let a = base + t * poly;
    let a = if swap { k(FRAC_PI_2) - a } else { a };
    let a = if x.is_sign_negative() { k(PI) - a } else { a };
    if y.is_sign_negative() { -a } else { a }
}

/// Catmull-Rom weights (Keys' cubic with `a = -1/2`) of the four samples around `t` in `[0, 1)`.
#[inline]
pub(crate) fn catmull_rom(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// Where sample `(r, c)` of an `h x w` lat-long grid lives when `r` or `c` is out of range:
/// the index inside the grid and whether the pole was crossed (tangent components flip).
#[inline]
pub(crate) fn continue_index(r: isize, c: isize, h: usize, w: usize) -> (usize, usize, bool) {
    let (hi, wi) = (h as isize, w as isize);
    let (r, c, crossed) = if r < 0 {
        (-1 - r, c + wi / 2, true)
    } else if r >= hi {
        (2 * hi - 1 - r, c + wi / 2, true)
    } else {
        (r, c, false)
    };
    (
        r.clamp(0, hi - 1) as usize,
        c.rem_euclid(wi) as usize,
        crossed,
    )
}

/// Channel `k` of four taps (offsets into `flat`) times their weights, summed in their order
/// from zero.
#[inline]
fn weighted<T: Sample>(flat: &[T], taps: &[usize; 4], weights: &[T; 4], k: usize) -> T {
    let mut sum = T::zero();
    for (&tap, &weight) in taps.iter().zip(weights) {
        sum += weight * flat[tap + k];
    }
    sum
}

/// `v.floor()` for a grid coordinate (`|v| < 2^63`; NaN gives 0, whose difference with `v`
/// is NaN as `floor`'s is): without SSE4.1 in the baseline x86-64 target, `f64::floor` is a
/// call into libm, which a bilinear lookup made twice per pixel.
#[inline]
fn floor(v: f64) -> f64 {
    let t = v as i64 as f64;
    if t > v { t - 1.0 } else { t }
}

/// A lat-long map: `H` rows of elevation by `W = 2 H` columns of azimuth by `C` channels.
///
/// ```
/// use haarshift::sphere::LatLongMap;
/// let map = LatLongMap::<f64>::from_fn(4, 1, |d, out| out[0] = d[1]).unwrap(); // f = y
/// assert_eq!((map.height(), map.width(), map.channels()), (4, 8, 1));
/// let mut v = [0.0];
/// map.bilinear(0.5 * std::f64::consts::PI, 1.0, &mut v); // on the horizon
/// assert!(v[0].abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LatLongMap<T> {
    data: Array3<T>,
}

impl<T: Sample> LatLongMap<T> {
    /// Wraps an `(H, W, C)` array: `W = 2 H`, `H >= 1`, `C >= 1`, finite values.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// use ndarray::Array3;
    /// assert!(LatLongMap::new(Array3::<f32>::zeros((4, 8, 3))).is_ok());
    /// let square = LatLongMap::new(Array3::<f32>::zeros((4, 4, 3)));
    /// assert!(matches!(square, Err(haarshift::Error::InvalidShape { .. })));
    /// ```
    pub fn new(data: Array3<T>) -> Result<Self> {
        let (h, w, c) = data.dim();
        if h == 0 || c == 0 || w != 2 * h {
            return Err(Error::shape(
                &[h, w, c],
                "a lat-long map is (H, W = 2 H, channels) with H and channels at least 1",
            ));
        }
        ensure_finite(&data)?;
        let data = if data.is_standard_layout() {
            data
        } else {
            data.as_standard_layout().into_owned()
        };
        Ok(LatLongMap { data })
    }

    /// Samples `f(direction, channels_out)` at every pixel centre of an `h x 2h` map.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// let m = LatLongMap::<f64>::from_fn(2, 2, |d, out| { out[0] = d[0]; out[1] = 1.0 }).unwrap();
    /// assert_eq!(m.as_array()[[0, 0, 1]], 1.0);
    /// ```
    pub fn from_fn(
        h: usize,
        channels: usize,
        f: impl Fn([f64; 3], &mut [T]) + Sync,
    ) -> Result<Self> {
        let data = fill_pixels(h, channels, |i, j, px| {
            let (t, p) = pixel_centre(h, i, j);
            f(direction(t, p), px)
        })?;
        LatLongMap::new(data)
    }

    /// The solid-angle mean of `f(direction, channels_out)` over every pixel of an `h x 2h`
    /// map, by an `n x n` grid of stratum midpoints (`n = samples`, 1 to 64), each weighted
    /// by its own `sin theta`: the midpoint rule, `O(1 / n^2)` per pixel for a smooth `f`,
    /// deterministic.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// // The mean of y over the top row's ring is close to, but below, y at its centre.
    /// let mean = LatLongMap::<f64>::from_fn_mean(4, 1, 16, |d, out| out[0] = d[1]).unwrap();
    /// let (t0, t1) = (0.0f64, std::f64::consts::PI / 4.0);
    /// let exact = (t1.sin().powi(2) - t0.sin().powi(2)) / 2.0 / (t0.cos() - t1.cos());
    /// assert!((mean.as_array()[[0, 0, 0]] - exact).abs() < 1e-3);
    /// assert!(LatLongMap::<f64>::from_fn_mean(4, 1, 0, |_, _| ()).is_err());
    /// ```
    pub fn from_fn_mean(
        h: usize,
        channels: usize,
        samples: usize,
        f: impl Fn([f64; 3], &mut [T]) + Sync,
    ) -> Result<Self> {
        if !(1..=64).contains(&samples) {
            return Err(Error::parameter(
                "samples",
                format!("{samples} samples per axis (expected 1 to 64)"),
            ));
        }
        let step = std::f64::consts::PI / h as f64;
        let sub = step / samples as f64;
        // The midpoints' sines and cosines, once per row and per column of midpoints (the
        // values direction() would compute at each sample, so the means are the same).
        check_size(h, channels)?;
        let table = |pixels: usize| -> Vec<(f64, f64)> {
            (0..pixels * samples)
                .map(|m| {
                    let (pixel, k) = (m / samples, m % samples);
                    (pixel as f64 * step + (k as f64 + 0.5) * sub).sin_cos()
                })
                .collect()
        };
        let (rows, columns) = (table(h), table(2 * h));
        let data = fill_pixels(h, channels, |i, j, out| {
            let mut acc = [0.0f64; 64];
            let acc = &mut acc[..channels];
            let mut value = [T::zero(); 64];
            let value = &mut value[..channels];
            let mut total_weight = 0.0;
            for &(weight, ct) in &rows[i * samples..][..samples] {
                total_weight += weight * samples as f64;
                for &(sp, cp) in &columns[j * samples..][..samples] {
                    f([weight * sp, ct, weight * cp], value);
                    for (s, v) in acc.iter_mut().zip(value.iter()) {
                        *s += weight * v.as_f64();
                    }
                }
            }
            for (o, s) in out.iter_mut().zip(acc.iter()) {
                *o = T::from_f64(s / total_weight);
            }
        })?;
        LatLongMap::new(data)
    }

    /// Rows (`H`).
    pub fn height(&self) -> usize {
        self.data.dim().0
    }

    /// Columns (`W = 2 H`).
    pub fn width(&self) -> usize {
        self.data.dim().1
    }

    /// Channels per pixel.
    pub fn channels(&self) -> usize {
        self.data.dim().2
    }

    /// The `(H, W, C)` array.
    pub fn as_array(&self) -> ArrayView3<'_, T> {
        self.data.view()
    }

    /// The `(H, W, C)` array, owned.
    pub fn into_array(self) -> Array3<T> {
        self.data
    }

    /// The map held by an image read from a file (channels become the map's channels, in
    /// order); the image must be 2:1 (width twice the height).
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// use haarshift::{Channels, PlanarImage, SampleDepth};
    /// use ndarray::Array3;
    /// let planes = Array3::from_shape_fn((3, 2, 4), |(c, i, j)| (100 * c + 10 * i + j) as f32);
    /// let image = PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32).unwrap();
    /// let map = LatLongMap::from_image(&image).unwrap();
    /// assert_eq!(map.as_array()[[1, 3, 2]], 213.0);
    /// assert_eq!(map.to_image(SampleDepth::F32).unwrap(), image);
    /// ```
    pub fn from_image(image: &PlanarImage<T>) -> Result<Self> {
        let (h, w) = (image.height(), image.width());
        if w != 2 * h {
            return Err(Error::shape(
                &[h, w],
                format!(
                    "a lat-long map must be twice as wide as it is high, but this image is \
                     {w} x {h} (width x height)"
                ),
            ));
        }
        let hwc = image.planes().permuted_axes([1, 2, 0]);
        LatLongMap::new(hwc.as_standard_layout().into_owned())
    }

    /// The map as an image with samples of `depth` (the depth to report and store; values
    /// are not rescaled): 1 to 4 channels become gray, gray + alpha, RGB or RGBA.
    pub fn to_image(&self, depth: SampleDepth) -> Result<PlanarImage<T>> {
        let channels = Channels::from_count(self.channels())?;
        let planes = self.data.view().permuted_axes([2, 0, 1]);
        PlanarImage::new(planes.as_standard_layout().into_owned(), channels, depth)
    }

    /// The channels of pixel `(r, c)` after continuing `r` over the poles and `c` around the
    /// seam (see the [module docs](self)).
    #[inline]
    fn pixel(&self, r: isize, c: isize) -> &[T] {
        let flat = self.data.as_slice().expect("standard layout");
        &flat[self.offset(r, c, 0)..][..self.channels()]
    }

    /// Where pixel `(r, c)` starts in the flat data, after continuing `r` over the poles and
    /// `c` around the seam, in the map with its columns rolled by `roll` (`< W`, as
    /// [`roll_columns`](Self::roll_columns) rolls them: its column `c` is this map's
    /// `c + roll`).
    #[inline]
    fn offset(&self, r: isize, c: isize, roll: usize) -> usize {
        let (h, w, ch) = self.data.dim();
        // Inside the map (nearly every lookup) the index is itself: no division.
        let (r, c) = if (0..h as isize).contains(&r) && (0..w as isize).contains(&c) {
            (r as usize, c as usize)
        } else {
            let (r, c, _) = continue_index(r, c, h, w);
            (r, c)
        };
        let c = c + roll;
        let c = if c >= w { c - w } else { c };
        (r * w + c) * ch
    }

    /// Bilinear lookup at `(theta, phi)` into `out` (one value per channel), between the four
    /// nearest pixel centres, continued over the seam and the poles.
    pub fn bilinear(&self, theta: f64, phi: f64, out: &mut [T]) {
        let (y, x) = self.grid_position(theta, phi);
        let (taps, weights) = self.bilinear_taps(y, x, 0);
        let flat = self.data.as_slice().expect("standard layout");
        // Channels beyond the map's (if `out` has more) stay zero.
        out.fill(T::zero());
        for (k, o) in out.iter_mut().take(self.channels()).enumerate() {
            *o = weighted(flat, &taps, &weights, k);
        }
    }

    /// [`bilinear`](Self::bilinear) of the first `N` channels (at most the map's) at the
    /// continuous grid position `(y, x)` of [`grid_position`](Self::grid_position), in the map
    /// with its columns rolled by `roll` (`< W`): the values of `self.roll_columns(roll)`
    /// without the copy.
    #[inline]
    #[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
    pub fn bilinear_grid<const N: usize>(&self, y: f64, x: f64, roll: usize) -> [T; N] {
        let (taps, weights) = self.bilinear_taps(y, x, roll);
        let flat = self.data.as_slice().expect("standard layout");
        let mut out = [T::zero(); N];
        for (k, o) in out.iter_mut().enumerate() {
            *o = weighted(flat, &taps, &weights, k);
        }
        out
    }

    /// The four pixel centres around the grid position `(y, x)` (their offsets in the flat
    /// data, continued and rolled as [`offset`](Self::offset) does; the upper row first, each
    /// row left to right) and their bilinear weights.
    #[inline]
    fn bilinear_taps(&self, y: f64, x: f64, roll: usize) -> ([usize; 4], [T; 4]) {
        let (r0, c0) = (floor(y), floor(x));
        let (fy, fx) = (y - r0, x - c0);
        let (r0, c0) = (r0 as isize, c0 as isize);
        let taps = [
            self.offset(r0, c0, roll),
            self.offset(r0, c0 + 1, roll),
            self.offset(r0 + 1, c0, roll),
            self.offset(r0 + 1, c0 + 1, roll),
        ];
        let (gy, gx) = (1.0 - fy, 1.0 - fx);
        let weights = [
            T::from_f64(gy * gx),
            T::from_f64(gy * fx),
            T::from_f64(fy * gx),
            T::from_f64(fy * fx),
        ];
        (taps, weights)
    }

    /// Bicubic (Catmull-Rom) lookup at `(theta, phi)` over the 4 x 4 nearest pixel centres,
    /// continued over the seam and the poles. Like every interpolating cubic it can overshoot
    /// next to a sharp peak (and go negative).
    pub fn bicubic(&self, theta: f64, phi: f64, out: &mut [T]) {
        let (y, x) = self.grid_position(theta, phi);
        let (r0, c0) = (y.floor(), x.floor());
        let (wy, wx) = (catmull_rom(y - r0), catmull_rom(x - c0));
        let (r0, c0) = (r0 as isize - 1, c0 as isize - 1);
        out.fill(T::zero());
        for (dr, &wr) in wy.iter().enumerate() {
            for (dc, &wc) in wx.iter().enumerate() {
                let weight = T::from_f64(wr * wc);
                let px = self.pixel(r0 + dr as isize, c0 + dc as isize);
                for (o, &v) in out.iter_mut().zip(px) {
                    *o += weight * v;
                }
            }
        }
    }

    /// Continuous pixel coordinates `(row, column)` of `(theta, phi)`: pixel centres sit at
    /// whole numbers.
    #[inline]
    #[doc(hidden)] // For haarshift-relight : public only for the sibling crates (crate docs).
    pub fn grid_position(&self, theta: f64, phi: f64) -> (f64, f64) {
        let h = self.height() as f64;
        let step = std::f64::consts::PI / h;
        (theta / step - 0.5, phi / step - 0.5)
    }

    /// The solid-angle integral of each channel, `sum_ij f_ij * solid_angle(i)`: the energy a
    /// rotation preserves.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// let one = LatLongMap::<f64>::from_fn(8, 1, |_, out| out[0] = 1.0).unwrap();
    /// assert!((one.energy()[0] - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    /// ```
    pub fn energy(&self) -> Vec<f64> {
        let (h, _, ch) = self.data.dim();
        let mut total = vec![0.0; ch];
        for (i, row) in self.data.axis_iter(Axis(0)).enumerate() {
            let weight = pixel_solid_angle(h, i);
            for px in row.as_slice().expect("standard layout").chunks_exact(ch) {
                for (t, &v) in total.iter_mut().zip(px) {
                    *t += weight * v.as_f64();
                }
            }
        }
        total
    }

    /// The map box-filtered by `factor x factor` (a power of two dividing `H`): each output
    /// pixel is the mean of its block, which is exactly the approximation a Haar pyramid
    /// holds at that resolution.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// let m = LatLongMap::<f64>::from_fn(4, 1, |d, out| out[0] = d[0]).unwrap();
    /// let small = m.downsample(2).unwrap();
    /// assert_eq!((small.height(), small.width()), (2, 4));
    /// let block: f64 = m.as_array().slice(ndarray::s![0..2, 0..2, 0]).sum() / 4.0;
    /// assert!((small.as_array()[[0, 0, 0]] - block).abs() < 1e-15);
    /// ```
    pub fn downsample(&self, factor: usize) -> Result<Self> {
        let (h, w, ch) = self.data.dim();
        if factor == 0 || !factor.is_power_of_two() || !h.is_multiple_of(factor) {
            return Err(Error::parameter(
                "factor",
                format!("{factor} is not a power of two dividing the height {h}"),
            ));
        }
        if factor == 1 {
            return Ok(self.clone());
        }
        let (sh, sw) = (h / factor, w / factor);
        let scale = T::from_f64(1.0 / (factor * factor) as f64);
        let src = self.data.as_slice().expect("standard layout");
        let mut out = Array3::zeros((sh, sw, ch));
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .for_each(|(i, mut row)| {
                let row = row.as_slice_mut().expect("standard layout");
                for r in i * factor..(i + 1) * factor {
                    let line = &src[r * w * ch..][..w * ch];
                    for (jj, px) in line.chunks_exact(ch).enumerate() {
                        let acc = &mut row[(jj / factor) * ch..][..ch];
                        for (a, &v) in acc.iter_mut().zip(px) {
                            *a += v;
                        }
                    }
                }
                row.iter_mut().for_each(|v| *v *= scale);
            });
        Ok(LatLongMap { data: out })
    }

    /// The map turned about +Y by `k` whole columns (`k * 360 / W` degrees of yaw): pixel
    /// `(i, j)` of the result is pixel `(i, j + k)` of `self`, an exact permutation.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// let m = LatLongMap::<f64>::from_fn(2, 1, |d, out| out[0] = d[0] + 2.0 * d[2]).unwrap();
    /// let r = m.roll_columns(3);
    /// assert_eq!(r.as_array()[[1, 0, 0]], m.as_array()[[1, 3, 0]]);
    /// ```
    pub fn roll_columns(&self, k: usize) -> Self {
        let w = self.width();
        let k = k % w;
        let mut data = Array3::zeros(self.data.dim());
        data.slice_mut(s![.., ..w - k, ..])
            .assign(&self.data.slice(s![.., k.., ..]));
        data.slice_mut(s![.., w - k.., ..])
            .assign(&self.data.slice(s![.., ..k, ..]));
        LatLongMap { data }
    }

    /// The pixel with the largest channel sum and its `(row, column)`.
    ///
    /// ```
    /// use haarshift::sphere::LatLongMap;
    /// let m = LatLongMap::<f64>::from_fn(4, 1, |d, out| out[0] = d[1]).unwrap();
    /// assert_eq!(m.brightest().0, 0); // the top row is nearest +Y
    /// ```
    pub fn brightest(&self) -> (usize, usize) {
        let ch = self.channels();
        let w = self.width();
        let flat = self.data.as_slice().expect("standard layout");
        let (best, _) = flat
            .chunks_exact(ch)
            .map(|px| px.iter().map(|v| v.as_f64()).sum::<f64>())
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |acc, (k, v)| {
                    if v > acc.1 { (k, v) } else { acc }
                },
            );
        (best / w, best % w)
    }
}

/// An `(h, 2h, channels)` array whose pixel `(i, j)` is written by `f(i, j, channels_out)`
/// ([`fill_grid`]).
pub(crate) fn fill_pixels<T: Sample>(
    h: usize,
    channels: usize,
    f: impl Fn(usize, usize, &mut [T]) + Sync,
) -> Result<Array3<T>> {
    check_size(h, channels)?;
    Ok(fill_grid((h, 2 * h, channels), f))
}

/// Grids of at most this many values (a one-channel 64 x 128 map) are filled on the calling
/// thread: at that size rayon's task overhead is a large part of the work, and a caller that
/// rotates many small maps (a BRDF per vertex) already runs in parallel over them. Every
/// sphere rotation of such a map ([`rotate_map`](super::rotate_map),
/// [`rotate_coefficients`](super::rotate_coefficients), every method) therefore runs
/// sequentially and never touches the rayon pool; larger grids split their rows across it.
///
/// ```
/// assert_eq!(haarshift::sphere::latlong::SEQUENTIAL_MAX_VALUES, 64 * 128);
/// ```
pub const SEQUENTIAL_MAX_VALUES: usize = 64 * 128;

/// `f(i, row)` for every row `i` of `row_len` values of `data`: on the calling thread for at
/// most [`SEQUENTIAL_MAX_VALUES`] values, otherwise rows in parallel.
pub(crate) fn for_each_row<T: Send>(
    data: &mut [T],
    row_len: usize,
    f: impl Fn(usize, &mut [T]) + Sync,
) {
    if data.len() <= SEQUENTIAL_MAX_VALUES {
        data.chunks_mut(row_len)
            .enumerate()
            .for_each(|(i, row)| f(i, row));
    } else {
        data.par_chunks_mut(row_len)
            .enumerate()
            .for_each(|(i, row)| f(i, row));
    }
}

/// A `(rows, cols, channels)` array whose entry `(i, j, ..)` is written by
/// `f(i, j, channels_out)`, rows in parallel above [`SEQUENTIAL_MAX_VALUES`].
pub(crate) fn fill_grid<T: Sample>(
    shape: (usize, usize, usize),
    f: impl Fn(usize, usize, &mut [T]) + Sync,
) -> Array3<T> {
    rows_from_fn(shape, |i, row| {
        for (j, px) in row.chunks_exact_mut(shape.2).enumerate() {
            f(i, j, px);
        }
    })
}

/// A `(rows, cols, channels)` array whose row `i` (`cols x channels` values, entry
/// `j channels + k`) is written by `f(i, row)`, rows in parallel above
/// [`SEQUENTIAL_MAX_VALUES`].
pub(crate) fn rows_from_fn<T: Sample>(
    shape: (usize, usize, usize),
    f: impl Fn(usize, &mut [T]) + Sync,
) -> Array3<T> {
    let mut data = Array3::zeros(shape);
    let len = shape.1 * shape.2;
    if len > 0 {
        for_each_row(data.as_slice_mut().expect("standard layout"), len, f);
    }
    data
}

/// Checks the height and channel count of a map to be made.
pub(crate) fn check_size(h: usize, channels: usize) -> Result<()> {
    if h == 0 || channels == 0 || h > 1 << 20 || channels > 64 {
        return Err(Error::shape(
            &[h, 2 * h, channels],
            "lat-long maps need 1 to 2^20 rows and 1 to 64 channels",
        ));
    }
    Ok(())
}

/// The centre `(theta, phi)` of pixel `(i, j)` of an `h x 2h` map.
///
/// ```
/// use haarshift::sphere::latlong::pixel_centre;
/// let (t, p) = pixel_centre(4, 0, 0);
/// assert!((t - std::f64::consts::PI / 8.0).abs() < 1e-15 && (p - t).abs() < 1e-15);
/// ```
#[inline]
pub fn pixel_centre(h: usize, i: usize, j: usize) -> (f64, f64) {
    let step = std::f64::consts::PI / h as f64;
    ((i as f64 + 0.5) * step, (j as f64 + 0.5) * step)
}

/// The solid angle of one pixel of row `i` of an `h x 2h` map:
/// `(cos theta_top - cos theta_bottom) * 2 pi / W`. The rows' pixels sum to `4 pi`.
///
/// ```
/// use haarshift::sphere::latlong::pixel_solid_angle;
/// let total: f64 = (0..16).map(|i| 32.0 * pixel_solid_angle(16, i)).sum();
/// assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12);
/// ```
#[inline]
pub fn pixel_solid_angle(h: usize, i: usize) -> f64 {
    let step = std::f64::consts::PI / h as f64;
    ((i as f64 * step).cos() - ((i + 1) as f64 * step).cos()) * step
}
