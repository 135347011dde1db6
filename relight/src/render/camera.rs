//! A perspective camera for the rasteriser.
//!
//! [`Camera`]: a `position`, a point to `look_at`, the world's +Y as up, and a vertical field
//! of view in degrees. The image's right is `forward x Y`, its up `right x forward`; looking
//! straight up or down (no horizontal component), the image's up is `-Z` (looking down) or
//! `+Z` (looking up). A point at camera coordinates `(x, y, z)` (`z` the depth along
//! `forward`) lands at pixel coordinates `(W / 2 + f x / z, H / 2 - f y / z)` with
//! `f = (H / 2) / tan(fov / 2)`; pixel `(row i, column j)` has its centre at `(j + 0.5, i + 0.5)`.
//! [`Camera::framing`] is the default: it looks at a bounding box's centre from 20 degrees above
//! the horizon on the +Z side, far enough that the box's bounding sphere fits the vertical field
//! of view (the narrower one of an image at least as wide as high).
//!
//! Positions and points looked at are refused beyond [`MAX_COORDINATE`] of the origin (the
//! bound on every scene coordinate), where the squared distances of the camera's geometry
//! cannot overflow.

use glam::DVec3;

use crate::scene::validate::{MAX_COORDINATE, in_range};
use crate::{Error, Result};

/// The default vertical field of view, degrees.
pub const DEFAULT_FOV: f64 = 40.0;

/// A perspective camera (see the [module docs](self) for its conventions).
///
/// ```
/// use haarshift_relight::render::camera::Camera;
/// let c = Camera::new([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 90.0).unwrap();
/// // 100 x 100 pixels: f = 50, so (1, 0.5, 0) at depth 5 lands 10 right and 5 up of the centre
/// let [x, y, depth] = c.project([1.0, 0.5, 0.0], 100, 100).unwrap();
/// assert!((x - 60.0).abs() < 1e-12 && (y - 45.0).abs() < 1e-12 && (depth - 5.0).abs() < 1e-12);
/// assert!(Camera::new([0.0; 3], [0.0; 3], 40.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    position: DVec3,
    look_at: DVec3,
    fov: f64,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
}

impl Camera {
    /// A camera at `position` looking at `look_at` (a different point), +Y up, with a vertical
    /// field of view of `fov_degrees` (above 0 and below 180).
    pub fn new(position: [f64; 3], look_at: [f64; 3], fov_degrees: f64) -> Result<Self> {
        if position.iter().chain(&look_at).any(|&v| !in_range(v)) {
            return Err(Error::parameter(
                "camera",
                format!(
                    "the position {position:?} and the point looked at {look_at:?} must be \
                     finite and within {MAX_COORDINATE:e} of the origin"
                ),
            ));
        }
        let (position, look_at) = (DVec3::from(position), DVec3::from(look_at));
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(Error::parameter(
                "fov",
                format!("{fov_degrees} degrees (expected more than 0 and less than 180)"),
            ));
        }
        let forward = normalize(look_at - position).ok_or_else(|| {
            Error::parameter("camera", "the camera cannot look at its own position")
        })?;
        let level = forward.cross(DVec3::Y);
        // Straight up or down: the image's up is -Z looking down, +Z looking up.
        let side = if level.length() > 1e-9 {
            level
        } else {
            forward.cross(DVec3::new(0.0, 0.0, forward.y.signum()))
        };
        // `forward` is a unit vector and `side` is perpendicular to it with length near 1.
        let right = normalize(side).ok_or_else(|| {
            Error::parameter("camera", "no image plane: the view direction is degenerate")
        })?;
        let up = right.cross(forward);
        Ok(Camera {
            position,
            look_at,
            fov: fov_degrees,
            right,
            up,
            forward,
        })
    }

    /// The default camera for the box `[min, max]` (see the [module docs](self)), with a vertical
    /// field of view of `fov_degrees`.
    ///
    /// ```
    /// use haarshift_relight::render::camera::{Camera, DEFAULT_FOV};
    /// let c = Camera::framing([-1.0, 0.0, -1.0], [1.0, 2.0, 1.0], DEFAULT_FOV).unwrap();
    /// assert_eq!(c.look_at(), [0.0, 1.0, 0.0]);
    /// // every corner of the box projects inside a square image
    /// for k in 0..8 {
    ///     let p = [[-1.0, 1.0][k & 1], [0.0, 2.0][(k >> 1) & 1], [-1.0, 1.0][k >> 2]];
    ///     let [x, y, _] = c.project(p, 64, 64).unwrap();
    ///     assert!((0.0..64.0).contains(&x) && (0.0..64.0).contains(&y));
    /// }
    /// ```
    pub fn framing(min: [f64; 3], max: [f64; 3], fov_degrees: f64) -> Result<Self> {
        let (min, max) = (DVec3::from(min), DVec3::from(max));
        let centre = 0.5 * (min + max);
        let radius = 0.5 * (max - min).length();
        let radius = if radius > 0.0 { radius } else { 1.0 };
        let half = 0.5 * fov_degrees.to_radians();
        let distance = radius / half.sin();
        let (s, c) = 20f64.to_radians().sin_cos();
        let position = [centre.x, centre.y + distance * s, centre.z + distance * c];
        Camera::new(position, centre.to_array(), fov_degrees)
    }

    /// The camera moved `degrees` about the vertical axis through the point it looks at (a
    /// turntable seen from a circling viewer; positive turns go from +Z toward +X, the
    /// direction of increasing azimuth).
    ///
    /// ```
    /// use haarshift_relight::render::camera::Camera;
    /// let c = Camera::new([0.0, 1.0, 5.0], [0.0, 1.0, 0.0], 40.0).unwrap();
    /// let p = c.orbited(90.0).unwrap().position();
    /// assert!((p[0] - 5.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12 && p[2].abs() < 1e-12);
    /// assert_eq!(c.orbited(0.0).unwrap().position(), c.position());
    /// ```
    pub fn orbited(&self, degrees: f64) -> Result<Camera> {
        if !degrees.is_finite() {
            return Err(Error::parameter(
                "orbit",
                format!("{degrees} degrees is not an angle"),
            ));
        }
        let (s, c) = degrees.to_radians().sin_cos();
        let (d, at) = (self.position - self.look_at, self.look_at);
        let turned = [
            at.x + c * d.x + s * d.z,
            self.position.y,
            at.z - s * d.x + c * d.z,
        ];
        Camera::new(turned, at.to_array(), self.fov)
    }

    /// The camera's position.
    pub fn position(&self) -> [f64; 3] {
        self.position.to_array()
    }

    /// The point looked at.
    pub fn look_at(&self) -> [f64; 3] {
        self.look_at.to_array()
    }

    /// The vertical field of view, degrees.
    pub fn fov(&self) -> f64 {
        self.fov
    }

    /// The focal length in pixels of an image `height` pixels high.
    pub(super) fn focal(&self, height: usize) -> f64 {
        0.5 * height as f64 / (0.5 * self.fov.to_radians()).tan()
    }

    /// Camera coordinates `(x, y, depth)` of a world point.
    pub(super) fn camera_coordinates(&self, p: [f64; 3]) -> [f64; 3] {
        let d = DVec3::from(p) - self.position;
        [d.dot(self.right), d.dot(self.up), d.dot(self.forward)]
    }

    /// The near plane's distance for `fraction` of the distance to the point looked at.
    pub(super) fn near(&self, fraction: f64) -> f64 {
        fraction * (self.look_at - self.position).length()
    }

    /// The pixel coordinates `(x, y)` and depth of a world point in a `width x height` image,
    /// or `None` when it is not in front of the camera.
    pub fn project(&self, p: [f64; 3], width: usize, height: usize) -> Option<[f64; 3]> {
        let [x, y, z] = self.camera_coordinates(p);
        (z > 0.0).then(|| {
            let f = self.focal(height);
            [
                0.5 * width as f64 + f * x / z,
                0.5 * height as f64 - f * y / z,
                z,
            ]
        })
    }

    /// The unit direction (world) of the ray through pixel coordinates `(x, y)`.
    pub fn ray(&self, x: f64, y: f64, width: usize, height: usize) -> [f64; 3] {
        self.ray_at_focal(self.focal(height), x, y, width, height)
    }

    /// [`ray`](Self::ray) with the focal length `f` ([`focal`](Self::focal)) computed once
    /// for a whole image.
    #[inline]
    pub(super) fn ray_at_focal(
        &self,
        f: f64,
        x: f64,
        y: f64,
        width: usize,
        height: usize,
    ) -> [f64; 3] {
        let (a, b) = ((x - 0.5 * width as f64) / f, (0.5 * height as f64 - y) / f);
        let d = self.forward + a * self.right + b * self.up;
        // At least as long as the unit forward axis, which it is perpendicular to the rest of.
        (d / d.length()).to_array()
    }
}

/// `a / |a|` (a division, not a multiplication by the reciprocal, so that the bits are those
/// of every earlier render), or `None` for a vector of no length or of one that overflows.
fn normalize(a: DVec3) -> Option<DVec3> {
    let n = a.length();
    (n > 0.0 && n.is_finite()).then(|| a / n)
}
