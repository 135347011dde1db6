//! The lighting: a lat-long environment map, loaded from a file, brought to the working
//! resolution by solid-angle-weighted means, rotated, and laid out in the parameterisation
//! the product integrals run in.
//!
//! # Pipeline
//!
//! [`Environment::load`] reads any image or array [`haarshift::io`] reads (Radiance `.hdr`, run-length
//! encoded or flat, OpenEXR, `.npy`, ...) and checks that it is 2:1; an alpha plane is dropped.
//! [`Environment::lat_long`] then gives the map at `N x 2N`, rotated by `g(p) = f(R p)`
//! ([`SphereRotation`]), and [`Environment::sphere_map`] the same in a [`Parameterization`]
//! (lat-long `N x 2N` faces, or a cube map).
//!
//! # Rotation
//!
//! A yaw by whole columns of the working map (`k x 360 / 2N` degrees) turns the downsampled
//! map's columns, exactly. Any other rotation is applied at the source's resolution, by the
//! sphere module's ground truth ([`reference`](haarshift::sphere::reference::reference): the
//! solid-angle mean of the bilinear source over each texel, `2 x 2` samples), and the result is
//! downsampled; so the rotation's blur is a source texel's, not a working texel's.
//!
//! # Prefiltered rotation
//!
//! A rotation at the source's resolution costs what the source has texels (a 1024 x 512 map:
//! about 0.1 s on two cores), whatever the working resolution. [`LightRotation::Prefiltered`]
//! instead starts from a copy of the map brought down once, by the same solid-angle-weighted
//! means, to `min(2N, H)` rows ([`Environment::downsampled`], kept with the environment), and
//! samples the rotation at the working texels from it: each working texel is the
//! `sin theta`-weighted mean of `2 x 2` stratum midpoints (one per texel of the copy) of the
//! copy's bilinear interpolant, the ground truth's estimator
//! ([`LatLongMap::from_fn_mean`]) on fewer, cheaper samples. The cost is four lookups per
//! working texel; the result is blurrier than [`LightRotation::Source`]'s (the copy's texels
//! and the bilinear tent over them are half a working texel), which moves a sun or a lamp
//! partly into the neighbouring texels: measured in `results/viewer/lighting_rotation.md`.
//! Under the identity the midpoints are the copy's texel centres and their `sin theta`
//! weights are proportional to the copy's ring solid angles, so even this path keeps the
//! map's energy to rounding. Whole-column yaws take the exact column shift in
//! both, so the two agree bit for bit there, and whenever `2N >= H` (the prefiltered copy is
//! the source).
//!
//! # Cube maps
//!
//! For a cube of face side `S`, the map is first downsampled to the lat-long height
//! `min(2 S, H')`, `H'` the largest power of two at most `H`, and then converted by
//! [`convert`](haarshift::faces::convert) (solid-angle integration over each cube texel, with its
//! [`default_samples`]).

use std::path::Path;
use std::sync::{Arc, Mutex, PoisonError};

use super::downsample::downsample_solid_angle;
use crate::{Error, Result};
use haarshift::faces::convert::{Conversion, default_samples};
use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
use haarshift::io::read_image;
use haarshift::named_enum;
use haarshift::sphere::latlong::angles;
use haarshift::sphere::{LatLongMap, SphereRotation};

/// Samples per axis and source texel when a general rotation is applied at the source's
/// resolution (the sphere module's [`reference`](haarshift::sphere::reference::reference)).
const ROTATION_SAMPLES: usize = 2;

/// The prefiltered copy is this many times the working lat-long height (capped at the
/// source's).
const PREFILTER_FACTOR: usize = 2;

/// Samples per axis and working texel of a prefiltered rotation: one per texel of the copy.
const PREFILTERED_SAMPLES: usize = PREFILTER_FACTOR;

named_enum! {
    /// How a general rotation of the lighting is applied (a whole-column yaw is an exact column
    /// shift either way): the names `relight render --light-rotation` takes. See the
    /// [module docs](self).
    ///
    /// ```
    /// use haarshift_relight::light::environment::LightRotation;
    /// assert_eq!(LightRotation::default(), LightRotation::Source);
    /// assert_eq!("prefiltered".parse::<LightRotation>().unwrap(), LightRotation::Prefiltered);
    /// assert_eq!(LightRotation::ALL.iter().map(|r| r.name()).collect::<Vec<_>>(),
    ///            ["source", "prefiltered"]);
    /// ```
    #[derive(Default)]
    pub enum LightRotation ("light-rotation") {
        #[default]
        /// At the source map's resolution, then downsampled: the sharpest, at a cost that
        /// grows with the source (about 0.1 s for a 1024 x 512 map on two cores).
        Source = "source",
        /// From a copy prefiltered once to twice the working lat-long height, sampled at the
        /// working texels: a few milliseconds, blurrier.
        Prefiltered = "prefiltered",
    }
}

/// An environment map at its source resolution (linear radiance, `f64`).
///
/// ```
/// use haarshift_relight::light::environment::Environment;
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let sky = LatLongMap::<f64>::from_fn(64, 3, |d, out| out.fill(1.0 + d[1].max(0.0))).unwrap();
/// let env = Environment::new(sky);
/// let working = env.lat_long(16, &SphereRotation::identity()).unwrap();
/// assert_eq!((working.height(), working.width(), working.channels()), (16, 32, 3));
/// // the solid-angle-weighted downsample keeps the integral over the sphere
/// let (a, b) = (env.map().energy()[0], working.energy()[0]);
/// assert!((a - b).abs() < 1e-12 * a);
/// ```
#[derive(Clone, Debug)]
pub struct Environment {
    map: LatLongMap<f64>,
    levels: Levels,
}

impl PartialEq for Environment {
    /// Environments are equal when their source maps are (the kept downsamples follow).
    fn eq(&self, other: &Self) -> bool {
        self.map == other.map
    }
}

/// The solid-angle-weighted downsamples of an environment's map made so far, each once.
#[derive(Debug, Default)]
struct Levels(Mutex<Vec<Arc<LatLongMap<f64>>>>);

impl Clone for Levels {
    fn clone(&self) -> Self {
        let levels = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        Levels(Mutex::new(levels.clone()))
    }
}

impl Environment {
    /// The environment whose source map is `map`.
    pub fn new(map: LatLongMap<f64>) -> Self {
        Environment {
            map,
            levels: Levels::default(),
        }
    }

    /// Reads a lat-long map from `path` (any format [`haarshift::io`] reads, by content); the
    /// image must be twice as wide as high. Gray stays one channel, colour is RGB; alpha is
    /// dropped. Errors name the file.
    ///
    /// ```
    /// use haarshift_relight::light::environment::Environment;
    /// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/envmaps/rooitou_park_256x128.npy");
    /// let env = Environment::load(path.as_ref()).unwrap();
    /// assert_eq!((env.map().height(), env.map().channels()), (128, 3));
    /// let square = concat!(env!("CARGO_MANIFEST_DIR"), "/../testdata/camera.png");
    /// let err = Environment::load(square.as_ref()).unwrap_err().to_string();
    /// assert!(err.contains("camera.png") && err.contains("twice as wide"));
    /// ```
    pub fn load(path: &Path) -> Result<Self> {
        let image = read_image::<f64>(path)?;
        let colour = image.color_planes();
        let (c, h, w) = colour.dim();
        if w != 2 * h {
            return Err(crate::Error::from(haarshift::Error::Format {
                path: path.to_path_buf(),
                reason: format!(
                    "an environment map must be a lat-long map, twice as wide as it is high, \
                     but this one is {w} x {h} (width x height)"
                ),
            }));
        }
        let hwc = colour
            .permuted_axes([1, 2, 0])
            .as_standard_layout()
            .into_owned();
        debug_assert_eq!(hwc.dim().2, c);
        let map = LatLongMap::new(hwc).map_err(|e| e.in_file(path))?;
        Ok(Environment::new(map))
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
    /// use haarshift_relight::light::environment::Environment;
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
        let rotated =
            haarshift::sphere::reference::reference(&self.map, rotation, ROTATION_SAMPLES)?;
        downsample_solid_angle(&rotated, n)
    }

    /// The source map at `n x 2n` by solid-angle-weighted means
    /// ([`downsample_solid_angle`]), computed on the first request for `n` and kept with the
    /// environment (its clones share what was computed before they were made).
    ///
    /// ```
    /// use haarshift_relight::light::downsample::downsample_solid_angle;
    /// use haarshift_relight::light::environment::Environment;
    /// use haarshift::sphere::LatLongMap;
    /// let f = LatLongMap::<f64>::from_fn(32, 1, |d, o| o[0] = 1.0 + d[1]).unwrap();
    /// let env = Environment::new(f.clone());
    /// let level = env.downsampled(8).unwrap();
    /// assert_eq!(*level, downsample_solid_angle(&f, 8).unwrap());
    /// assert!(std::sync::Arc::ptr_eq(&level, &env.downsampled(8).unwrap())); // kept
    /// assert!(env.downsampled(33).is_err());
    /// ```
    pub fn downsampled(&self, n: usize) -> Result<Arc<LatLongMap<f64>>> {
        let mut levels = self.levels.0.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(level) = levels.iter().find(|l| l.height() == n) {
            return Ok(Arc::clone(level));
        }
        let level = Arc::new(downsample_solid_angle(&self.map, n)?);
        levels.push(Arc::clone(&level));
        Ok(level)
    }

    /// [`lat_long`](Self::lat_long) with a general rotation applied as `how` says:
    /// [`LightRotation::Source`] is `lat_long` itself, [`LightRotation::Prefiltered`] rotates
    /// the [`downsampled`](Self::downsampled) copy `min(2n, H)` high (see the
    /// [module docs](self)).
    ///
    /// ```
    /// use haarshift_relight::light::environment::{Environment, LightRotation};
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let f = LatLongMap::<f64>::from_fn(64, 1, |d, o| o[0] = 2.0 + d[0] - d[1]).unwrap();
    /// let env = Environment::new(f);
    /// let tilt = SphereRotation::from_degrees(20.0, 35.0, -10.0).unwrap();
    /// let fast = env.rotated(8, &tilt, LightRotation::Prefiltered).unwrap();
    /// let source = env.rotated(8, &tilt, LightRotation::Source).unwrap();
    /// assert_eq!(source, env.lat_long(8, &tilt).unwrap());
    /// let worst = (&fast.as_array() - &source.as_array()).fold(0.0f64, |m, d| m.max(d.abs()));
    /// assert!(worst > 0.0 && worst < 5e-2, "{worst}"); // the copy 16 high: O(copy texel^2)
    /// // a whole-column yaw is the same column shift in both
    /// let yaw = SphereRotation::from_degrees(45.0, 0.0, 0.0).unwrap();
    /// assert_eq!(env.rotated(8, &yaw, LightRotation::Prefiltered).unwrap(),
    ///            env.lat_long(8, &yaw).unwrap());
    /// ```
    pub fn rotated(
        &self,
        n: usize,
        rotation: &SphereRotation,
        how: LightRotation,
    ) -> Result<LatLongMap<f64>> {
        match how {
            LightRotation::Source => self.lat_long(n, rotation),
            LightRotation::Prefiltered => {
                if let Some(k) = rotation.whole_column_yaw(2 * n) {
                    return Ok(self.downsampled(n)?.roll_columns(k));
                }
                let h = self.map.height();
                let m = (PREFILTER_FACTOR * n).min(h);
                if m == h {
                    // The prefiltered copy would be the source itself.
                    return self.lat_long(n, rotation);
                }
                let level = self.downsampled(m)?;
                // The working texel's solid-angle mean of the copy's bilinear interpolant,
                // rotated: the ground truth's estimator, sampled at the working resolution.
                Ok(LatLongMap::from_fn_mean(
                    n,
                    level.channels(),
                    PREFILTERED_SAMPLES,
                    |d, out| {
                        let (theta, phi) = angles(rotation.apply(d));
                        level.bilinear(theta, phi, out);
                    },
                )?)
            }
        }
    }

    /// The rotated map in `param`: lat-long faces of side `N` ([`lat_long`](Self::lat_long)
    /// at `N`), or a cube map converted from the lat-long map of height
    /// `min(2 S, largest power of two <= H)`.
    ///
    /// ```
    /// use haarshift_relight::light::environment::Environment;
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
/// a cube map, the [`Conversion`] (its overlap table costs more to build than to apply); and
/// how a general rotation is applied ([`LightRotation`], [`with_rotation`](Self::with_rotation)).
///
/// ```
/// use haarshift_relight::light::environment::{Environment, SphereMapping};
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
    rotation: LightRotation,
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
                rotation: LightRotation::Source,
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
                    rotation: LightRotation::Source,
                }
            }
        })
    }

    /// This mapping with general rotations applied as `how` says ([`LightRotation::Source`]
    /// unless set). A [`LightRotation::Prefiltered`] mapping rotates the environment's copy
    /// twice the working lat-long height high, made on its first use and kept with the
    /// environment ([`Environment::downsampled`]).
    ///
    /// ```
    /// use haarshift_relight::light::environment::{Environment, LightRotation, SphereMapping};
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let env = Environment::new(LatLongMap::<f64>::from_fn(64, 1, |d, o| o[0] = 1.0 + d[0]).unwrap());
    /// let cube = Parameterization::new(ParamKind::Cube, 8).unwrap(); // lat-long 16, copy 32
    /// let fast = SphereMapping::new(64, cube).unwrap().with_rotation(LightRotation::Prefiltered);
    /// assert_eq!(fast.rotation(), LightRotation::Prefiltered);
    /// let turn = SphereRotation::from_degrees(30.0, 40.0, 0.0).unwrap();
    /// let m = fast.apply(&env, &turn).unwrap();
    /// let truth = env.sphere_map(cube, &turn).unwrap();
    /// assert!(m.relative_rms_error(&truth).unwrap() < 1e-3);
    /// assert_eq!(env.downsampled(32).unwrap().height(), 32); // made by apply, kept
    /// ```
    pub fn with_rotation(self, how: LightRotation) -> Self {
        SphereMapping {
            rotation: how,
            ..self
        }
    }

    /// How general rotations are applied.
    pub fn rotation(&self) -> LightRotation {
        self.rotation
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
        self.to_param(&env.rotated(self.height, rotation, self.rotation)?)
    }

    /// The lat-long height the environment is brought to (and rotated at) before it goes into
    /// the parameterisation: the face size for lat-long, `min(2 S, H')` for a cube of side `S`
    /// (`H'` the largest power of two at most the source's height).
    ///
    /// ```
    /// use haarshift_relight::light::environment::SphereMapping;
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// let cube = Parameterization::new(ParamKind::Cube, 64).unwrap();
    /// assert_eq!(SphereMapping::new(512, cube).unwrap().lat_long_height(), 128);
    /// assert_eq!(SphereMapping::new(100, cube).unwrap().lat_long_height(), 64);
    /// ```
    pub fn lat_long_height(&self) -> usize {
        self.height
    }

    /// A lat-long map [`lat_long_height`](Self::lat_long_height) high (already rotated) in
    /// the parameterisation: itself for lat-long, converted for a cube.
    ///
    /// ```
    /// use haarshift_relight::light::environment::SphereMapping;
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::sphere::LatLongMap;
    /// let cube = Parameterization::new(ParamKind::Cube, 4).unwrap();
    /// let mapping = SphereMapping::new(32, cube).unwrap();
    /// let ll = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 2.0).unwrap();
    /// let m = mapping.to_param(&ll).unwrap();
    /// assert!(m.as_array().iter().all(|&v| (v - 2.0).abs() < 1e-12));
    /// assert!(mapping.to_param(&LatLongMap::<f64>::from_fn(16, 1, |_, o| o[0] = 2.0).unwrap()).is_err());
    /// ```
    pub fn to_param(&self, map: &LatLongMap<f64>) -> Result<SphereMap<f64>> {
        if map.height() != self.height {
            return Err(Error::parameter(
                "environment",
                format!(
                    "a lat-long map {} texels high, but the mapping works at {}",
                    map.height(),
                    self.height
                ),
            ));
        }
        let ll = SphereMap::from_lat_long(map)?;
        match &self.conversion {
            None => Ok(ll),
            Some(conversion) => Ok(conversion.apply(&ll)?),
        }
    }
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
