//! Dynamic scenes behind [`Shader`]: moving objects shadowing each other through occlusion
//! fields ([`DynamicScene`], Sun 2006), by n-function product integrals or by the ray-cast
//! reference, and the frames an animation plays ([`play`](crate::dynamic::motion::play),
//! just-in-time radiance transfer) reported alike.

use std::time::Instant;

use ndarray::Array2;

use super::{FrameSpec, HaarEncoder, Preparation, Radiance, Shader, Shading, Timing, seconds};
use crate::Brdf;
use crate::Result;
use crate::dynamic::DynamicScene;
use crate::light::environment::{Environment, LightRotation};
use haarshift::named_enum;
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;

named_enum! {
    /// How a dynamic scene's radiance is computed: the names `relight scene --method` takes.
    ///
    /// ```
    /// use haarshift_relight::shade::dynamic_scene::DynamicMethod;
    /// assert_eq!("reference".parse::<DynamicMethod>().unwrap(), DynamicMethod::Reference);
    /// ```
    pub enum DynamicMethod ("method") {
        /// Occlusion fields and Haar product integrals (`f32`).
        Haar = "haar",
        /// Ray-cast visibility against the placed scene, direct quadrature (`f64`).
        Reference = "reference",
    }
}

/// A [`DynamicScene`] as it is placed now, shaded by a [`DynamicMethod`] with the lighting
/// truncated to `keep_light` (Haar) and rotated at the source map's resolution (or as
/// [`with_light_rotation`](Self::with_light_rotation) says).
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::SceneFile;
/// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
/// use haarshift_relight::light::environment::Environment;
/// use haarshift_relight::shade::dynamic_scene::{DynamicMethod, DynamicShader};
/// use haarshift_relight::shade::{FrameSpec, Shader};
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// let sky = Environment::new(LatLongMap::<f64>::from_fn(16, 3, |_, o| o.fill(1.0)).unwrap());
/// let frame = FrameSpec { environment: &sky, rotation: SphereRotation::identity(), eye: None };
/// let haar = DynamicShader::new(&scene, DynamicMethod::Haar, Selection::All).shade(&frame).unwrap();
/// let truth = DynamicShader::new(&scene, DynamicMethod::Reference, Selection::All).shade(&frame).unwrap();
/// let (h, t) = (haar.radiance.to_f64(), truth.radiance.to_f64());
/// assert!((h[[0, 0]] - t[[0, 0]]).abs() < 0.05 * t[[0, 0]]);
/// ```
pub struct DynamicShader<'a> {
    scene: &'a DynamicScene,
    method: DynamicMethod,
    encoder: HaarEncoder,
}

impl<'a> DynamicShader<'a> {
    /// `scene` shaded by `method`.
    pub fn new(scene: &'a DynamicScene, method: DynamicMethod, keep_light: Selection) -> Self {
        DynamicShader {
            scene,
            method,
            encoder: HaarEncoder::new(scene.param(), keep_light, LightRotation::Source),
        }
    }

    /// The shader with the Haar lighting rotated as `how` says: [`LightRotation::Prefiltered`]
    /// is what an interactive drag needs (milliseconds at any angle, against a tenth of a
    /// second at a 1k map's resolution). The reference always rotates the source.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::SceneFile;
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::light::environment::{Environment, LightRotation};
    /// use haarshift_relight::shade::dynamic_scene::{DynamicMethod, DynamicShader};
    /// use haarshift_relight::shade::{FrameSpec, Shader};
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let file: SceneFile = serde_json::from_str(r#"{"objects": [
    ///     {"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// (options.field.circles, options.field.circle_points) = (8, 16);
    /// (options.field.shells, options.field.shell_grid) = (4, 3);
    /// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// let sky = Environment::new(LatLongMap::<f64>::from_fn(64, 3, |d, o| o.fill(1.0 + d[1])).unwrap());
    /// let tilt = SphereRotation::from_degrees(10.0, 30.0, 0.0).unwrap();
    /// let frame = FrameSpec { environment: &sky, rotation: tilt, eye: None };
    /// let haar = |how| {
    ///     let mut shader = DynamicShader::new(&scene, DynamicMethod::Haar, Selection::All)
    ///         .with_light_rotation(how);
    ///     shader.shade(&frame).unwrap().radiance.to_f64()
    /// };
    /// let (source, fast) = (haar(LightRotation::Source), haar(LightRotation::Prefiltered));
    /// assert_ne!(source, fast);
    /// assert!((&source - &fast).iter().all(|d| d.abs() < 0.02 * source[[0, 0]]));
    /// ```
    pub fn with_light_rotation(self, how: LightRotation) -> Self {
        let keep = self.encoder.keep();
        DynamicShader {
            encoder: HaarEncoder::new(self.scene.param(), keep, how),
            ..self
        }
    }

    /// The reference of `scene` as placed now under `environment` turned by `rotation`.
    fn reference(
        scene: &DynamicScene,
        environment: &Environment,
        rotation: &SphereRotation,
    ) -> Result<(Array2<f64>, f64, f64)> {
        let start = Instant::now();
        let map = environment.lat_long(scene.param().face_size(), rotation)?;
        let encode = seconds(start);
        let start = Instant::now();
        let radiance = scene.reference(&map)?;
        Ok((radiance, encode, seconds(start)))
    }
}

impl Shader for DynamicShader<'_> {
    fn shade(&mut self, frame: &FrameSpec<'_>) -> Result<Shading> {
        let param = self.scene.param();
        let (radiance, encode_seconds, shade_seconds, description, coefficients) = match self.method
        {
            DynamicMethod::Haar => {
                let (lighting, encode) = self.encoder.encode(frame)?;
                let start = Instant::now();
                let radiance = Radiance::F32(self.scene.shade::<f32>(&lighting)?);
                let coefficients = lighting.kept() + param.faces();
                (
                    radiance,
                    encode,
                    seconds(start),
                    "n-function product integrals",
                    coefficients,
                )
            }
            DynamicMethod::Reference => {
                let (radiance, encode, shade) =
                    Self::reference(self.scene, frame.environment, &frame.rotation)?;
                let n = param.face_size();
                (
                    Radiance::F64(radiance),
                    encode,
                    shade,
                    "ray-cast reference",
                    2 * n * n,
                )
            }
        };
        Ok(unrotated_shading(
            radiance,
            (encode_seconds, shade_seconds),
            description,
            Some(coefficients),
        ))
    }

    fn preparation(&self) -> Preparation {
        Preparation {
            seconds: self.scene.report().transport_seconds,
            filled: None,
        }
    }
}

impl DynamicMethod {
    /// One frame that [`play`](crate::dynamic::motion::play) handed over with just-in-time
    /// radiance transfer's `played` radiance, shaded in `shade_seconds`: kept by Haar,
    /// computed again by the reference against `scene` as placed for the frame. The
    /// description is `shading` or `reference`.
    pub fn played(
        self,
        scene: &DynamicScene,
        played: &Array2<f32>,
        shade_seconds: f64,
        environment: &Environment,
        rotation: &SphereRotation,
    ) -> Result<Shading> {
        let (radiance, encode_seconds, shade_seconds, description) = match self {
            DynamicMethod::Haar => (Radiance::F32(played.clone()), 0.0, shade_seconds, "shading"),
            DynamicMethod::Reference => {
                let (radiance, encode, shade) =
                    DynamicShader::reference(scene, environment, rotation)?;
                (Radiance::F64(radiance), encode, shade, "reference")
            }
        };
        Ok(unrotated_shading(
            radiance,
            (encode_seconds, shade_seconds),
            description,
            None,
        ))
    }
}

/// The first glossy material of `scene`'s objects, else Lambert: the one a caller's glossy
/// options (rotation method, cache, truncation) are checked against (any other glossy
/// material is rotated alike).
///
/// ```
/// use haarshift_relight::{Brdf, SceneFile};
/// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
/// use haarshift_relight::shade::dynamic_scene::glossy_material;
/// use haarshift::faces::param::{ParamKind, Parameterization};
/// let file: SceneFile = serde_json::from_str(r#"{"objects": [
///     {"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
/// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
/// (options.field.circles, options.field.circle_points) = (8, 16);
/// (options.field.shells, options.field.shell_grid) = (4, 3);
/// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
/// assert_eq!(glossy_material(&scene).unwrap(), Brdf::Lambert);
/// scene.set_brdf(0, "phong:30".parse().unwrap()).unwrap();
/// assert_eq!(glossy_material(&scene).unwrap().to_string(), "phong:30");
/// ```
pub fn glossy_material(scene: &DynamicScene) -> Result<Brdf> {
    for k in 0..scene.object_count() {
        let brdf = scene.brdf(k)?;
        if !brdf.is_lambert() {
            return Ok(brdf.clone());
        }
    }
    Ok(Brdf::Lambert)
}

/// A dynamic scene's frame: its timing reports encoding and shading, no separate BRDF
/// rotation.
fn unrotated_shading(
    radiance: Radiance,
    (encode_seconds, shade_seconds): (f64, f64),
    description: &str,
    light_coefficients: Option<usize>,
) -> Shading {
    Shading {
        radiance,
        timing: Timing::unrotated(encode_seconds, shade_seconds),
        description: description.into(),
        maps: None,
        light_coefficients,
    }
}
