//! The cube map: the sphere as six square faces of `S x S` texels, with each texel's centre
//! direction and its exact solid angle.
//!
//! # Faces, orientation, texel directions
//!
//! The faces come in the OpenGL order `+X, -X, +Y, -Y, +Z, -Z` (indices 0 to 5, see
//! [`CubeFace`]). Face `f` has an outward normal `n` and two in-face axes `u` (along a row,
//! columns increasing) and `v` (down a column, rows increasing); texel `(row, col)` of an
//! `S x S` face covers `a in [a0, a0 + 2/S]`, `b in [b0, b0 + 2/S]` with
//! `a0 = 2 col / S - 1`, `b0 = 2 row / S - 1`, and its centre looks along the normalised
//! `n + a u + b v` at the centre `(a, b)`:
//!
//! | face | `n` | `u` | `v` |
//! |---|---|---|---|
//! | 0 `+X` | `+X` | `-Z` | `-Y` |
//! | 1 `-X` | `-X` | `+Z` | `-Y` |
//! | 2 `+Y` | `+Y` | `+X` | `+Z` |
//! | 3 `-Y` | `-Y` | `+X` | `-Z` |
//! | 4 `+Z` | `+Z` | `+X` | `-Y` |
//! | 5 `-Z` | `-Z` | `-X` | `-Y` |
//!
//! Directions live in the world frame of [`latlong`](crate::sphere::latlong): right-handed, Y up,
//! `phi = 0` at `+Z` and `phi = 90` degrees at `+X`. The four side faces are laid out the
//! way the lat-long map is: their columns run with increasing `phi` (from `+Z` over `+X`,
//! `-Z` and `-X` back to `+Z`) and their rows downwards (`v = -Y`), so the row of side faces
//! `+Z, +X, -Z, -X` reads like the lat-long map's equator band. The top face's last row
//! touches `+Z`'s first row, the bottom face's first row `+Z`'s last row. (Each face's
//! `(u, v, n)` is a left-handed triple, as in OpenGL: the faces, like the lat-long map, are
//! images of the sphere seen from outside.)
//!
//! # Solid angles
//!
//! The rectangle `[a0, a1] x [b0, b1]` on the plane at distance 1 subtends the solid angle
//! `F(a1, b1) - F(a0, b1) - F(a1, b0) + F(a0, b0)` with `F(a, b) = atan2(a b, sqrt(1 + a^2 +
//! b^2))`, the antiderivative of `dA / (1 + a^2 + b^2)^(3/2)`; the faces' texels sum to
//! `4 pi` (each face's corners give `4 atan(1 / sqrt 3) = 2 pi / 3`).

/// One face of the cube map, in the order of the face index (see the [module docs](self)).
///
/// ```
/// use haarshift::faces::cube::CubeFace;
/// assert_eq!(CubeFace::ALL[4], CubeFace::PosZ);
/// assert_eq!(CubeFace::PosZ.axes(), [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CubeFace {
    /// Face 0, normal `+X`.
    PosX,
    /// Face 1, normal `-X`.
    NegX,
    /// Face 2, normal `+Y` (up).
    PosY,
    /// Face 3, normal `-Y` (down).
    NegY,
    /// Face 4, normal `+Z` (`phi = 0`).
    PosZ,
    /// Face 5, normal `-Z`.
    NegZ,
}

impl CubeFace {
    /// The six faces in index order.
    pub const ALL: [CubeFace; 6] = [
        CubeFace::PosX,
        CubeFace::NegX,
        CubeFace::PosY,
        CubeFace::NegY,
        CubeFace::PosZ,
        CubeFace::NegZ,
    ];

    /// `[n, u, v]`: the outward normal, the direction of increasing column and of increasing
    /// row.
    pub const fn axes(self) -> [[f64; 3]; 3] {
        match self {
            CubeFace::PosX => [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]],
            CubeFace::NegX => [[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]],
            CubeFace::PosY => [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
            CubeFace::NegY => [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
            CubeFace::PosZ => [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
            CubeFace::NegZ => [[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
        }
    }
}

/// The unit direction of the point `(a, b)` (each in `[-1, 1]`) of face `face` (0 to 5):
/// `n + a u + b v`, normalised.
///
/// ```
/// use haarshift::faces::cube::face_direction;
/// assert_eq!(face_direction(4, 0.0, 0.0), [0.0, 0.0, 1.0]); // the centre of +Z
/// let d = face_direction(2, 0.0, 1.0); // the edge of +Y shared with +Z
/// assert!((d[1] - d[2]).abs() < 1e-15 && d[0] == 0.0);
/// ```
#[inline]
pub fn face_direction(face: usize, a: f64, b: f64) -> [f64; 3] {
    let [n, u, v] = CubeFace::ALL[face].axes();
    let p = [
        n[0] + a * u[0] + b * v[0],
        n[1] + a * u[1] + b * v[1],
        n[2] + a * u[2] + b * v[2],
    ];
    let norm = (1.0 + a * a + b * b).sqrt();
    [p[0] / norm, p[1] / norm, p[2] / norm]
}

/// Where the direction `d` (any non-zero length) meets the cube: `(face, a, b)` with `a`, `b`
/// in `[-1, 1]`. On an edge or a corner the face listed first in [`CubeFace::ALL`] among the
/// candidates wins.
///
/// ```
/// use haarshift::faces::cube::{face_direction, face_point};
/// let (face, a, b) = face_point(face_direction(3, 0.25, -0.5));
/// assert_eq!(face, 3);
/// assert!((a - 0.25).abs() < 1e-15 && (b + 0.5).abs() < 1e-15);
/// ```
#[inline]
pub fn face_point(d: [f64; 3]) -> (usize, f64, f64) {
    let [x, y, z] = d;
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let face = if ax >= ay && ax >= az {
        if x >= 0.0 { 0 } else { 1 }
    } else if ay >= az {
        if y >= 0.0 { 2 } else { 3 }
    } else if z >= 0.0 {
        4
    } else {
        5
    };
    let [n, u, v] = CubeFace::ALL[face].axes();
    let depth = n[0] * x + n[1] * y + n[2] * z;
    let a = (u[0] * x + u[1] * y + u[2] * z) / depth;
    let b = (v[0] * x + v[1] * y + v[2] * z) / depth;
    (face, a.clamp(-1.0, 1.0), b.clamp(-1.0, 1.0))
}

/// The texel `(face, row, col)` of an `size x size` cube map that direction `d` falls in.
///
/// ```
/// use haarshift::faces::cube::{texel_direction, texel_of};
/// assert_eq!(texel_of(8, texel_direction(8, 5, 2, 7)), (5, 2, 7));
/// assert_eq!(texel_of(8, [0.0, 1.0, 0.0]).0, 2); // straight up: the +Y face
/// ```
#[inline]
pub fn texel_of(size: usize, d: [f64; 3]) -> (usize, usize, usize) {
    let (face, a, b) = face_point(d);
    let index = |t: f64| (((t + 1.0) * 0.5 * size as f64) as usize).min(size - 1);
    (face, index(b), index(a))
}

/// The face coordinate of texel edge `k` (0 to `size`) of a `size`-texel face: `2 k / size - 1`.
#[inline]
pub(crate) fn edge(size: usize, k: f64) -> f64 {
    2.0 * k / size as f64 - 1.0
}

/// The centre direction of texel `(row, col)` of face `face` of a `size x size` cube map.
///
/// ```
/// use haarshift::faces::cube::texel_direction;
/// // The top-left texel of the +Z face: a = b = -1/2, so -X (u = +X) and up (v = -Y).
/// let d = texel_direction(2, 4, 0, 0);
/// let s = (1.5f64).sqrt();
/// assert!((d[0] + 0.5 / s).abs() < 1e-15 && (d[1] - 0.5 / s).abs() < 1e-15);
/// ```
#[inline]
pub fn texel_direction(size: usize, face: usize, row: usize, col: usize) -> [f64; 3] {
    face_direction(
        face,
        edge(size, col as f64 + 0.5),
        edge(size, row as f64 + 0.5),
    )
}

/// The solid angle subtended by the rectangle `[a0, a1] x [b0, b1]` of a cube face (the plane
/// at distance 1 from the centre): exact, by the corner formula of the
/// [module docs](self).
///
/// ```
/// use haarshift::faces::cube::rectangle_solid_angle;
/// let face = rectangle_solid_angle(-1.0, 1.0, -1.0, 1.0);
/// assert!((face - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-15);
/// ```
#[inline]
pub fn rectangle_solid_angle(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    let f = |a: f64, b: f64| (a * b).atan2((1.0 + a * a + b * b).sqrt());
    f(a1, b1) - f(a0, b1) - f(a1, b0) + f(a0, b0)
}

/// The exact solid angle of texel `(row, col)` of a `size x size` face (the same on every
/// face). The `6 size^2` texels sum to `4 pi` to rounding.
///
/// ```
/// use haarshift::faces::cube::texel_solid_angle;
/// let total: f64 = (0..4).flat_map(|r| (0..4).map(move |c| texel_solid_angle(4, r, c))).sum();
/// assert!((6.0 * total - 4.0 * std::f64::consts::PI).abs() < 1e-14);
/// ```
#[inline]
pub fn texel_solid_angle(size: usize, row: usize, col: usize) -> f64 {
    rectangle_solid_angle(
        edge(size, col as f64),
        edge(size, col as f64 + 1.0),
        edge(size, row as f64),
        edge(size, row as f64 + 1.0),
    )
}

#[cfg(test)]
#[path = "cube_tests.rs"]
mod tests;
