//! The environment behind a rendered image: what a pixel that no triangle covers shows.
//!
//! The pixel whose centre's ray (world, unit) is `d` shows `f(R d)`: the environment `f` (a
//! lat-long map, bilinear between its pixel centres, continued over the seam and the poles)
//! turned by `R`, as the surfaces see it (the sphere module's convention:
//! [`reference`](haarshift::sphere::reference::reference) and
//! [`Environment::lat_long`](crate::light::environment::Environment::lat_long) turn a
//! map the same way).
//!
//! Finding where a pixel's ray meets the map (the ray, a square root, two arctangents) costs
//! several times the lookup itself, and depends only on the camera, the image size and the
//! map's height: a [`SkyLookup`] holds it for every pixel (the continuous grid position, two
//! f64 a pixel, row-major), prepared once; a frame then reads it and four texels. A turn about
//! the vertical by whole columns of the map (an animation's step, see
//! [`SphereRotation::whole_column_yaw`]) moves every pixel's place by the same whole columns,
//! so the lookup serves every such frame; any other turn finds each pixel's place anew from
//! `R d`.
//!
//! The values are those of `map.bilinear` along `R d`, bit for bit; for a whole-column yaw by
//! `k`, those of `map.roll_columns(k)` along `d` (what the turned map of
//! `Environment::lat_long` shows).

use super::camera::Camera;
use crate::{Error, Result};
use haarshift::sphere::latlong::angles;
use haarshift::sphere::{LatLongMap, SphereRotation};
use rayon::prelude::*;

/// Where each pixel centre's ray meets a lat-long map of one height, for one camera and image
/// size (see the [module docs](self)).
///
/// ```
/// use haarshift_relight::render::{Background, Camera, LitMesh, Sky, SkyLookup, render};
/// use haarshift::sphere::{LatLongMap, SphereRotation};
/// use ndarray::Array2;
/// let map = LatLongMap::<f64>::from_fn(16, 3, |d, out| out.copy_from_slice(&d)).unwrap();
/// let camera = Camera::new([0.0, 0.0, 4.0], [0.0; 3], 40.0).unwrap();
/// let lookup = SkyLookup::new(&camera, 24, 16, &map).unwrap();
/// let (positions, radiance) = (Array2::<f64>::zeros((0, 3)), Array2::<f32>::zeros((0, 3)));
/// let mesh = LitMesh { positions: positions.view(), triangles: &[], radiance: radiance.view() };
/// let turn = SphereRotation::from_degrees(90.0, 0.0, 0.0).unwrap(); // 8 of 32 columns
/// let sky = Sky { map: &map, rotation: &turn, lookup: Some(&lookup) };
/// let image = render(&camera, 24, 16, &mesh, Background::Sky(sky)).unwrap();
/// let rolled = map.roll_columns(8);
/// assert_eq!(image, render(&camera, 24, 16, &mesh, Background::Environment(&rolled)).unwrap());
/// // a lookup is made for one camera, image size and map height
/// assert!(render(&camera, 24, 8, &mesh, Background::Sky(sky)).is_err());
/// ```
#[derive(Clone, Debug)]
pub struct SkyLookup {
    camera: Camera,
    width: usize,
    height: usize,
    map_height: usize,
    /// Per pixel, row-major: the continuous grid position `(row, column)` of its ray.
    grid: Vec<[f64; 2]>,
}

impl SkyLookup {
    /// The lookup of every pixel of a `width x height` image seen by `camera`, into maps as
    /// high as `map` (1 to 32768 pixels wide and high, as [`render`](super::render) draws).
    pub fn new(
        camera: &Camera,
        width: usize,
        height: usize,
        map: &LatLongMap<f64>,
    ) -> Result<Self> {
        super::raster::check_size(width, height)?;
        let focal = camera.focal(height);
        let mut grid = vec![[0.0; 2]; width * height];
        grid.par_chunks_mut(width).enumerate().for_each(|(i, row)| {
            for (j, out) in row.iter_mut().enumerate() {
                let d = camera.ray_at_focal(focal, j as f64 + 0.5, i as f64 + 0.5, width, height);
                let (theta, phi) = angles(d);
                let (y, x) = map.grid_position(theta, phi);
                *out = [y, x];
            }
        });
        Ok(SkyLookup {
            camera: *camera,
            width,
            height,
            map_height: map.height(),
            grid,
        })
    }

    /// Whether this lookup was made for `camera`, a `width x height` image and maps as high
    /// as `map`.
    pub fn fits(
        &self,
        camera: &Camera,
        width: usize,
        height: usize,
        map: &LatLongMap<f64>,
    ) -> bool {
        self.camera == *camera
            && (self.width, self.height, self.map_height) == (width, height, map.height())
    }
}

/// The environment `map` turned by `rotation` behind the image, each pixel's place in it read
/// from `lookup` (made for the render's camera, image size and `map`'s height) or, without
/// one, found from its ray: see the [module docs](self).
#[derive(Clone, Copy, Debug)]
pub struct Sky<'a> {
    /// The environment (1 channel: gray; 3 or more: the first three).
    pub map: &'a LatLongMap<f64>,
    /// How it is turned: the pixel with ray `d` shows `map` at `rotation.apply(d)`.
    pub rotation: &'a SphereRotation,
    /// Each pixel's place in a map as high as `map` (none: found from its ray, for one
    /// frame). A turn other than a whole-column yaw finds it from the ray in any case.
    pub lookup: Option<&'a SkyLookup>,
}

/// How a render finds the background of a pixel, checked and ready.
pub(super) enum Behind<'a> {
    /// A constant colour.
    Colour([f32; 3]),
    /// `map` with its columns rolled by `roll`, at each pixel's `place`.
    Map {
        map: &'a LatLongMap<f64>,
        roll: usize,
        place: Place<'a>,
    },
}

/// Where a pixel's ray meets the map.
pub(super) enum Place<'a> {
    /// Read from a lookup.
    Lookup(&'a [[f64; 2]]),
    /// Found anew from the pixel's ray, turned by `rotation` (none: as it is).
    Ray {
        camera: &'a Camera,
        focal: f64,
        rotation: Option<&'a SphereRotation>,
    },
}

impl<'a> Behind<'a> {
    /// `background` behind a `width x height` image seen by `camera`, or why it cannot be.
    pub(super) fn new(
        background: super::Background<'a>,
        camera: &'a Camera,
        width: usize,
        height: usize,
    ) -> Result<Self> {
        use super::Background;
        let (map, rotation, lookup) = match background {
            Background::Colour(c) => return Ok(Behind::Colour(c)),
            Background::Environment(map) => (map, None, None),
            Background::Sky(sky) => (sky.map, Some(sky.rotation), sky.lookup),
        };
        if !matches!(map.channels(), 1 | 3..=64) {
            return Err(Error::parameter(
                "background",
                format!(
                    "an environment of {} channels (expected 1 for gray, or 3 to 64)",
                    map.channels()
                ),
            ));
        }
        if let Some(lookup) = lookup
            && !lookup.fits(camera, width, height, map)
        {
            return Err(Error::parameter(
                "background",
                format!(
                    "a sky lookup made for a {} x {} image into maps {} high, another camera or \
                     both, drawn at {width} x {height} into a map {} high",
                    lookup.width,
                    lookup.height,
                    lookup.map_height,
                    map.height()
                ),
            ));
        }
        let ray = |rotation| Place::Ray {
            camera,
            focal: camera.focal(height),
            rotation,
        };
        // A whole-column yaw (or none) moves the unturned ray's place by whole columns.
        let roll = rotation.map_or(Some(0), |r| r.whole_column_yaw(map.width()));
        let place = match (roll, lookup) {
            (Some(_), Some(lookup)) => Place::Lookup(&lookup.grid),
            (Some(_), None) => ray(None),
            (None, _) => ray(rotation),
        };
        Ok(Behind::Map {
            map,
            roll: roll.unwrap_or(0),
            place,
        })
    }

    /// The background of pixel `(i, j)` of a `width x height` image.
    #[inline]
    pub(super) fn at(&self, i: usize, j: usize, width: usize, height: usize) -> [f32; 3] {
        let (map, roll, place) = match self {
            Behind::Colour(c) => return *c,
            Behind::Map { map, roll, place } => (map, *roll, place),
        };
        let (y, x) = match *place {
            Place::Lookup(grid) => {
                let [y, x] = grid[i * width + j];
                (y, x)
            }
            Place::Ray {
                camera,
                focal,
                rotation,
            } => {
                let d = camera.ray_at_focal(focal, j as f64 + 0.5, i as f64 + 0.5, width, height);
                let (theta, phi) = angles(rotation.map_or(d, |r| r.apply(d)));
                map.grid_position(theta, phi)
            }
        };
        if map.channels() < 3 {
            let [v] = map.bilinear_grid::<1>(y, x, roll);
            [v as f32; 3]
        } else {
            let [r, g, b] = map.bilinear_grid::<3>(y, x, roll);
            [r as f32, g as f32, b as f32]
        }
    }
}

#[cfg(test)]
#[path = "sky_tests.rs"]
mod tests;
