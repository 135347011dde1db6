//! How a relit scene is seen: the camera a caller asked for resolved against the scene file's
//! and the scene's framing, and the frame drawn ([`ViewSpec`]), or frame after frame
//! ([`Frames`]).

use ndarray::ArrayView2;

use super::{Background, Camera, DEFAULT_FOV, LitMesh, Sky, SkyLookup, render};
use crate::Result;
use crate::light::environment::Environment;
use crate::{CameraSpec, Mesh};
use haarshift::PlanarImage;
use haarshift::sphere::SphereRotation;

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
/// use haarshift_relight::render::view::ViewSpec;
/// use haarshift_relight::{Generator, Mesh};
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
    /// the backdrop: the lighting `env` turned by `rotation` (its copy at most
    /// [`BACKGROUND_HEIGHT`] rows high, seen along each pixel's ray: see
    /// [`sky`](super::sky)), or a colour. One frame of [`Frames`].
    ///
    /// ```
    /// use haarshift_relight::light::environment::Environment;
    /// use haarshift_relight::render::view::{Backdrop, ViewSpec};
    /// use haarshift_relight::Generator;
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
        self.draw_keeping(camera, mesh, radiance, env, rotation, None)
    }

    /// [`draw`](Self::draw), each pixel's place in the environment read from the lookup in
    /// `kept` when there is one and the lighting turns by whole columns (the lookup made
    /// first, or anew for another camera, image size or map height, and left there), else
    /// found from its ray.
    fn draw_keeping(
        &self,
        camera: &Camera,
        mesh: &Mesh,
        radiance: ArrayView2<'_, f32>,
        env: &Environment,
        rotation: &SphereRotation,
        kept: Option<&mut Option<SkyLookup>>,
    ) -> Result<PlanarImage<f32>> {
        let (width, height) = (self.width, self.height);
        let drawn = LitMesh {
            positions: mesh.positions(),
            triangles: mesh.triangles(),
            radiance,
        };
        let map = match self.backdrop {
            Backdrop::Colour(c) => {
                return render(camera, width, height, &drawn, Background::Colour(c));
            }
            Backdrop::Environment => env.downsampled(env.map().height().min(BACKGROUND_HEIGHT))?,
        };
        // Only a whole-column yaw reads a lookup (see `sky`).
        let lookup = match kept {
            Some(kept) if rotation.whole_column_yaw(map.width()).is_some() => {
                let lookup = match kept.take() {
                    Some(lookup) if lookup.fits(camera, width, height, &map) => lookup,
                    _ => SkyLookup::new(camera, width, height, &map)?,
                };
                Some(&*kept.insert(lookup))
            }
            _ => None,
        };
        let sky = Sky {
            map: &map,
            rotation,
            lookup,
        };
        render(camera, width, height, &drawn, Background::Sky(sky))
    }
}

/// A view drawn frame after frame: [`ViewSpec::draw`], with each pixel's place in the
/// environment ([`SkyLookup`]) prepared for the first frame the lighting turns by whole
/// columns (or not at all) and kept while the camera, the image size and the backdrop's
/// height stay (an animation's frames turn the lighting, or move the camera and prepare it
/// anew).
///
/// ```
/// use haarshift_relight::light::environment::Environment;
/// use haarshift_relight::render::view::{Frames, ViewSpec};
/// use haarshift_relight::Generator;
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// let mesh = Generator::Sphere { cells: 2 }.mesh().unwrap();
/// let view = ViewSpec { width: 32, height: 24, ..ViewSpec::default() };
/// let camera = view.camera(None, &mesh).unwrap();
/// let radiance = ndarray::Array2::<f32>::ones((mesh.vertex_count(), 3));
/// let env = Environment::new(LatLongMap::<f64>::from_fn(8, 3, |d, o| o.fill(1.0 + d[0])).unwrap());
/// let mut frames = Frames::new(view);
/// for yaw in [0.0, 45.0, 10.0] {
///     let turn = SphereRotation::from_degrees(yaw, 0.0, 0.0).unwrap();
///     let image = frames.draw(&camera, &mesh, radiance.view(), &env, &turn).unwrap();
///     assert_eq!(image, view.draw(&camera, &mesh, radiance.view(), &env, &turn).unwrap());
/// }
/// ```
#[derive(Clone, Debug)]
pub struct Frames {
    view: ViewSpec,
    lookup: Option<SkyLookup>,
}

impl Frames {
    /// Frames of `view`, nothing prepared yet.
    pub fn new(view: ViewSpec) -> Self {
        Frames { view, lookup: None }
    }

    /// One frame, as [`ViewSpec::draw`] draws it.
    pub fn draw(
        &mut self,
        camera: &Camera,
        mesh: &Mesh,
        radiance: ArrayView2<'_, f32>,
        env: &Environment,
        rotation: &SphereRotation,
    ) -> Result<PlanarImage<f32>> {
        let view = self.view;
        view.draw_keeping(
            camera,
            mesh,
            radiance,
            env,
            rotation,
            Some(&mut self.lookup),
        )
    }
}
