//! A software rasteriser for meshes with per-vertex radiance: perspective camera, z-buffer,
//! perspective-correct Gouraud interpolation, the environment (or a colour) as background,
//! exposure and sRGB for 8-bit PNG, linear f32 for OpenEXR.
//!
//! The camera is [`camera`](super::camera)'s; files are written by [`output`](super::output).
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
//! # Tiles and threads
//!
//! Vertices are taken to camera space once, then triangles are set up in parallel (no
//! allocation unless one must be clipped). The image is cut into bands of [`BAND_ROWS`] full
//! rows (tiles as wide as the image, so that each writes whole rows of the three output
//! planes), rendered in parallel with rayon. A band first keeps, per pixel, only the depth and
//! the index of the nearest triangle, going over the triangles whose bounding box reaches it
//! in the mesh's order (so the result does not depend on the thread count); then it fills
//! each pixel once: the winner's radiance, interpolated at the pixel centre, or the
//! background. A pixel hidden behind others is never shaded, and its value is the same
//! arithmetic on the same numbers as if every fragment had been shaded as it came.
//!
//! Pixels no triangle covers show the [`Background`]: a colour, or the environment seen along
//! the pixel centre's ray (bilinear lookup in the lat-long map, the sphere module's direction
//! convention), turned and looked up through a prepared table with [`Background::Sky`] (see
//! [`sky`](super::sky)).

use std::ops::Range;

use ndarray::{Array3, ArrayView2};
use rayon::prelude::*;

use super::camera::Camera;
use super::sky::{Behind, Sky};
use crate::{Error, Result};
use haarshift::sphere::LatLongMap;
use haarshift::{Channels, PlanarImage, SampleDepth};

/// The near plane's distance as a fraction of the camera's distance to the point looked at.
const NEAR_FRACTION: f64 = 1e-3;

/// Sub-pixel steps per pixel of the snapped vertex coordinates.
const SUBPIXEL: f64 = 256.0;

/// Half-width of the guard band in pixels: vertices projecting further out are clipped away
/// first, which keeps the integer edge functions far from overflow.
const GUARD: f64 = (1u64 << 21) as f64;

/// Rows per band of parallel work: a band's depths and winners (12 bytes a pixel) stay in a
/// core's L2 at any width up to a few thousand pixels.
pub const BAND_ROWS: usize = 16;

/// No triangle covers the pixel (yet).
const NONE: u32 = u32::MAX;

/// What pixels that no triangle covers show.
#[derive(Clone, Copy, Debug)]
pub enum Background<'a> {
    /// A constant linear RGB colour.
    Colour([f32; 3]),
    /// The environment along each pixel's ray (1 channel: gray; 3 or more: the first three).
    Environment(&'a LatLongMap<f64>),
    /// The environment turned, each pixel's place in it prepared once for the camera
    /// ([`Sky`]).
    Sky(Sky<'a>),
}

/// A mesh to draw: `positions` `(V, 3)`, triangles indexing them, and the linear RGB radiance
/// leaving each vertex, `(V, 3)`.
#[derive(Clone, Copy, Debug)]
pub struct LitMesh<'a> {
    /// Vertex positions, world space.
    pub positions: ArrayView2<'a, f64>,
    /// Triangles as vertex indices.
    pub triangles: &'a [[u32; 3]],
    /// Outgoing radiance per vertex, linear RGB.
    pub radiance: ArrayView2<'a, f32>,
}

impl LitMesh<'_> {
    /// Checks shapes, indices and values.
    fn check(&self) -> Result<()> {
        let (v, c) = self.positions.dim();
        if c != 3 || self.radiance.dim() != (v, 3) {
            return Err(Error::shape(
                &[v, c, self.radiance.dim().0, self.radiance.dim().1],
                "a mesh to draw has positions (V, 3) and radiance (V, 3)",
            ));
        }
        haarshift::ensure_finite(&self.positions)?;
        haarshift::ensure_finite(&self.radiance)?;
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
/// use haarshift_relight::render::{Background, Camera, LitMesh, render};
/// use ndarray::array;
/// let positions = array![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
/// let radiance = array![[1.0f32, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mesh = LitMesh { positions: positions.view(), triangles: &[[0, 1, 2]], radiance: radiance.view() };
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
    mesh: &LitMesh<'_>,
    background: Background<'_>,
) -> Result<PlanarImage<f32>> {
    check_size(width, height)?;
    let behind = Behind::new(background, camera, width, height)?;
    mesh.check()?;
    let setups = setup_triangles(camera, width, height, mesh);
    let bands = height.div_ceil(BAND_ROWS);
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (k, s) in setups.iter().enumerate() {
        for list in &mut binned[s.rows.start / BAND_ROWS..s.rows.end.div_ceil(BAND_ROWS)] {
            list.push(k as u32);
        }
    }
    let mut planes = Array3::<f32>::zeros((3, height, width));
    let flat = planes.as_slice_mut().expect("standard layout");
    let (red, rest) = flat.split_at_mut(width * height);
    let (green, blue) = rest.split_at_mut(width * height);
    let band = BAND_ROWS * width;
    red.par_chunks_mut(band)
        .zip(green.par_chunks_mut(band))
        .zip(blue.par_chunks_mut(band))
        .zip(binned)
        .enumerate()
        .for_each_init(
            || (Vec::new(), Vec::new()),
            |(depth, winner), (b, (((red, green), blue), list))| {
                let rows = b * BAND_ROWS..b * BAND_ROWS + red.len() / width;
                depth.clear();
                depth.resize(red.len(), 0.0f64);
                winner.clear();
                winner.resize(red.len(), NONE);
                for &k in &list {
                    rasterize(&setups[k as usize], rows.clone(), width, |i, j, w| {
                        let p = (i - rows.start) * width + j;
                        if winner[p] == NONE || w > depth[p] {
                            winner[p] = k;
                            depth[p] = w;
                        }
                    });
                }
                for (p, i) in rows.clone().enumerate() {
                    for j in 0..width {
                        let q = p * width + j;
                        let rgb = match winner[q] {
                            NONE => behind.at(i, j, width, height),
                            k => setups[k as usize].radiance(i, j, depth[q]),
                        };
                        (red[q], green[q], blue[q]) = (rgb[0], rgb[1], rgb[2]);
                    }
                }
            },
        );
    Ok(PlanarImage::new(planes, Channels::Rgb, SampleDepth::F32)?)
}

/// Refuses an image size [`render`] cannot draw.
pub(super) fn check_size(width: usize, height: usize) -> Result<()> {
    if width == 0 || height == 0 || width > 1 << 15 || height > 1 << 15 {
        return Err(Error::shape(
            &[height, width],
            "an image is 1 to 32768 pixels wide and high",
        ));
    }
    Ok(())
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

/// Triangles set up per parallel task: enough to amortise the task, few enough to balance.
const SETUP_CHUNK: usize = 2048;

/// Every triangle of `mesh` clipped, projected, snapped and set up, in the mesh's order.
fn setup_triangles(camera: &Camera, width: usize, height: usize, mesh: &LitMesh<'_>) -> Vec<Setup> {
    let near = camera.near(NEAR_FRACTION);
    let f = camera.focal(height);
    let (cx, cy) = (0.5 * width as f64, 0.5 * height as f64);
    // Each vertex taken to camera space once, not once per triangle using it.
    let vertices: Vec<ClipVertex> = (0..mesh.positions.nrows())
        .into_par_iter()
        .map(|i| {
            let p = [0, 1, 2].map(|k| mesh.positions[[i, k]]);
            let [x, y, z] = camera.camera_coordinates(p);
            let r = mesh.radiance.row(i);
            [x, y, z, r[0] as f64, r[1] as f64, r[2] as f64]
        })
        .collect();
    let project = |v: &ClipVertex| -> [f64; 6] {
        let w = 1.0 / v[2];
        [
            cx + f * v[0] * w,
            cy - f * v[1] * w,
            w,
            v[3] * w,
            v[4] * w,
            v[5] * w,
        ]
    };
    let outside =
        |v: &ClipVertex| (f * v[0]).abs() > GUARD * v[2] || (f * v[1]).abs() > GUARD * v[2];
    mesh.triangles
        .par_chunks(SETUP_CHUNK)
        .flat_map_iter(|chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            for tri in chunk {
                let [a, b, c] = [0, 1, 2].map(|k| &vertices[tri[k] as usize]);
                if [a, b, c].iter().all(|v| v[2] >= near && !outside(v)) {
                    // Nearly every triangle: nothing to clip, no allocation.
                    out.extend(setup([project(a), project(b), project(c)], width, height));
                    continue;
                }
                let corners = [*a, *b, *c];
                let mut poly = corners.to_vec();
                if poly.iter().any(|v| v[2] < near) {
                    poly = clip(&poly, |v| v[2] - near);
                }
                if poly.iter().any(outside) {
                    let g = GUARD / f;
                    poly = clip(&poly, |v| g * v[2] - v[0]);
                    poly = clip(&poly, |v| g * v[2] + v[0]);
                    poly = clip(&poly, |v| g * v[2] - v[1]);
                    poly = clip(&poly, |v| g * v[2] + v[1]);
                }
                let screen: Vec<[f64; 6]> = poly.iter().map(project).collect();
                for k in 1..screen.len().saturating_sub(1) {
                    out.extend(setup([screen[0], screen[k], screen[k + 1]], width, height));
                }
            }
            out
        })
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

impl Setup {
    /// The radiance at the centre of pixel `(i, j)`, where `1/z` is `w` (the value of
    /// [`rasterize`]'s fragment there).
    #[inline]
    fn radiance(&self, i: usize, j: usize, w: f64) -> [f32; 3] {
        let (x, y) = (j as f64 + 0.5, i as f64 + 0.5);
        let z = 1.0 / w;
        [
            (self.at(1, x, y) * z) as f32,
            (self.at(2, x, y) * z) as f32,
            (self.at(3, x, y) * z) as f32,
        ]
    }

    /// Plane `q` (0: `1/z`; 1 to 3: `radiance / z`) at pixel coordinates `(x, y)`, evaluated
    /// afresh at every pixel (not stepped) so that a value does not depend on where a
    /// triangle's span began.
    #[inline]
    fn at(&self, q: usize, x: f64, y: f64) -> f64 {
        self.planes[q][0] * x + self.planes[q][1] * y + self.planes[q][2]
    }
}

/// Calls `fragment(row, column, 1/z)` for every pixel centre in `rows` that the triangle
/// covers, by the top-left rule.
fn rasterize(
    s: &Setup,
    rows: Range<usize>,
    width: usize,
    mut fragment: impl FnMut(usize, usize, f64),
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
                fragment(i, j, s.at(0, j as f64 + 0.5, y));
            }
            for k in 0..3 {
                e[k] += dx[k];
            }
        }
    }
}

#[cfg(test)]
#[path = "raster_tests.rs"]
mod tests;
