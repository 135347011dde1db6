//! How a relit scene is seen: the camera a caller asked for resolved against the scene file's
//! and the scene's framing, and the frame drawn ([`ViewSpec`]).

use ndarray::ArrayView2;

use super::{Background, Camera, DEFAULT_FOV, LitMesh, render};
use crate::relight::light::environment::Environment;
use crate::relight::{CameraSpec, Mesh};
use crate::sphere::{LatLongMap, SphereRotation};
use crate::{PlanarImage, Result};

/// What uncovered pixels show.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Backdrop {
    /// The lighting, rotated as the surfaces see it.
    #[default]
    Environment,
    /// A constant linear colour.
    Colour([f32; 3]),
}

/// The background's lat-long height: the environment's, at most this (a background is seen,
/// not integrated).
pub const BACKGROUND_HEIGHT: usize = 512;

/// The view of a render: the camera (asked for, else the scene file's, else one that frames
/// the scene), the image size and the backdrop.
///
/// ```
/// use haarshift::render::view::ViewSpec;
/// use haarshift::relight::{Generator, Mesh};
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let framed = ViewSpec::default().camera(None, &mesh).unwrap();
/// assert!(framed.position()[2] > 1.0); // on the +Z side, looking at the sphere
/// let asked = ViewSpec { camera: Some(([0.0, 0.0, 4.0], [0.0; 3])), ..ViewSpec::default() };
/// assert_eq!(asked.camera(None, &mesh).unwrap().position(), [0.0, 0.0, 4.0]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSpec {
    /// The camera's position and the point it looks at.
    pub camera: Option<([f64; 3], [f64; 3])>,
    /// Vertical field of view, degrees [default: the scene file's, else [`DEFAULT_FOV`]].
    pub fov: Option<f64>,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// What uncovered pixels show.
    pub backdrop: Backdrop,
}

impl Default for ViewSpec {
    /// A framing camera, 640 x 480, the environment behind.
    fn default() -> Self {
        ViewSpec {
            camera: None,
            fov: None,
            width: 640,
            height: 480,
            backdrop: Backdrop::Environment,
        }
    }
}

impl ViewSpec {
    /// The camera: the one asked for, else the scene file's `scene`, else
    /// [`Camera::framing`] of `mesh` (from 20 degrees above the horizon on the +Z side).
    pub fn camera(&self, scene: Option<&CameraSpec>, mesh: &Mesh) -> Result<Camera> {
        match (self.camera, scene) {
            (Some((position, look_at)), _) => {
                Camera::new(position, look_at, self.fov.unwrap_or(DEFAULT_FOV))
            }
            (None, Some(spec)) => {
                Camera::new(spec.position, spec.look_at, self.fov.unwrap_or(spec.fov))
            }
            (None, None) => {
                let b = mesh.bounds();
                Camera::framing(b.min, b.max, self.fov.unwrap_or(DEFAULT_FOV))
            }
        }
    }

    /// `mesh` with per-vertex `radiance` as `camera` sees it, `width x height`, in front of
    /// the backdrop: the lighting `env` rotated by `rotation` (at most
    /// [`BACKGROUND_HEIGHT`] rows), or a colour.
    ///
    /// ```
    /// use haarshift::relight::light::environment::Environment;
    /// use haarshift::render::view::{Backdrop, ViewSpec};
    /// use haarshift::relight::Generator;
    /// use haarshift::sphere::{LatLongMap, SphereRotation};
    /// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
    /// let view = ViewSpec { width: 32, height: 24, backdrop: Backdrop::Colour([0.0; 3]), ..ViewSpec::default() };
    /// let camera = view.camera(None, &mesh).unwrap();
    /// let radiance = ndarray::Array2::<f32>::ones((mesh.vertex_count(), 3));
    /// let sky = Environment::new(LatLongMap::<f64>::from_fn(8, 3, |_, o| o.fill(1.0)).unwrap());
    /// let image = view.draw(&camera, &mesh, radiance.view(), &sky, &SphereRotation::identity()).unwrap();
    /// assert_eq!((image.width(), image.height()), (32, 24));
    /// ```
    pub fn draw(
        &self,
        camera: &Camera,
        mesh: &Mesh,
        radiance: ArrayView2<'_, f32>,
        env: &Environment,
        rotation: &SphereRotation,
    ) -> Result<PlanarImage<f32>> {
        let backdrop: LatLongMap<f64>;
        let background = match self.backdrop {
            Backdrop::Environment => {
                backdrop = env.lat_long(env.map().height().min(BACKGROUND_HEIGHT), rotation)?;
                Background::Environment(&backdrop)
            }
            Backdrop::Colour(c) => Background::Colour(c),
        };
        let drawn = LitMesh {
            positions: mesh.positions(),
            triangles: mesh.triangles(),
            radiance,
        };
        render(camera, self.width, self.height, &drawn, background)
    }
}
