//! The shading stage: every vertex's outgoing radiance under a lighting, behind one interface.
//!
//! A [`ShaderSpec`] says how the radiance is computed: the [`Method`] (the Haar basis, spherical
//! harmonics, the reference quadrature, ambient occlusion), the material, how a glossy BRDF is
//! brought into each vertex's frame and truncated (with its rotation cache), and the budgets of
//! the transport and the lighting. [`ShaderSpec::build`] makes a [`Shader`] from a scene
//! ([`ShadingInput`]: a scene cache, or a scene for the reference) once; each
//! [`Shader::shade`] of a [`FrameSpec`] (the environment, its rotation, the eye) returns a
//! [`Shading`]: the radiance `(V, 3)`, what each part took, and a line saying what was done.
//! Callers build a spec and loop over frames; none of them chooses between the methods, so a
//! new method is one more [`Method`] and one more file here.
//!
//! | file | shader | numeric code |
//! |---|---|---|
//! | [`lambert`] | [`LambertShader`](lambert::LambertShader): one sparse dot per vertex | [`PreparedTransport`] |
//! | [`glossy`] | [`GlossyHaarShader`](glossy::GlossyHaarShader): the triple product with the rotated BRDF | [`GlossyShader`](glossy::GlossyShader), the rotation cache |
//! | [`sh`] | [`ShShader`](sh::ShShader): Microsoft 2003's spherical-harmonic baseline | [`shade_sh`](sh::shade_sh), [`PhongSh`](sh::PhongSh) |
//! | [`mod@reference`] | [`ReferenceShader`](reference::ReferenceShader): the ground truth | [`reference()`](reference::reference) |
//! | [`ambient`] | [`AmbientShader`](ambient::AmbientShader): `albedo / pi x <T, 1>` | [`PreparedTransport`] under a white sky |
//! | [`dynamic_scene`] | [`DynamicShader`](dynamic_scene::DynamicShader): moving objects (Sun 2006) | [`DynamicScene`](crate::dynamic::DynamicScene) |
//! | [`frame`] | [`FrameSpec`], [`LightSpec`]: the lighting of a frame, resolved | |

pub mod ambient;
pub mod dynamic_scene;
pub mod frame;
pub mod glossy;
pub mod lambert;
pub mod reference;
pub mod sh;
mod spec;

pub use frame::{FrameSpec, LightSpec};
pub use lambert::{PreparedTransport, ShadeOptions, shade_lambertian};
pub(crate) use lambert::{select_kept, within_depth};
pub use spec::{Method, Precision, ShaderSpec, ShadingInput};

use std::time::Instant;

use ndarray::Array2;

use crate::Lighting;
use crate::Result;
use crate::light::environment::{LightRotation, SphereMapping};
use haarshift::faces::{Parameterization, SphereMap};
use haarshift::product::Selection;

/// A way of computing every vertex's outgoing radiance, made once by [`ShaderSpec::build`]
/// and asked for frame after frame (a glossy shader keeps its rotation cache between them).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::light::environment::Environment;
/// use haarshift_relight::shade::{FrameSpec, ShaderSpec, ShadingInput};
/// use haarshift_relight::{Mesh, TransportSet};
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// use ndarray::{Array2, Axis, array};
/// // An upward triangle whose vertices see the whole sky: transport = cosine x solid angle.
/// let mesh = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                      vec![[0, 1, 2]], None).unwrap();
/// let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
/// let cosine = SphereMap::<f64>::from_fn(param, 1, |d, o| o[0] = d[1].max(0.0)).unwrap();
/// let unweighted = cosine.as_array().index_axis(Axis(3), 0).mapv(|v| v as f32);
/// let mut set = TransportSet::new(param, Selection::All);
/// for _ in 0..3 {
///     set.push(unweighted.view()).unwrap();
/// }
/// let albedo = Array2::from_elem((3, 3), 0.5f32);
/// let input = ShadingInput::new(&mesh, albedo.view(), Some(&set), 3);
/// let mut shader = ShaderSpec::default().build(&input).unwrap();
/// let sky = Environment::new(LatLongMap::<f64>::from_fn(16, 3, |_, o| o.fill(1.0)).unwrap());
/// let frame = FrameSpec { environment: &sky, rotation: SphereRotation::identity(), eye: None };
/// let shading = shader.shade(&frame).unwrap();
/// // Irradiance pi under a unit sky: albedo / pi x pi, to the quadrature of the cosine at
/// // texel centres of lat-long 16 (0.5024 here).
/// let got = shading.radiance.to_f32()[[0, 0]];
/// assert!((got - 0.5).abs() < 5e-3, "{got}");
/// ```
pub trait Shader: Send {
    /// Every vertex's outgoing radiance under `frame`'s lighting, seen from its eye.
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading>;

    /// What [`ShaderSpec::build`] did once, before any frame.
    fn preparation(&self) -> Preparation;
}

/// One frame's per-vertex radiance and what it cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Shading {
    /// `(V, 3)` outgoing radiance, in the precision its method computes.
    pub radiance: Radiance,
    /// What each part of the frame took.
    pub timing: Timing,
    /// One line saying what was computed, e.g. `Haar, lighting kept 200 detail coefficients,
    /// transport 80000 coefficients; transport prepared once in 12.0 ms`.
    pub description: String,
    /// A glossy Haar shader's BRDF maps: how many the vertices used and how many were rotated.
    pub maps: Option<glossy::GlossyReport>,
    /// Coefficients of the lighting used: Haar the kept details and each face's scaling
    /// coefficient, spherical harmonics `B^2`, the reference its texels.
    /// `None` where the frame's lighting was encoded elsewhere (a played animation frame).
    pub light_coefficients: Option<usize>,
}

/// Per-vertex radiance `(V, 3)` in the precision it was computed in.
#[derive(Clone, Debug, PartialEq)]
pub enum Radiance {
    /// The fast paths: Haar in `f32`, Lambertian spherical harmonics.
    F32(Array2<f32>),
    /// Haar in `f64`, the glossy spherical-harmonics baseline, the reference.
    F64(Array2<f64>),
}

impl Radiance {
    /// The radiance in `f32` (an `f64` one rounded to nearest).
    ///
    /// ```
    /// use haarshift_relight::shade::Radiance;
    /// let r = Radiance::F64(ndarray::array![[0.1, 0.2, 0.3]]);
    /// assert_eq!(r.to_f32(), ndarray::array![[0.1f32, 0.2, 0.3]]);
    /// ```
    pub fn to_f32(&self) -> Array2<f32> {
        match self {
            Radiance::F32(r) => r.clone(),
            Radiance::F64(r) => r.mapv(|x| x as f32),
        }
    }

    /// The radiance in `f64` (an `f32` one exactly).
    ///
    /// ```
    /// use haarshift_relight::shade::Radiance;
    /// let r = Radiance::F32(ndarray::array![[0.1f32, 0.2, 0.3]]);
    /// assert_eq!(r.to_f64()[[0, 0]], f64::from(0.1f32));
    /// ```
    pub fn to_f64(&self) -> Array2<f64> {
        match self {
            Radiance::F32(r) => r.mapv(f64::from),
            Radiance::F64(r) => r.clone(),
        }
    }

    /// `(V, 3)`.
    ///
    /// ```
    /// use haarshift_relight::shade::Radiance;
    /// assert_eq!(Radiance::F32(ndarray::Array2::zeros((7, 3))).dim(), (7, 3));
    /// ```
    pub fn dim(&self) -> (usize, usize) {
        match self {
            Radiance::F32(r) => r.dim(),
            Radiance::F64(r) => r.dim(),
        }
    }
}

impl From<Array2<f32>> for Radiance {
    fn from(r: Array2<f32>) -> Self {
        Radiance::F32(r)
    }
}

impl From<Array2<f64>> for Radiance {
    fn from(r: Array2<f64>) -> Self {
        Radiance::F64(r)
    }
}

/// What the parts of one frame took, seconds.
///
/// ```
/// use haarshift_relight::shade::Timing;
/// let t = Timing { encode_seconds: 0.002, rotate_seconds: 0.001, shade_seconds: 0.003 };
/// assert!((t.total_seconds() - 0.005).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// Bringing the environment to the method's basis: rotated, resampled, transformed and
    /// truncated (Haar), projected (spherical harmonics), downsampled (the reference).
    pub encode_seconds: f64,
    /// Of the shading, the BRDF maps rotated into vertex frames (glossy Haar; 0 otherwise).
    pub rotate_seconds: f64,
    /// The shading itself, rotations included.
    pub shade_seconds: f64,
}

impl Timing {
    /// A frame of a method that rotates no BRDF: encoding and shading only.
    ///
    /// ```
    /// use haarshift_relight::shade::Timing;
    /// let t = Timing::unrotated(0.25, 0.5);
    /// assert_eq!((t.encode_seconds, t.rotate_seconds, t.shade_seconds), (0.25, 0.0, 0.5));
    /// ```
    pub fn unrotated(encode_seconds: f64, shade_seconds: f64) -> Timing {
        Timing {
            encode_seconds,
            rotate_seconds: 0.0,
            shade_seconds,
        }
    }

    /// Encoding and shading together.
    pub fn total_seconds(&self) -> f64 {
        self.encode_seconds + self.shade_seconds
    }
}

/// What [`ShaderSpec::build`] did before any frame.
///
/// ```
/// use haarshift_relight::shade::Preparation;
/// let p = Preparation::default();
/// assert_eq!((p.seconds, p.filled), (0.0, None));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Preparation {
    /// Seconds preparing the scene's data (the transport truncated and scaled by the albedo,
    /// the Gaunt table, the bounding volume), the cache fill apart.
    pub seconds: f64,
    /// With [`ShaderSpec::fill_cache`], the rotation cache filled ahead.
    pub filled: Option<Filled>,
}

/// A rotation cache filled ahead: the maps rotated and the seconds that took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Filled {
    /// BRDF maps rotated.
    pub maps: usize,
    /// Seconds.
    pub seconds: f64,
}

/// The lighting of frames in a shader's parameterisation: the environment rotated (as
/// `rotation` says) and brought to it, the mapping into it (a cube's conversion table) made
/// once per environment height and reused from frame to frame.
#[derive(Debug)]
pub(crate) struct FrameMapping {
    param: Parameterization,
    rotation: LightRotation,
    mapping: Option<(usize, SphereMapping)>,
}

impl FrameMapping {
    pub(crate) fn new(param: Parameterization, rotation: LightRotation) -> Self {
        FrameMapping {
            param,
            rotation,
            mapping: None,
        }
    }

    /// `frame`'s environment, rotated, in the parameterisation.
    pub(crate) fn apply(&mut self, frame: &FrameSpec<'_>) -> Result<SphereMap<f64>> {
        let height = frame.environment.map().height();
        let mapping = match self.mapping.take() {
            Some((h, mapping)) if h == height => mapping,
            _ => SphereMapping::new(height, self.param)?.with_rotation(self.rotation),
        };
        let map = mapping.apply(frame.environment, &frame.rotation);
        self.mapping = Some((height, mapping));
        map
    }
}

/// The Haar lighting of frames ([`Lighting::encode`] with a [`FrameMapping`]).
#[derive(Debug)]
pub(crate) struct HaarEncoder {
    mapping: FrameMapping,
    keep: Selection,
}

impl HaarEncoder {
    pub(crate) fn new(param: Parameterization, keep: Selection, rotation: LightRotation) -> Self {
        HaarEncoder {
            mapping: FrameMapping::new(param, rotation),
            keep,
        }
    }

    /// The lighting's truncation.
    pub(crate) fn keep(&self) -> Selection {
        self.keep
    }

    /// `frame`'s lighting and the seconds encoding it took.
    pub(crate) fn encode(&mut self, frame: &FrameSpec<'_>) -> Result<(Lighting, f64)> {
        let start = Instant::now();
        let lighting = Lighting::from_map(&self.mapping.apply(frame)?, self.keep)?;
        Ok((lighting, start.elapsed().as_secs_f64()))
    }
}

/// Seconds since `start`.
pub(crate) fn seconds(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

#[cfg(test)]
mod tests;
