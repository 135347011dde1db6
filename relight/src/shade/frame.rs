//! A frame's lighting and eye ([`FrameSpec`]), and the lighting a caller asked for resolved
//! against a scene file's ([`LightSpec`]).

use std::path::PathBuf;

use crate::EnvironmentSpec;
use crate::light::environment::Environment;
use crate::{Error, Result};
use haarshift::sphere::SphereRotation;

/// What one frame is shaded under: the environment, its rotation (`g(p) = f(R p)`) and the
/// camera's position (needed by view-dependent materials).
///
/// ```
/// use haarshift_relight::light::environment::Environment;
/// use haarshift_relight::shade::FrameSpec;
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let sky = Environment::new(LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap());
/// let frame = FrameSpec { environment: &sky, rotation: SphereRotation::identity(), eye: None };
/// assert!(frame.eye().is_err()); // a glossy shader asks for it
/// ```
#[derive(Clone, Copy, Debug)]
pub struct FrameSpec<'a> {
    /// The lighting, a lat-long map.
    pub environment: &'a Environment,
    /// Its rotation.
    pub rotation: SphereRotation,
    /// The camera's position.
    pub eye: Option<[f64; 3]>,
}

impl FrameSpec<'_> {
    /// The eye, required.
    pub fn eye(&self) -> Result<[f64; 3]> {
        self.eye.ok_or_else(|| {
            Error::parameter(
                "eye",
                "a view-dependent material needs the camera's position",
            )
        })
    }
}

/// The lighting a caller asked for: an environment file and rotation angles in degrees, each
/// possibly absent; [`resolve`](Self::resolve) fills them from a scene file's `environment`,
/// else 0 degrees.
///
/// ```
/// use haarshift_relight::EnvironmentSpec;
/// use haarshift_relight::shade::LightSpec;
/// let file = EnvironmentSpec { path: "sky.hdr".into(), yaw: 30.0, pitch: 5.0, roll: 0.0 };
/// let asked = LightSpec { yaw: Some(90.0), ..LightSpec::default() };
/// let (path, angles) = asked.resolve(Some(&file)).unwrap();
/// assert_eq!((path.to_str().unwrap(), angles), ("sky.hdr", [90.0, 5.0, 0.0]));
/// assert!(asked.resolve(None).is_err()); // no environment anywhere
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightSpec {
    /// The environment map's file.
    pub env: Option<PathBuf>,
    /// Rotation about +Y, degrees.
    pub yaw: Option<f64>,
    /// Rotation about +X, degrees.
    pub pitch: Option<f64>,
    /// Rotation about +Z, degrees.
    pub roll: Option<f64>,
}

impl LightSpec {
    /// The environment's file and `[yaw, pitch, roll]` in degrees: what was asked, else the
    /// scene file's `environment`, else 0 degrees (a file is required).
    pub fn resolve(&self, scene: Option<&EnvironmentSpec>) -> Result<(PathBuf, [f64; 3])> {
        let path = match (&self.env, scene) {
            (Some(path), _) => path.clone(),
            (None, Some(spec)) => spec.path.clone(),
            (None, None) => {
                return Err(crate::Error::from(haarshift::Error::InvalidParameter {
                    name: "environment",
                    reason: "give --env ENV (the scene names none)".into(),
                }));
            }
        };
        Ok((path, self.angles(scene)))
    }

    /// `[yaw, pitch, roll]` in degrees: what was asked, else the scene file's, else 0.
    ///
    /// ```
    /// use haarshift_relight::shade::LightSpec;
    /// assert_eq!(LightSpec { roll: Some(-4.0), ..LightSpec::default() }.angles(None), [0.0, 0.0, -4.0]);
    /// ```
    pub fn angles(&self, scene: Option<&EnvironmentSpec>) -> [f64; 3] {
        let angle = |asked: Option<f64>, file: fn(&EnvironmentSpec) -> f64| {
            asked.or(scene.map(file)).unwrap_or(0.0)
        };
        [
            angle(self.yaw, |s| s.yaw),
            angle(self.pitch, |s| s.pitch),
            angle(self.roll, |s| s.roll),
        ]
    }

    /// [`resolve`](Self::resolve) with the environment read and the rotation made.
    pub fn load(&self, scene: Option<&EnvironmentSpec>) -> Result<(Environment, [f64; 3])> {
        let (path, angles) = self.resolve(scene)?;
        Ok((Environment::load(&path)?, angles))
    }
}

/// The rotation `R = Rz(roll) Ry(yaw) Rx(pitch)` of `[yaw, pitch, roll]` in degrees.
///
/// ```
/// use haarshift_relight::shade::frame::rotation;
/// assert_eq!(rotation([0.0; 3]).unwrap(), haarshift::sphere::SphereRotation::identity());
/// ```
pub fn rotation([yaw, pitch, roll]: [f64; 3]) -> Result<SphereRotation> {
    Ok(SphereRotation::from_degrees(yaw, pitch, roll)?)
}
