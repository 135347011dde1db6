//! The lighting: a lat-long environment map, loaded from a file, brought to the working
//! resolution by solid-angle-weighted means, rotated, and laid out in the parameterisation
//! the product integrals run in.
//!
//! # Pipeline
//!
//! [`Environment::load`] reads any image or array [`crate::io`] reads (Radiance `.hdr`, run-length
//! encoded or flat, OpenEXR, `.npy`, ...) and checks that it is 2:1; an alpha plane is dropped.
//! [`Environment::lat_long`] then gives the map at `N x 2N`, rotated by `g(p) = f(R p)`
//! ([`SphereRotation`]), and [`Environment::sphere_map`] the same in a [`Parameterization`]
//! (lat-long `N x 2N` faces, or a cube map).
//!
//! # The solid-angle-weighted downsample
//!
//! [`downsample_solid_angle`] gives each target texel the mean of the source over the texel
//! *on the sphere*: `sum_s v_s |s and t| / |t|`, where `|.|` is solid angle. The overlaps are
//! exact for any source height `H` and target height `N`, multiples or not: a texel is a
//! rectangle in `(theta, phi)`, so the overlap of two is a rectangle too, of solid angle
//! `(cos theta_0 - cos theta_1) (phi_1 - phi_0)`, and its edges are found in integer units of
//! `pi / (H N)` (no rounding decides which texels meet). So every source texel's solid angle is
//! shared out in full, and the integral over the sphere (the map's energy, [`LatLongMap::energy`])
//! is unchanged to rounding (tested to 1e-12 relative). [`LatLongMap::downsample`] instead takes
//! the plain mean of each block, which is what a Haar pyramid holds but weighs a texel next to
//! a pole as much as one at the equator, so it moves energy wherever the map is not constant
//! along a block's rows (tested: a bright pole cap changes the energy by percents).
//!
//! # Rotation
//!
//! A yaw by whole columns of the working map (`k x 360 / 2N` degrees) turns the downsampled
//! map's columns, exactly. Any other rotation is applied at the source's resolution, by the
//! sphere module's ground truth ([`reference`](crate::sphere::reference::reference): the
//! solid-angle mean of the bilinear source over each texel, `2 x 2` samples), and the result is
//! downsampled; so the rotation's blur is a source texel's, not a working texel's.
//!
//! # Cube maps
//!
//! For a cube of face side `S`, the map is first downsampled to the lat-long height
//! `min(2 S, H')`, `H'` the largest power of two at most `H`, and then converted by
//! [`convert`](crate::faces::convert) (solid-angle integration over each cube texel, with its
//! [`default_samples`]).

use std::path::Path;

use ndarray::{Array2, Array3, Axis, s};
use rayon::prelude::*;

use crate::faces::convert::{Conversion, default_samples};
use crate::faces::param::{ParamKind, Parameterization, SphereMap};
use crate::io::read_image;
use crate::sphere::{LatLongMap, SphereRotation};
use crate::{Error, Result, Sample};

/// Samples per axis and source texel when a general rotation is applied at the source's
/// resolution (the sphere module's [`reference`](crate::sphere::reference::reference)).
const ROTATION_SAMPLES: usize = 2;

/// An environment map at its source resolution (linear radiance, `f64`).
///
/// ```
/// use haarshift::relight::light::environment::Environment;
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let sky = LatLongMap::<f64>::from_fn(64, 3, |d, out| out.fill(1.0 + d[1].max(0.0))).unwrap();
/// let env = Environment::new(sky);
/// let working = env.lat_long(16, &SphereRotation::identity()).unwrap();
/// assert_eq!((working.height(), working.width(), working.channels()), (16, 32, 3));
/// // the solid-angle-weighted downsample keeps the integral over the sphere
/// let (a, b) = (env.map().energy()[0], working.energy()[0]);
/// assert!((a - b).abs() < 1e-12 * a);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    map: LatLongMap<f64>,
}

impl Environment {
    /// The environment whose source map is `map`.
    pub fn new(map: LatLongMap<f64>) -> Self {
        Environment { map }
    }

    /// Reads a lat-long map from `path` (any format [`crate::io`] reads, by content); the
    /// image must be twice as wide as high. Gray stays one channel, colour is RGB; alpha is
    /// dropped. Errors name the file.
    ///
    /// ```
    /// use haarshift::relight::light::environment::Environment;
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/envmaps/rooitou_park_256x128.npy");
    /// let env = Environment::load(path.as_ref()).unwrap();
    /// assert_eq!((env.map().height(), env.map().channels()), (128, 3));
    /// let square = concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/camera.png");
    /// let err = Environment::load(square.as_ref()).unwrap_err().to_string();
    /// assert!(err.contains("camera.png") && err.contains("twice as wide"));
    /// ```
    pub fn load(path: &Path) -> Result<Self> {
        let image = read_image::<f64>(path)?;
        let colour = image.color_planes();
        let (c, h, w) = colour.dim();
        if w != 2 * h {
            return Err(Error::Format {
                path: path.to_path_buf(),
                reason: format!(
                    "an environment map must be a lat-long map, twice as wide as it is high, \
                     but this one is {w} x {h} (width x height)"
                ),
            });
        }
        let hwc = colour
            .permuted_axes([1, 2, 0])
            .as_standard_layout()
            .into_owned();
        debug_assert_eq!(hwc.dim().2, c);
        let map = LatLongMap::new(hwc).map_err(|e| e.in_file(path))?;
        Ok(Environment { map })
    }

    /// The source map.
    pub fn map(&self) -> &LatLongMap<f64> {
        &self.map
    }

    /// The map rotated by `rotation` (`g(p) = f(R p)`) and downsampled to `n x 2n` by
    /// solid-angle-weighted means (`n` from 1 to the source's height); see the
    /// [module docs](self) for how each kind of rotation is applied.
    ///
    /// ```
    /// use haarshift::relight::light::environment::Environment;
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let f = LatLongMap::<f64>::from_fn(32, 1, |d, out| out[0] = 2.0 + d[0]).unwrap();
    /// let env = Environment::new(f);
    /// let quarter = SphereRotation::from_degrees(90.0, 0.0, 0.0).unwrap(); // 4 columns of 16
    /// let turned = env.lat_long(8, &quarter).unwrap();
    /// let plain = env.lat_long(8, &SphereRotation::identity()).unwrap();
    /// assert_eq!(turned, plain.roll_columns(4));
    /// ```
    pub fn lat_long(&self, n: usize, rotation: &SphereRotation) -> Result<LatLongMap<f64>> {
        if let Some(k) = rotation.whole_column_yaw(2 * n) {
            return Ok(downsample_solid_angle(&self.map, n)?.roll_columns(k));
        }
        let rotated = crate::sphere::reference::reference(&self.map, rotation, ROTATION_SAMPLES)?;
        downsample_solid_angle(&rotated, n)
    }

    /// The rotated map in `param`: lat-long faces of side `N` ([`lat_long`](Self::lat_long)
    /// at `N`), or a cube map converted from the lat-long map of height
    /// `min(2 S, largest power of two <= H)`.
    ///
    /// ```
    /// use haarshift::relight::light::environment::Environment;
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let env = Environment::new(LatLongMap::<f64>::from_fn(64, 3, |_, o| o.fill(0.5)).unwrap());
    /// let cube = Parameterization::new(ParamKind::Cube, 8).unwrap();
    /// let m = env.sphere_map(cube, &SphereRotation::identity()).unwrap();
    /// assert_eq!(m.as_array().dim(), (6, 8, 8, 3));
    /// assert!(m.as_array().iter().all(|&v| (v - 0.5).abs() < 1e-12));
    /// ```
    pub fn sphere_map(
        &self,
        param: Parameterization,
        rotation: &SphereRotation,
    ) -> Result<SphereMap<f64>> {
        SphereMapping::new(self.map.height(), param)?.apply(self, rotation)
    }
}

/// What [`Environment::sphere_map`] prepares before it sees a map, kept to be applied to many
/// (an animation's frames, the lighting of a benchmark): the working lat-long height and, for
/// a cube map, the [`Conversion`] (its overlap table costs more to build than to apply).
///
/// ```
/// use haarshift::relight::light::environment::{Environment, SphereMapping};
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let env = Environment::new(LatLongMap::<f64>::from_fn(64, 1, |d, o| o[0] = 1.0 + d[0]).unwrap());
/// let cube = Parameterization::new(ParamKind::Cube, 8).unwrap();
/// let mapping = SphereMapping::new(64, cube).unwrap();
/// let turn = SphereRotation::from_degrees(45.0, 0.0, 0.0).unwrap();
/// assert_eq!(mapping.apply(&env, &turn).unwrap(), env.sphere_map(cube, &turn).unwrap());
/// ```
#[derive(Clone, Debug)]
pub struct SphereMapping {
    param: Parameterization,
    source_height: usize,
    /// The lat-long height the environment is brought to first.
    height: usize,
    conversion: Option<Conversion>,
}

impl SphereMapping {
    /// The mapping of environments `source_height` high into `param`.
    pub fn new(source_height: usize, param: Parameterization) -> Result<Self> {
        if source_height == 0 {
            return Err(Error::parameter("environment", "a map 0 texels high"));
        }
        Ok(match param.kind() {
            ParamKind::LatLong => SphereMapping {
                param,
                source_height,
                height: param.face_size(),
                conversion: None,
            },
            ParamKind::Cube => {
                let largest = 1usize << (usize::BITS - 1 - source_height.leading_zeros());
                let height = (2 * param.face_size()).min(largest);
                let ll = Parameterization::new(ParamKind::LatLong, height)?;
                let conversion = Conversion::new(ll, param, default_samples(ll, param))?;
                SphereMapping {
                    param,
                    source_height,
                    height,
                    conversion: Some(conversion),
                }
            }
        })
    }

    /// The parameterisation mapped to.
    pub fn param(&self) -> Parameterization {
        self.param
    }

    /// `env` rotated by `rotation` in this mapping's parameterisation; `env` must be as high as
    /// the mapping was made for.
    pub fn apply(&self, env: &Environment, rotation: &SphereRotation) -> Result<SphereMap<f64>> {
        let h = env.map().height();
        if h != self.source_height {
            return Err(Error::parameter(
                "environment",
                format!(
                    "{h} texels high, but the mapping was made for maps {} high",
                    self.source_height
                ),
            ));
        }
        let ll = SphereMap::from_lat_long(&env.lat_long(self.height, rotation)?)?;
        match &self.conversion {
            None => Ok(ll),
            Some(conversion) => conversion.apply(&ll),
        }
    }
}

/// `map` at `n x 2n`, each texel the solid-angle-weighted mean of the source texels it
/// overlaps (exact overlaps; see the [module docs](self)). `n` runs from 1 to the map's
/// height `H` and need not divide it.
///
/// ```
/// use haarshift::relight::light::environment::downsample_solid_angle;
/// use haarshift::sphere::LatLongMap;
/// let f = LatLongMap::<f64>::from_fn(48, 2, |d, o| { o[0] = d[1].exp(); o[1] = 1.0 }).unwrap();
/// let g = downsample_solid_angle(&f, 20).unwrap(); // 48 is not a multiple of 20
/// assert_eq!((g.height(), g.width()), (20, 40));
/// assert!((f.energy()[0] - g.energy()[0]).abs() < 1e-12 * f.energy()[0]);
/// assert!(g.as_array().iter().skip(1).step_by(2).all(|&v| (v - 1.0).abs() < 1e-14));
/// assert!(downsample_solid_angle(&f, 49).is_err());
/// ```
pub fn downsample_solid_angle<T: Sample>(map: &LatLongMap<T>, n: usize) -> Result<LatLongMap<T>> {
    let (h, w, ch) = map.as_array().dim();
    if n == 0 || n > h {
        return Err(Error::parameter(
            "resolution",
            format!("{n}: the working height must be from 1 to the map's height {h}"),
        ));
    }
    if n == h {
        return Ok(map.clone());
    }
    // Edges in integer units: a row edge in units of pi / (h n) (source edge r at r n, target
    // edge i at i h), a column edge in units of 2 pi / (2h 2n).
    let row_unit = std::f64::consts::PI / (h * n) as f64;
    let col_unit = std::f64::consts::TAU / (w * 2 * n) as f64;
    let rows = overlaps(h, n);
    let cols = overlaps(w, 2 * n);
    // Columns first: for every source row, the phi integral over each target column.
    let src = map.as_array();
    let src = src.as_slice().expect("standard layout");
    let mut by_column = Array3::<f64>::zeros((h, 2 * n, ch));
    by_column
        .axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(r, mut out)| {
            let line = &src[r * w * ch..][..w * ch];
            for (j, pieces) in cols.iter().enumerate() {
                let mut acc = out.slice_mut(s![j, ..]);
                for &(c, _, len) in pieces {
                    let dphi = len as f64 * col_unit;
                    for (a, v) in acc.iter_mut().zip(&line[c * ch..][..ch]) {
                        *a += dphi * v.as_f64();
                    }
                }
            }
        });
    // Then rows: the theta integral (with its sin theta) over each target row, divided by
    // the target texel's solid angle.
    let mut out = Array3::<T>::zeros((n, 2 * n, ch));
    out.axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(i, mut target)| {
            let mut acc = Array2::<f64>::zeros((2 * n, ch));
            let mut band = 0.0;
            for &(r, start, len) in &rows[i] {
                let (t0, t1) = (start as f64 * row_unit, (start + len) as f64 * row_unit);
                let weight = t0.cos() - t1.cos();
                band += weight;
                acc.scaled_add(weight, &by_column.index_axis(Axis(0), r));
            }
            let area = band * std::f64::consts::PI / n as f64;
            target.zip_mut_with(&acc, |o, &a| *o = T::from_f64(a / area));
        });
    LatLongMap::new(out)
}

/// For each of `targets` equal intervals of `[0, sources x targets)` (target `t` spans
/// `[t sources, (t + 1) sources)`), the source intervals (of width `targets`) it overlaps, as
/// `(source, start, length)` in those integer units.
fn overlaps(sources: usize, targets: usize) -> Vec<Vec<(usize, usize, usize)>> {
    (0..targets)
        .map(|t| {
            let (lo, hi) = (t * sources, (t + 1) * sources);
            (lo / targets..hi.div_ceil(targets))
                .filter_map(|s| {
                    let a = lo.max(s * targets);
                    let b = hi.min((s + 1) * targets);
                    (b > a).then_some((s, a, b - a))
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{WriteOptions, write_image};
    use crate::{Channels, PlanarImage, SampleDepth};
    use std::f64::consts::PI;

    /// A lumpy positive map with a bright cap at the north pole (the first `cap` rows).
    fn bright_pole(h: usize, cap: usize) -> LatLongMap<f64> {
        let data = Array3::from_shape_fn((h, 2 * h, 2), |(i, j, c)| {
            let base = 1.0 + 0.3 * ((i * 7 + j * 3 + c) % 5) as f64;
            if i < cap { 1000.0 * base } else { base }
        });
        LatLongMap::new(data).unwrap()
    }

    fn relative_energy_change(a: &LatLongMap<f64>, b: &LatLongMap<f64>) -> f64 {
        a.energy()
            .iter()
            .zip(b.energy())
            .map(|(x, y)| (x - y).abs() / x.abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_weighted_downsample_keeps_the_energy_and_the_plain_mean_does_not() {
        for (h, n) in [(64, 8), (64, 32), (48, 20), (37, 5), (64, 1)] {
            let f = bright_pole(h, 3);
            let g = downsample_solid_angle(&f, n).unwrap();
            let change = relative_energy_change(&f, &g);
            assert!(change < 1e-12, "{h} -> {n}: {change:e}");
        }
        // The plain block mean weighs the pole's texels like the equator's.
        let f = bright_pole(64, 3);
        let plain = relative_energy_change(&f, &f.downsample(8).unwrap());
        assert!(plain > 0.1, "the plain mean moved only {plain:e}");
    }

    #[test]
    fn a_constant_stays_constant() {
        for (h, n) in [(32, 8), (30, 7), (16, 16)] {
            let f = LatLongMap::<f32>::from_fn(h, 3, |_, o| o.copy_from_slice(&[0.25, 2.0, 7.5]))
                .unwrap();
            let g = downsample_solid_angle(&f, n).unwrap();
            for px in g.as_array().as_slice().unwrap().chunks_exact(3) {
                for (v, want) in px.iter().zip([0.25, 2.0, 7.5]) {
                    assert!((v - want).abs() < 1e-6 * want, "{h} -> {n}: {v}");
                }
            }
        }
    }

    /// The oracle: cut the sphere into the common refinement of both grids (cells of
    /// `pi / (h n)` in theta and `pi / (h n)` in phi), each cell in one source texel and one
    /// target texel, with its exact solid angle; sum value x solid angle per target texel.
    #[test]
    fn overlaps_match_the_common_refinement() {
        let (h, n) = (6, 4);
        let f = LatLongMap::<f64>::from_fn(h, 1, |d, o| o[0] = (d[0] + 2.0 * d[1] - d[2]).exp())
            .unwrap();
        let g = downsample_solid_angle(&f, n).unwrap();
        let cell = PI / (h * n) as f64;
        let mut sum = Array2::<f64>::zeros((n, 2 * n));
        let mut area = Array2::<f64>::zeros((n, 2 * n));
        for a in 0..h * n {
            let band = (a as f64 * cell).cos() - ((a + 1) as f64 * cell).cos();
            for b in 0..2 * h * n {
                let omega = band * cell;
                let (si, sj) = (a / n, b / n);
                let (ti, tj) = (a / h, b / h);
                sum[[ti, tj]] += omega * f.as_array()[[si, sj, 0]];
                area[[ti, tj]] += omega;
            }
        }
        for ((i, j), s) in sum.indexed_iter() {
            let want = s / area[[i, j]];
            let got = g.as_array()[[i, j, 0]];
            assert!(
                (got - want).abs() < 1e-13 * want,
                "({i}, {j}): {got} vs {want}"
            );
        }
    }

    #[test]
    fn bad_resolutions_and_shapes_are_errors() {
        let f = bright_pole(8, 1);
        assert_err!(
            downsample_solid_angle(&f, 0),
            InvalidParameter {
                name: "resolution",
                ..
            },
            "0: the working height"
        );
        assert_err!(
            downsample_solid_angle(&f, 9),
            InvalidParameter {
                name: "resolution",
                ..
            },
            "9: the working height"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("square.npy");
        let planes = Array3::<f32>::ones((3, 4, 4));
        let image = PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32).unwrap();
        write_image(&image, &path, WriteOptions::default()).unwrap();
        let err = Environment::load(&path).unwrap_err().to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
        assert!(err.contains("4 x 4"), "{err}");
        assert_err!(
            Environment::load(&dir.path().join("missing.hdr")),
            Io { .. },
            "missing.hdr"
        );
    }

    #[test]
    fn a_run_length_encoded_radiance_file_loads() {
        // Values whose RGBE form is exact: a shared exponent and 8-bit mantissas.
        let planes = Array3::from_shape_fn((3, 8, 16), |(c, i, j)| {
            [3.0f32, 1.0, 0.5][c] * 2f32.powi((i as i32 + j as i32 % 3) - 4)
        });
        let image = PlanarImage::new(planes.clone(), Channels::Rgb, SampleDepth::F32).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sky.hdr");
        write_image(&image, &path, WriteOptions::default()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        // A new-style run-length scanline starts 2, 2, then the width (16) in two bytes.
        assert!(bytes.windows(4).any(|w| w == [2, 2, 0, 16]), "not RLE");
        let env = Environment::load(&path).unwrap();
        let map = env.map().as_array();
        assert_eq!(map.dim(), (8, 16, 3));
        for ((c, i, j), &v) in planes.indexed_iter() {
            assert_eq!(map[[i, j, c]], f64::from(v), "({c}, {i}, {j})");
        }
    }

    #[test]
    fn rotations_keep_constants_and_whole_column_yaws_are_exact() {
        let f = bright_pole(32, 2);
        let env = Environment::new(f.clone());
        let yaw = SphereRotation::from_degrees(-45.0, 0.0, 0.0).unwrap(); // -2 columns of 16
        let turned = env.lat_long(8, &yaw).unwrap();
        let want = downsample_solid_angle(&f, 8).unwrap().roll_columns(14);
        assert_eq!(turned, want);
        let one = Environment::new(LatLongMap::from_fn(32, 1, |_, o| o[0] = 3.0).unwrap());
        let tilt = SphereRotation::from_degrees(20.0, 35.0, -10.0).unwrap();
        for param in [
            Parameterization::new(ParamKind::LatLong, 8).unwrap(),
            Parameterization::new(ParamKind::Cube, 4).unwrap(),
        ] {
            let m = one.sphere_map(param, &tilt).unwrap();
            assert!(m.as_array().iter().all(|&v| (v - 3.0).abs() < 1e-12));
        }
        // A general rotation of a linear map, f(p) = a . p + 2: the working texel must hold the
        // exact mean of f(R p) = (R^T a) . p + 2 over it, from the closed-form texel mean of p.
        let a = [1.0, -0.5, 0.25];
        let env = Environment::new(
            LatLongMap::from_fn(128, 1, |d, o| {
                o[0] = 2.0 + (0..3).map(|k| a[k] * d[k]).sum::<f64>()
            })
            .unwrap(),
        );
        let g = env.lat_long(16, &tilt).unwrap();
        let m = tilt.matrix();
        let rta: Vec<f64> = (0..3)
            .map(|k| (0..3).map(|i| m[i][k] * a[i]).sum())
            .collect();
        let step = PI / 16.0;
        let sin2 = |t: f64| t / 2.0 - (2.0 * t).sin() / 4.0; // an antiderivative of sin^2
        let mut worst = 0.0f64;
        for i in 0..16 {
            let (t0, t1) = (i as f64 * step, (i + 1) as f64 * step);
            for j in 0..32 {
                let (p0, p1) = (j as f64 * step, (j + 1) as f64 * step);
                let omega = (t0.cos() - t1.cos()) * step;
                let mean = [
                    (sin2(t1) - sin2(t0)) * (p0.cos() - p1.cos()) / omega,
                    0.5 * (t1.sin().powi(2) - t0.sin().powi(2)) * step / omega,
                    (sin2(t1) - sin2(t0)) * (p1.sin() - p0.sin()) / omega,
                ];
                let want = 2.0 + (0..3).map(|k| rta[k] * mean[k]).sum::<f64>();
                worst = worst.max((g.as_array()[[i, j, 0]] - want).abs());
            }
        }
        // The source holds centre samples, not texel means, and the rotation integrates their
        // bilinear interpolant: both are O(source texel^2) = O(6e-4).
        assert!(worst < 2e-3, "{worst}");
    }
}
