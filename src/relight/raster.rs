//! A software rasteriser for meshes with per-vertex radiance: perspective camera, z-buffer,
//! perspective-correct Gouraud interpolation, the environment (or a colour) as background,
//! exposure and sRGB for 8-bit PNG, linear f32 for OpenEXR.
//!
//! # Camera
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
//! # Rasterisation
//!
//! Triangles are clipped in camera space against the near plane (`1e-3` of the distance from
//! the camera to the point looked at) and, when they would project beyond a guard band of
//! `2^21` pixels, against its sides; the pieces are fanned into triangles. Coverage is decided
//! on vertices snapped to `1/256` pixel with exact integer edge functions and the **top-left
//! fill rule** (a pixel centre on an edge belongs to the triangle whose top or left edge it
//! is), so a pixel centre on an edge shared by two triangles is drawn exactly once. Values are
//! interpolated from the unsnapped positions, perspective-correctly: `1/z` and `radiance / z`
//! are linear in screen space, so a linear function of the 3D position is reproduced exactly
//! at every pixel centre. Both faces of a triangle are drawn. The z-buffer keeps the nearest
//! fragment; of two at the same depth, the earlier triangle.
//!
//! The image is cut into bands of rows rendered in parallel with rayon, each band going over
//! the triangles whose bounding box reaches it, in the mesh's order (so the result does not
//! depend on the thread count). Pixels no triangle covers show the [`Background`]: a colour,
//! or the environment seen along the pixel centre's ray (bilinear lookup in the lat-long map,
//! the sphere module's direction convention).
//!
//! # Output
//!
//! [`render`] returns linear radiance as an f32 RGB [`PlanarImage`]. [`write_render`] writes
//! `.exr` as it is (linear f32) and `.png` as 8-bit sRGB after an exposure of `2^stops`
//! ([`to_srgb8`], [`srgb_encode`]), atomically, through [`crate::io`].

use std::ops::Range;
use std::path::Path;

use ndarray::{Array3, ArrayView2, Axis};
use rayon::prelude::*;

use crate::io::{FileFormat, WriteOptions, write_image};
use crate::sphere::LatLongMap;
use crate::sphere::latlong::angles;
use crate::{Channels, Error, PlanarImage, Result, SampleDepth};

/// The default vertical field of view, degrees.
pub const DEFAULT_FOV: f64 = 40.0;

/// The near plane's distance as a fraction of the camera's distance to the point looked at.
const NEAR_FRACTION: f64 = 1e-3;

/// Sub-pixel steps per pixel of the snapped vertex coordinates.
const SUBPIXEL: f64 = 256.0;

/// Half-width of the guard band in pixels: vertices projecting further out are clipped away
/// first, which keeps the integer edge functions far from overflow.
const GUARD: f64 = (1u64 << 21) as f64;

/// Rows per band of parallel work.
const BAND_ROWS: usize = 16;

/// A perspective camera (see the [module docs](self) for its conventions).
///
/// ```
/// use haarshift::relight::raster::Camera;
/// let c = Camera::new([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 90.0).unwrap();
/// // 100 x 100 pixels: f = 50, so (1, 0.5, 0) at depth 5 lands 10 right and 5 up of the centre
/// let [x, y, depth] = c.project([1.0, 0.5, 0.0], 100, 100).unwrap();
/// assert!((x - 60.0).abs() < 1e-12 && (y - 45.0).abs() < 1e-12 && (depth - 5.0).abs() < 1e-12);
/// assert!(Camera::new([0.0; 3], [0.0; 3], 40.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    position: [f64; 3],
    look_at: [f64; 3],
    fov: f64,
    right: [f64; 3],
    up: [f64; 3],
    forward: [f64; 3],
}

impl Camera {
    /// A camera at `position` looking at `look_at` (a different point), +Y up, with a vertical
    /// field of view of `fov_degrees` (above 0 and below 180).
    pub fn new(position: [f64; 3], look_at: [f64; 3], fov_degrees: f64) -> Result<Self> {
        // In range (relight::validate): the forward axis is then a difference whose square
        // cannot overflow, so it normalises.
        let limit = super::validate::MAX_COORDINATE;
        if position.iter().chain(&look_at).any(|v| !(v.abs() <= limit)) {
            return Err(Error::parameter(
                "camera",
                format!(
                    "the position and the point looked at must be finite and within {limit:e} of the origin"
                ),
            ));
        }
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(Error::parameter(
                "fov",
                format!("{fov_degrees} degrees (expected more than 0 and less than 180)"),
            ));
        }
        let forward = normalize(sub(look_at, position)).ok_or_else(|| {
            Error::parameter("camera", "the camera cannot look at its own position")
        })?;
        let level = cross(forward, [0.0, 1.0, 0.0]);
        // Straight up or down: the image's up is -Z looking down, +Z looking up.
        let side = if norm(level) > 1e-9 {
            level
        } else {
            cross(forward, [0.0, 0.0, forward[1].signum()])
        };
        let right = normalize(side).expect("not parallel to the forward axis");
        let up = cross(right, forward);
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
    /// use haarshift::relight::raster::{Camera, DEFAULT_FOV};
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
        let centre = [0, 1, 2].map(|k| 0.5 * (min[k] + max[k]));
        let radius = 0.5 * norm(sub(max, min));
        let radius = if radius > 0.0 { radius } else { 1.0 };
        let half = 0.5 * fov_degrees.to_radians();
        let distance = radius / half.sin();
        let (s, c) = 20f64.to_radians().sin_cos();
        let position = [
            centre[0],
            centre[1] + distance * s,
            centre[2] + distance * c,
        ];
        Camera::new(position, centre, fov_degrees)
    }

    /// The camera moved `degrees` about the vertical axis through the point it looks at (a
    /// turntable seen from a circling viewer; positive turns go from +Z toward +X, the
    /// direction of increasing azimuth).
    ///
    /// ```
    /// use haarshift::relight::raster::Camera;
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
        let d = sub(self.position, self.look_at);
        let turned = [
            self.look_at[0] + c * d[0] + s * d[2],
            self.position[1],
            self.look_at[2] - s * d[0] + c * d[2],
        ];
        Camera::new(turned, self.look_at, self.fov)
    }

    /// The camera's position.
    pub fn position(&self) -> [f64; 3] {
        self.position
    }

    /// The point looked at.
    pub fn look_at(&self) -> [f64; 3] {
        self.look_at
    }

    /// The vertical field of view, degrees.
    pub fn fov(&self) -> f64 {
        self.fov
    }

    /// The focal length in pixels of an image `height` pixels high.
    fn focal(&self, height: usize) -> f64 {
        0.5 * height as f64 / (0.5 * self.fov.to_radians()).tan()
    }

    /// Camera coordinates `(x, y, depth)` of a world point.
    fn camera_coordinates(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.position);
        [dot(d, self.right), dot(d, self.up), dot(d, self.forward)]
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
        let f = self.focal(height);
        let (a, b) = ((x - 0.5 * width as f64) / f, (0.5 * height as f64 - y) / f);
        let d = [0, 1, 2].map(|k| self.forward[k] + a * self.right[k] + b * self.up[k]);
        normalize(d).expect("the forward axis has unit length")
    }
}

/// What pixels that no triangle covers show.
#[derive(Clone, Copy, Debug)]
pub enum Background<'a> {
    /// A constant linear RGB colour.
    Colour([f32; 3]),
    /// The environment along each pixel's ray (1 channel: gray; 3 or more: the first three).
    Environment(&'a LatLongMap<f64>),
}

/// A mesh to draw: `positions` `(V, 3)`, triangles indexing them, and the linear RGB radiance
/// leaving each vertex, `(V, 3)`.
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a> {
    /// Vertex positions, world space.
    pub positions: ArrayView2<'a, f64>,
    /// Triangles as vertex indices.
    pub triangles: &'a [[u32; 3]],
    /// Outgoing radiance per vertex, linear RGB.
    pub radiance: ArrayView2<'a, f32>,
}

impl Mesh<'_> {
    /// Checks shapes, indices and values.
    fn check(&self) -> Result<()> {
        let (v, c) = self.positions.dim();
        if c != 3 || self.radiance.dim() != (v, 3) {
            return Err(Error::shape(
                &[v, c, self.radiance.dim().0, self.radiance.dim().1],
                "a mesh to draw has positions (V, 3) and radiance (V, 3)",
            ));
        }
        crate::ensure_finite(&self.positions)?;
        crate::ensure_finite(&self.radiance)?;
        if let Some((t, tri)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&i| i as usize >= v))
        {
            return Err(Error::parameter(
                "triangles",
                format!("triangle {t} is {tri:?}, but there are {v} vertices"),
            ));
        }
        Ok(())
    }
}

/// Draws `mesh` as seen by `camera` into a `width x height` image of linear radiance (f32 RGB,
/// depth [`SampleDepth::F32`]); see the [module docs](self).
///
/// ```
/// use haarshift::relight::raster::{Background, Camera, Mesh, render};
/// use ndarray::array;
/// let positions = array![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
/// let radiance = array![[1.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mesh = Mesh { positions: positions.view(), triangles: &[[0, 1, 2]], radiance: radiance.view() };
/// let camera = Camera::new([0.0, 0.0, 4.0], [0.0; 3], 40.0).unwrap();
/// let image = render(&camera, 32, 32, &mesh, Background::Colour([0.5; 3])).unwrap();
/// let centre: f32 = (0..3).map(|c| image.plane(c)[[16, 16]]).sum();
/// assert!((centre - 1.0).abs() < 1e-5); // the three weights add up to one
/// assert_eq!(image.plane(0)[[0, 0]], 0.5); // a corner shows the background
/// ```
pub fn render(
    camera: &Camera,
    width: usize,
    height: usize,
    mesh: &Mesh<'_>,
    background: Background<'_>,
) -> Result<PlanarImage<f32>> {
    if width == 0 || height == 0 || width > 1 << 15 || height > 1 << 15 {
        return Err(Error::shape(
            &[height, width],
            "an image is 1 to 32768 pixels wide and high",
        ));
    }
    if let Background::Environment(env) = background
        && !matches!(env.channels(), 1 | 3..=64)
    {
        return Err(Error::parameter(
            "background",
            format!(
                "an environment of {} channels (expected 1 for gray, or 3 to 64)",
                env.channels()
            ),
        ));
    }
    mesh.check()?;
    let setups = setup_triangles(camera, width, height, mesh);
    let bands = height.div_ceil(BAND_ROWS);
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (k, s) in setups.iter().enumerate() {
        for list in &mut binned[s.rows.start / BAND_ROWS..s.rows.end.div_ceil(BAND_ROWS)] {
            list.push(k as u32);
        }
    }
    // (row, column, channel) radiance; rows in bands.
    let mut pixels = Array3::<f32>::zeros((height, width, 3));
    pixels
        .axis_chunks_iter_mut(Axis(0), BAND_ROWS)
        .into_par_iter()
        .zip(binned)
        .enumerate()
        .for_each(|(b, (mut band, list))| {
            let rows = b * BAND_ROWS..(b * BAND_ROWS + band.dim().0);
            let out = band.as_slice_mut().expect("standard layout");
            let mut depth = vec![0.0f64; rows.len() * width];
            let mut covered = vec![false; rows.len() * width];
            for &k in &list {
                rasterize(&setups[k as usize], rows.clone(), width, |i, j, w, rgb| {
                    let p = (i - rows.start) * width + j;
                    if !covered[p] || w > depth[p] {
                        covered[p] = true;
                        depth[p] = w;
                        out[3 * p..3 * p + 3].copy_from_slice(&rgb);
                    }
                });
            }
            for (p, px) in out.chunks_exact_mut(3).enumerate() {
                if !covered[p] {
                    let (i, j) = (rows.start + p / width, p % width);
                    px.copy_from_slice(&background_at(camera, width, height, i, j, background));
                }
            }
        });
    let planes = pixels
        .permuted_axes([2, 0, 1])
        .as_standard_layout()
        .into_owned();
    PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32)
}

/// The background seen through the centre of pixel `(i, j)`.
fn background_at(
    camera: &Camera,
    width: usize,
    height: usize,
    i: usize,
    j: usize,
    background: Background<'_>,
) -> [f32; 3] {
    match background {
        Background::Colour(c) => c,
        Background::Environment(env) => {
            let d = camera.ray(j as f64 + 0.5, i as f64 + 0.5, width, height);
            let (theta, phi) = angles(d);
            let mut v = [0.0f64; 64];
            let v = &mut v[..env.channels()];
            env.bilinear(theta, phi, v);
            if v.len() < 3 {
                [v[0] as f32; 3]
            } else {
                [v[0] as f32, v[1] as f32, v[2] as f32]
            }
        }
    }
}

/// A triangle ready to rasterise: snapped vertices, interpolation planes, the rows it spans.
#[derive(Clone, Debug)]
struct Setup {
    /// Vertices in sub-pixel units, oriented so that the edge functions are positive inside.
    snapped: [[i64; 2]; 3],
    /// `(A, B, C)` of the screen-space planes of `1/z` and `radiance / z` (R, G, B), in pixels.
    planes: [[f64; 3]; 4],
    /// The pixel rows and columns whose centres it may cover.
    rows: Range<usize>,
    cols: Range<usize>,
}

/// A vertex in camera space with its radiance: `(x, y, z, r, g, b)`.
type ClipVertex = [f64; 6];

/// Every triangle of `mesh` clipped, projected, snapped and set up, in the mesh's order.
fn setup_triangles(camera: &Camera, width: usize, height: usize, mesh: &Mesh<'_>) -> Vec<Setup> {
    let near = NEAR_FRACTION * norm(sub(camera.look_at, camera.position));
    let f = camera.focal(height);
    let (cx, cy) = (0.5 * width as f64, 0.5 * height as f64);
    let vertex = |i: u32| -> ClipVertex {
        let i = i as usize;
        let p = [0, 1, 2].map(|k| mesh.positions[[i, k]]);
        let [x, y, z] = camera.camera_coordinates(p);
        let r = mesh.radiance.row(i);
        [x, y, z, r[0] as f64, r[1] as f64, r[2] as f64]
    };
    mesh.triangles
        .par_iter()
        .fold(Vec::new, |mut out, tri| {
            let mut poly = vec![vertex(tri[0]), vertex(tri[1]), vertex(tri[2])];
            if poly.iter().any(|v| v[2] < near) {
                poly = clip(&poly, |v| v[2] - near);
            }
            let outside =
                |v: &ClipVertex| (f * v[0]).abs() > GUARD * v[2] || (f * v[1]).abs() > GUARD * v[2];
            if poly.iter().any(outside) {
                let g = GUARD / f;
                poly = clip(&poly, |v| g * v[2] - v[0]);
                poly = clip(&poly, |v| g * v[2] + v[0]);
                poly = clip(&poly, |v| g * v[2] - v[1]);
                poly = clip(&poly, |v| g * v[2] + v[1]);
            }
            let screen: Vec<[f64; 6]> = poly
                .iter()
                .map(|v| {
                    let w = 1.0 / v[2];
                    [
                        cx + f * v[0] * w,
                        cy - f * v[1] * w,
                        w,
                        v[3] * w,
                        v[4] * w,
                        v[5] * w,
                    ]
                })
                .collect();
            for k in 1..screen.len().saturating_sub(1) {
                if let Some(s) = setup([screen[0], screen[k], screen[k + 1]], width, height) {
                    out.push(s);
                }
            }
            out
        })
        .flatten()
        .collect()
}

/// The part of a convex polygon where `inside(v) >= 0` (Sutherland-Hodgman, one plane), with
/// the attributes interpolated linearly along cut edges.
fn clip(poly: &[ClipVertex], inside: impl Fn(&ClipVertex) -> f64) -> Vec<ClipVertex> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for (k, a) in poly.iter().enumerate() {
        let b = &poly[(k + 1) % poly.len()];
        let (da, db) = (inside(a), inside(b));
        if da >= 0.0 {
            out.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(std::array::from_fn(|i| a[i] + t * (b[i] - a[i])));
        }
    }
    out
}

/// A screen-space triangle `(x, y, 1/z, r/z, g/z, b/z)` set up for [`rasterize`], or `None`
/// when it has no area or covers no pixel centre of the image.
fn setup(v: [[f64; 6]; 3], width: usize, height: usize) -> Option<Setup> {
    let snap = |p: &[f64; 6]| {
        [
            (p[0] * SUBPIXEL).round() as i64,
            (p[1] * SUBPIXEL).round() as i64,
        ]
    };
    let mut s = [snap(&v[0]), snap(&v[1]), snap(&v[2])];
    let area = edge(s[0], s[1], s[2]);
    if area == 0 {
        return None;
    }
    if area < 0 {
        s.swap(1, 2);
    }
    // Pixel rows/columns whose centres (k + 0.5) can lie inside the bounding box.
    let span = |k: usize, limit: usize| {
        let lo = s.iter().map(|p| p[k]).min().expect("three");
        let hi = s.iter().map(|p| p[k]).max().expect("three");
        let first = ((lo as f64 / SUBPIXEL - 0.5).ceil().max(0.0)) as usize;
        let last = ((hi as f64 / SUBPIXEL - 0.5).floor() + 1.0).clamp(0.0, limit as f64) as usize;
        first.min(limit)..last
    };
    let (cols, rows) = (span(0, width), span(1, height));
    if rows.is_empty() || cols.is_empty() {
        return None;
    }
    // Planes through the unsnapped vertices: q(x, y) = A x + B y + C.
    let (x0, y0) = (v[0][0], v[0][1]);
    let (x1, y1) = (v[1][0] - x0, v[1][1] - y0);
    let (x2, y2) = (v[2][0] - x0, v[2][1] - y0);
    let det = x1 * y2 - x2 * y1;
    if det == 0.0 {
        return None;
    }
    let planes = std::array::from_fn(|q| {
        let (q0, q1, q2) = (
            v[0][q + 2],
            v[1][q + 2] - v[0][q + 2],
            v[2][q + 2] - v[0][q + 2],
        );
        let a = (q1 * y2 - q2 * y1) / det;
        let b = (x1 * q2 - x2 * q1) / det;
        [a, b, q0 - a * x0 - b * y0]
    });
    Some(Setup {
        snapped: s,
        planes,
        rows,
        cols,
    })
}

/// The edge function of `a -> b` at `p`: twice the signed area of `(a, b, p)`, positive when
/// `p` is on the inside of a triangle oriented as [`Setup::snapped`] is.
#[inline]
fn edge(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Whether `a -> b` is a top edge (horizontal, the inside below it, y pointing down) or a left
/// edge (the inside to its right), for the orientation of [`Setup::snapped`].
#[inline]
fn top_left(a: [i64; 2], b: [i64; 2]) -> bool {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    dy < 0 || (dy == 0 && dx > 0)
}

/// Calls `fragment(row, column, 1/z, radiance)` for every pixel centre in `rows` that the
/// triangle covers, by the top-left rule.
fn rasterize(
    s: &Setup,
    rows: Range<usize>,
    width: usize,
    mut fragment: impl FnMut(usize, usize, f64, [f32; 3]),
) {
    let rows = rows.start.max(s.rows.start)..rows.end.min(s.rows.end);
    let cols = s.cols.start..s.cols.end.min(width);
    if rows.is_empty() || cols.is_empty() {
        return;
    }
    let [a, b, c] = s.snapped;
    let edges = [(b, c), (c, a), (a, b)];
    // A pixel centre on a non-top-left edge is outside: require e >= 1 there.
    let bias = edges.map(|(p, q)| if top_left(p, q) { 0 } else { -1 });
    let half = (SUBPIXEL / 2.0) as i64;
    let step = SUBPIXEL as i64;
    for i in rows {
        let py = i as i64 * step + half;
        let x0 = cols.start as i64 * step + half;
        let mut e = [0usize, 1, 2].map(|k| edge(edges[k].0, edges[k].1, [x0, py]) + bias[k]);
        let dx = edges.map(|(p, q)| -(q[1] - p[1]) * step);
        let y = i as f64 + 0.5;
        for j in cols.clone() {
            if e[0] >= 0 && e[1] >= 0 && e[2] >= 0 {
                let x = j as f64 + 0.5;
                let at = |q: usize| s.planes[q][0] * x + s.planes[q][1] * y + s.planes[q][2];
                let w = at(0);
                let z = 1.0 / w;
                fragment(
                    i,
                    j,
                    w,
                    [(at(1) * z) as f32, (at(2) * z) as f32, (at(3) * z) as f32],
                );
            }
            for k in 0..3 {
                e[k] += dx[k];
            }
        }
    }
}

/// The sRGB encoding (IEC 61966-2-1) of a linear value, clamped to `[0, 1]` first:
/// `12.92 v` up to `0.0031308`, `1.055 v^(1/2.4) - 0.055` above.
///
/// ```
/// use haarshift::relight::raster::srgb_encode;
/// assert_eq!(srgb_encode(0.0), 0.0);
/// assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
/// assert_eq!(srgb_encode(-1.0), 0.0);
/// ```
pub fn srgb_encode(linear: f64) -> f64 {
    let v = linear.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// `image` (linear) times `2^exposure` (stops), sRGB-encoded, as 8-bit codes (depth
/// [`SampleDepth::U8`], values `0..=255`, rounded to nearest).
///
/// ```
/// use haarshift::relight::raster::to_srgb8;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array2;
/// let half = PlanarImage::from_gray(Array2::from_elem((1, 1), 0.5f32), SampleDepth::F32).unwrap();
/// assert_eq!(to_srgb8(&half, 1.0).unwrap().plane(0)[[0, 0]], 255.0); // 0.5 x 2 = 1
/// assert_eq!(to_srgb8(&half, 0.0).unwrap().plane(0)[[0, 0]], 188.0); // 0.7354 x 255
/// ```
pub fn to_srgb8(image: &PlanarImage<f32>, exposure: f64) -> Result<PlanarImage<f32>> {
    if !exposure.is_finite() || exposure.abs() > 64.0 {
        return Err(Error::parameter(
            "exposure",
            format!("{exposure} stops (expected a finite number from -64 to 64)"),
        ));
    }
    let scale = exposure.exp2();
    let planes = image
        .planes()
        .mapv(|v| (srgb_encode(v as f64 * scale) * 255.0).round() as f32);
    PlanarImage::new(planes, image.channels(), SampleDepth::U8)
}

/// Writes a linear render: `.exr` as linear f32, `.png` as 8-bit sRGB after `exposure` stops
/// ([`to_srgb8`]); atomically, replacing an existing file only with `force`. Other extensions
/// are refused.
///
/// ```
/// use haarshift::relight::raster::write_render;
/// use haarshift::{PlanarImage, SampleDepth};
/// use ndarray::Array3;
/// let dir = tempfile::tempdir().unwrap();
/// let image = PlanarImage::new(Array3::from_elem((3, 2, 2), 0.25f32), haarshift::Channels::Rgb, SampleDepth::F32).unwrap();
/// write_render(&image, &dir.path().join("a.exr"), 0.0, false).unwrap();
/// let back = haarshift::io::read_image::<f32>(dir.path().join("a.exr")).unwrap();
/// assert_eq!(back.planes(), image.planes());
/// assert!(write_render(&image, &dir.path().join("a.jpg"), 0.0, false).is_err());
/// ```
pub fn write_render(
    image: &PlanarImage<f32>,
    path: &Path,
    exposure: f64,
    force: bool,
) -> Result<()> {
    let options = WriteOptions {
        force,
        ..Default::default()
    };
    match render_format(path)? {
        FileFormat::Exr => {
            let linear = PlanarImage::new(
                image.planes().to_owned(),
                image.channels(),
                SampleDepth::F32,
            )?;
            write_image(&linear, path, options)
        }
        _ => write_image(&to_srgb8(image, exposure)?, path, options),
    }
}

/// The format [`write_render`] writes to `path`: PNG or OpenEXR by the extension, anything else
/// refused (so a caller can check an output before rendering).
///
/// ```
/// use haarshift::io::FileFormat;
/// use haarshift::relight::raster::render_format;
/// assert_eq!(render_format("a.PNG".as_ref()).unwrap(), FileFormat::Png);
/// assert!(render_format("a.tif".as_ref()).unwrap_err().to_string().contains("a.tif"));
/// ```
pub fn render_format(path: &Path) -> Result<FileFormat> {
    match FileFormat::from_extension(path) {
        Some(format @ (FileFormat::Exr | FileFormat::Png)) => Ok(format),
        _ => Err(Error::Format {
            path: path.to_path_buf(),
            reason: "a render is written as .png (8-bit sRGB) or .exr (linear f32)".into(),
        }),
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` for a zero vector.
fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let n = norm(a);
    (n > 0.0).then(|| [a[0] / n, a[1] / n, a[2] / n])
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{Array2, array};

    fn front_camera() -> Camera {
        Camera::new([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 60.0).unwrap()
    }

    /// One triangle's screen-space setup, as `render` makes it.
    fn setups(
        camera: &Camera,
        w: usize,
        h: usize,
        positions: &Array2<f64>,
        tris: &[[u32; 3]],
    ) -> Vec<Setup> {
        let radiance = Array2::<f32>::zeros((positions.nrows(), 3));
        let mesh = Mesh {
            positions: positions.view(),
            triangles: tris,
            radiance: radiance.view(),
        };
        setup_triangles(camera, w, h, &mesh)
    }

    /// How many triangles cover each pixel centre.
    fn coverage(
        camera: &Camera,
        w: usize,
        h: usize,
        positions: &Array2<f64>,
        tris: &[[u32; 3]],
    ) -> Array2<u32> {
        let mut count = Array2::<u32>::zeros((h, w));
        for s in setups(camera, w, h, positions, tris) {
            rasterize(&s, 0..h, w, |i, j, _, _| count[[i, j]] += 1);
        }
        count
    }

    /// Signed distance in pixels from `p` to the line `a -> b` (positive on the left, y down).
    fn side(a: [f64; 3], b: [f64; 3], p: [f64; 2]) -> f64 {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        (dx * (p[1] - a[1]) - dy * (p[0] - a[0])) / (dx * dx + dy * dy).sqrt()
    }

    #[test]
    fn a_triangle_covers_exactly_the_pixel_centres_inside_it() {
        let camera = front_camera();
        let (w, h) = (64, 48);
        let tris = [
            array![[-1.3, -0.7, 0.2], [1.1, -1.2, -0.4], [0.3, 1.4, 0.1]],
            array![[-2.0, 0.1, -1.0], [0.05, 0.2, 0.5], [-0.4, 0.9, 0.0]],
        ];
        for positions in tris {
            let count = coverage(&camera, w, h, &positions, &[[0, 1, 2]]);
            let v: Vec<[f64; 3]> = (0..3)
                .map(|k| {
                    camera
                        .project([0, 1, 2].map(|c| positions[[k, c]]), w, h)
                        .unwrap()
                })
                .collect();
            let orient = side(v[0], v[1], [v[2][0], v[2][1]]).signum();
            let (mut inside, mut ambiguous) = (0, 0);
            for ((i, j), &n) in count.indexed_iter() {
                let p = [j as f64 + 0.5, i as f64 + 0.5];
                let d = [(0, 1), (1, 2), (2, 0)].map(|(a, b)| orient * side(v[a], v[b], p));
                let margin = d.iter().fold(f64::INFINITY, |m, &x| m.min(x));
                if margin.abs() < 0.01 {
                    ambiguous += 1; // within the 1/256-pixel snapping of an edge
                    continue;
                }
                let want = u32::from(margin > 0.0);
                inside += want;
                assert_eq!(n, want, "pixel ({i}, {j}), margin {margin}");
            }
            assert!(
                inside > 30 && ambiguous < 5,
                "{inside} inside, {ambiguous} ambiguous"
            );
        }
    }

    /// A grid of `n x n` vertices `vertex(a, b)`, two triangles per quad (alternating diagonals).
    fn grid(n: usize, vertex: impl Fn(usize, usize) -> [f64; 3]) -> (Array2<f64>, Vec<[u32; 3]>) {
        let positions = Array2::from_shape_fn((n * n, 3), |(k, c)| vertex(k / n, k % n)[c]);
        let mut tris = Vec::new();
        for a in 0..n - 1 {
            for b in 0..n - 1 {
                let (k, m) = ((a * n + b) as u32, n as u32);
                if (a + b) % 2 == 0 {
                    tris.extend([[k, k + 1, k + m + 1], [k, k + m + 1, k + m]]);
                } else {
                    tris.extend([[k, k + 1, k + m], [k + 1, k + m + 1, k + m]]);
                }
            }
        }
        (positions, tris)
    }

    #[test]
    fn shared_edges_are_drawn_once_and_leave_no_cracks() {
        // Vertices on pixel centres, 3 px apart: every edge, horizontal, vertical or diagonal,
        // runs through pixel centres, and only the fill rule decides who draws them. Camera:
        // f = 50 px for 100 x 100, depth 10, so world x goes to 50 + 5 x and y to 50 - 5 y.
        let camera = Camera::new([0.0, 0.0, 10.0], [0.0, 0.0, 0.0], 90.0).unwrap();
        let (positions, tris) = grid(11, |a, b| [0.1 + 0.6 * b as f64, 0.1 + 0.6 * a as f64, 0.0]);
        let count = coverage(&camera, 100, 100, &positions, &tris);
        // The outline spans x in [50.5, 80.5] and y in [19.5, 49.5]: its left and top edges
        // are in, its right and bottom edges out.
        for ((i, j), &c) in count.indexed_iter() {
            let want = u32::from((19..49).contains(&i) && (50..80).contains(&j));
            assert_eq!(c, want, "pixel ({i}, {j})");
        }
        // A jittered grid on a tilted plane: nothing drawn twice, no crack along any row.
        let camera = Camera::new([0.3, 0.2, 4.0], [0.0, 0.0, 0.0], 50.0).unwrap();
        let (positions, tris) = grid(10, |a, b| {
            let jitter = 0.3 * (((a * 10 + b) * 7919 % 13) as f64 / 13.0 - 0.5);
            let (a, b) = (a as f64, b as f64);
            [
                -1.5 + b / 3.0 + 0.2 * jitter,
                -1.5 + a / 3.0 - 0.1 * jitter,
                0.03 * (b - a),
            ]
        });
        let count = coverage(&camera, 96, 96, &positions, &tris);
        assert!(count.iter().all(|&c| c <= 1), "a pixel drawn twice");
        let drawn = count.iter().filter(|&&c| c == 1).count();
        assert!(drawn > 2000, "{drawn}");
        for (i, row) in count.outer_iter().enumerate() {
            let cols: Vec<usize> = (0..96).filter(|&j| row[j] == 1).collect();
            if let (Some(&first), Some(&last)) = (cols.first(), cols.last()) {
                assert_eq!(cols.len(), last - first + 1, "a crack in row {i}");
            }
        }
    }

    #[test]
    fn the_nearer_of_two_overlapping_triangles_wins_in_either_order() {
        let camera = front_camera();
        let positions = array![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, -1.0, 1.0],
        ];
        let mut radiance = Array2::<f32>::zeros((6, 3));
        radiance.slice_mut(ndarray::s![..3, 0]).fill(1.0); // far: red
        radiance.slice_mut(ndarray::s![3.., 2]).fill(1.0); // near: blue
        for tris in [[[0, 1, 2], [3, 4, 5]], [[3, 4, 5], [0, 1, 2]]] {
            let mesh = Mesh {
                positions: positions.view(),
                triangles: &tris,
                radiance: radiance.view(),
            };
            let image = render(&camera, 40, 40, &mesh, Background::Colour([0.0; 3])).unwrap();
            // The centre is covered by both: blue.
            assert_eq!(
                (image.plane(0)[[20, 20]], image.plane(2)[[20, 20]]),
                (0.0, 1.0)
            );
        }
    }

    #[test]
    fn interpolation_is_perspective_correct() {
        // A triangle steep in depth with radiance linear in the position: at every pixel centre
        // the value must be the linear function at the point where the ray meets the plane.
        let camera = Camera::new([0.2, 0.4, 3.0], [0.0, 0.0, 0.0], 70.0).unwrap();
        let positions = array![[-1.5, -1.0, 1.5], [1.5, -0.8, 1.2], [0.0, 1.2, -6.0]];
        let f = |p: [f64; 3]| {
            [
                1.0 + 0.3 * p[0],
                2.0 - 0.2 * p[1] + 0.1 * p[2],
                0.5 + 0.05 * p[2],
            ]
        };
        let radiance = Array2::from_shape_fn((3, 3), |(k, c)| {
            f([0, 1, 2].map(|i| positions[[k, i]]))[c] as f32
        });
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[[0, 1, 2]],
            radiance: radiance.view(),
        };
        let (w, h) = (80, 60);
        let image = render(&camera, w, h, &mesh, Background::Colour([-1.0; 3])).unwrap();
        let p0 = [0, 1, 2].map(|c| positions[[0, c]]);
        let normal = cross(
            sub([0, 1, 2].map(|c| positions[[1, c]]), p0),
            sub([0, 1, 2].map(|c| positions[[2, c]]), p0),
        );
        let mut checked = 0;
        for i in 0..h {
            for j in 0..w {
                if image.plane(0)[[i, j]] == -1.0 {
                    continue;
                }
                let d = camera.ray(j as f64 + 0.5, i as f64 + 0.5, w, h);
                let t = dot(sub(p0, camera.position()), normal) / dot(d, normal);
                let hit = [0, 1, 2].map(|k| camera.position()[k] + t * d[k]);
                for (c, want) in f(hit).iter().enumerate() {
                    let got = image.plane(c)[[i, j]] as f64;
                    assert!(
                        (got - want).abs() < 2e-6 * want.abs(),
                        "({i}, {j}) {c}: {got} vs {want}"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 500, "{checked}");
    }

    #[test]
    fn a_known_point_projects_to_its_pixel() {
        // Looking along -Z from (0, 0, 10), fov 90: f = H / 2 = 50 for 100 x 100.
        let camera = Camera::new([0.0, 0.0, 10.0], [0.0, 0.0, 9.0], 90.0).unwrap();
        let [x, y, z] = camera.project([2.0, -3.0, 0.0], 100, 100).unwrap();
        assert!((x - (50.0 + 50.0 * 2.0 / 10.0)).abs() < 1e-12);
        assert!((y - (50.0 + 50.0 * 3.0 / 10.0)).abs() < 1e-12);
        assert!((z - 10.0).abs() < 1e-12);
        assert!(camera.project([0.0, 0.0, 11.0], 100, 100).is_none());
        // A triangle 0.2 px wide around the point seen at the centre (59.5, 64.5) of pixel
        // (row 64, column 59) lights that pixel and no other.
        let (x, y, e) = (1.9, -2.9, 0.02);
        let positions = array![[x - e, y - e, 0.0], [x + e, y - e, 0.0], [x, y + e, 0.0]];
        let count = coverage(&camera, 100, 100, &positions, &[[0, 1, 2]]);
        let lit: Vec<(usize, usize)> = count
            .indexed_iter()
            .filter(|(_, c)| **c > 0)
            .map(|(p, _)| p)
            .collect();
        assert_eq!(lit, vec![(64, 59)]);
    }

    #[test]
    fn the_background_of_a_constant_environment_is_the_constant() {
        let env =
            LatLongMap::<f64>::from_fn(16, 3, |_, o| o.copy_from_slice(&[0.3, 0.6, 0.9])).unwrap();
        let camera = Camera::new([1.0, 2.0, 3.0], [0.0, 0.5, 0.0], 75.0).unwrap();
        let positions = Array2::<f64>::zeros((0, 3));
        let radiance = Array2::<f32>::zeros((0, 3));
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[],
            radiance: radiance.view(),
        };
        let image = render(&camera, 33, 21, &mesh, Background::Environment(&env)).unwrap();
        for (c, want) in [0.3f32, 0.6, 0.9].iter().enumerate() {
            assert!(image.plane(c).iter().all(|v| (v - want).abs() < 1e-6));
        }
        // The direction convention: the env holds its own direction; the centre pixel of a
        // camera looking along -X sees about (-1, 0, 0).
        let dirs = LatLongMap::<f64>::from_fn(64, 3, |d, o| o.copy_from_slice(&d)).unwrap();
        let camera = Camera::new([0.0; 3], [-1.0, 0.0, 0.0], 60.0).unwrap();
        let image = render(&camera, 11, 11, &mesh, Background::Environment(&dirs)).unwrap();
        let centre = [0, 1, 2].map(|c| image.plane(c)[[5, 5]]);
        assert!(
            (centre[0] + 1.0).abs() < 1e-2 && centre[1].abs() < 1e-2 && centre[2].abs() < 1e-2,
            "{centre:?}"
        );
    }

    #[test]
    fn srgb_matches_the_standard_at_known_values() {
        // IEC 61966-2-1: 12.92 v below 0.0031308, else 1.055 v^(1/2.4) - 0.055.
        for (v, want) in [
            (0.0, 0.0),
            (0.002, 0.02584),
            (0.003_130_8, 0.040_449_936),
            (0.18, 0.461_356_129_500_441_6),
            (0.5, 0.735_356_983_052_449_5),
            (1.0, 1.0),
            (4.0, 1.0),
        ] {
            assert!(
                (srgb_encode(v) - want).abs() < 1e-8,
                "{v}: {}",
                srgb_encode(v)
            );
        }
    }

    #[test]
    fn renders_are_written_as_srgb_png_and_linear_exr() {
        let planes = Array3::from_shape_fn((3, 2, 2), |(c, i, j)| {
            [0.0f32, 0.18, 0.5, 2.0][(c + i + 2 * j) % 4]
        });
        let image = PlanarImage::new(planes.clone(), Channels::Rgb, SampleDepth::F32).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("r.png");
        write_render(&image, &png, 0.0, false).unwrap();
        let back = crate::io::read_image::<f32>(&png).unwrap();
        for (&v, &b) in planes.iter().zip(back.planes().iter()) {
            assert_eq!(b, (srgb_encode(v as f64) * 255.0).round() as f32);
        }
        assert_err!(
            write_render(&image, &png, 0.0, false),
            OutputExists { .. },
            "already exists"
        );
        write_render(&image, &png, 1.0, true).unwrap();
        let exr = dir.path().join("r.exr");
        write_render(&image, &exr, 5.0, false).unwrap(); // the exposure does not touch EXR
        assert_eq!(
            crate::io::read_image::<f32>(&exr).unwrap().planes(),
            planes.view()
        );
    }

    #[test]
    fn bad_meshes_and_cameras_are_errors() {
        let camera = front_camera();
        let positions = array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
        let radiance = Array2::<f32>::zeros((3, 3));
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[[0, 1, 2]],
            radiance: radiance.view(),
        };
        assert_err!(
            render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])),
            NonFinite { .. },
            "NaN"
        );
        let positions = Array2::<f64>::zeros((3, 3));
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[[0, 1, 3]],
            radiance: radiance.view(),
        };
        let err = render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])).unwrap_err();
        assert!(err.to_string().contains("triangle 0"), "{err}");
        let short = Array2::<f32>::zeros((2, 3));
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[],
            radiance: short.view(),
        };
        assert_err!(
            render(&camera, 8, 8, &mesh, Background::Colour([0.0; 3])),
            InvalidShape { .. },
            "positions (V, 3) and radiance (V, 3)"
        );
        let mesh = Mesh {
            positions: positions.view(),
            triangles: &[],
            radiance: radiance.view(),
        };
        assert_err!(
            render(&camera, 0, 8, &mesh, Background::Colour([0.0; 3])),
            InvalidShape { .. },
            "1 to 32768 pixels"
        );
        let two = LatLongMap::<f64>::from_fn(4, 2, |_, o| o.fill(1.0)).unwrap();
        assert_err!(
            render(&camera, 8, 8, &mesh, Background::Environment(&two)),
            InvalidParameter {
                name: "background",
                ..
            },
            "2 channels"
        );
        assert_err!(
            Camera::new([0.0; 3], [0.0, 0.0, -1.0], 180.0),
            InvalidParameter { name: "fov", .. },
            "180 degrees"
        );
        assert_err!(
            Camera::new([0.0, f64::INFINITY, 0.0], [0.0; 3], 40.0),
            InvalidParameter { name: "camera", .. },
            "must be finite"
        );
        // Looking straight down is allowed: the image's up is -Z.
        let down = Camera::new([0.0, 5.0, 0.0], [0.0; 3], 40.0).unwrap();
        let [_, y, _] = down.project([0.0, 0.0, -1.0], 10, 10).unwrap();
        assert!(y < 5.0);
    }

    #[test]
    fn triangles_through_the_near_plane_are_clipped_not_dropped() {
        // A floor running from behind the camera to far in front fills the lower half.
        let camera = Camera::new([0.0, 1.0, 0.0], [0.0, 1.0, -1.0], 90.0).unwrap();
        let positions = array![
            [-50.0, 0.0, 50.0],
            [50.0, 0.0, 50.0],
            [50.0, 0.0, -50.0],
            [-50.0, 0.0, -50.0]
        ];
        let count = coverage(&camera, 20, 20, &positions, &[[0, 1, 2], [0, 2, 3]]);
        for i in 0..20 {
            for j in 0..20 {
                // The horizon of a floor 50 units away is about 1/50 of the half-height below
                // the centre line: rows from 11 on are floor, rows up to 9 are sky.
                if i >= 11 {
                    assert_eq!(count[[i, j]], 1, "({i}, {j})");
                }
                if i <= 9 {
                    assert_eq!(count[[i, j]], 0, "({i}, {j})");
                }
            }
        }
    }
}
