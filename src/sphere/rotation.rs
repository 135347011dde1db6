//! [`SphereRotation`]: a rotation of the sphere and how it acts on a lat-long map.
//!
//! From yaw (about +Y), pitch (about +X) and roll (about +Z) in degrees,
//! `R = Rz(roll) Ry(yaw) Rx(pitch)` (Alnasser 2008's (4.10)) with the usual right-handed matrices
//! `Rx(a) = [[1, 0, 0], [0, c, -s], [0, s, c]]`, `Ry(a) = [[c, 0, s], [0, 1, 0], [-s, 0, c]]`,
//! `Rz(a) = [[c, -s, 0], [s, c, 0], [0, 0, 1]]`. The rotated map is `g(p) = f(R p)`
//! ((4.11)-(4.14)): the pixel of `g` looking along `p` shows what `f` saw along `R p`.

use crate::{Error, Result};

/// A proper rotation of 3-space (orthonormal, determinant +1), stored as its matrix.
///
/// ```
/// use haarshift::sphere::SphereRotation;
/// let r = SphereRotation::from_degrees(90.0, 0.0, 0.0).unwrap(); // yaw: +Z goes to +X
/// let q = r.apply([0.0, 0.0, 1.0]);
/// assert!((q[0] - 1.0).abs() < 1e-15 && q[2].abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereRotation {
    m: [[f64; 3]; 3],
}

/// Product of two 3x3 matrices.
fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

impl SphereRotation {
    /// The identity.
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// assert_eq!(SphereRotation::identity().apply([1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
    /// ```
    pub fn identity() -> Self {
        SphereRotation {
            m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// `Rz(roll) Ry(yaw) Rx(pitch)` from angles in degrees (finite, at most 1e6 in size).
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// let r = SphereRotation::from_degrees(0.0, 90.0, 0.0).unwrap(); // pitch: +Y goes to +Z
    /// let q = r.apply([0.0, 1.0, 0.0]);
    /// assert!((q[2] - 1.0).abs() < 1e-15);
    /// let nan = SphereRotation::from_degrees(f64::NAN, 0.0, 0.0);
    /// assert!(matches!(nan, Err(haarshift::Error::InvalidParameter { name: "yaw", .. })));
    /// ```
    pub fn from_degrees(yaw: f64, pitch: f64, roll: f64) -> Result<Self> {
        for (name, v) in [("yaw", yaw), ("pitch", pitch), ("roll", roll)] {
            if !v.is_finite() || v.abs() > 1e6 {
                return Err(Error::parameter(
                    name,
                    format!("{v} degrees is not a finite angle of at most 1e6 degrees"),
                ));
            }
        }
        let (sy, cy) = yaw.to_radians().sin_cos();
        let (sp, cp) = pitch.to_radians().sin_cos();
        let (sr, cr) = roll.to_radians().sin_cos();
        let rx = [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]];
        let ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]];
        let rz = [[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]];
        Ok(SphereRotation {
            m: mul(&rz, &mul(&ry, &rx)),
        })
    }

    /// A rotation from its matrix (row-major), which must be orthonormal with determinant +1
    /// to within 1e-9.
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// let swap = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]; // a reflection
    /// let err = SphereRotation::from_matrix(swap).unwrap_err();
    /// assert!(err.to_string().contains("not a rotation matrix") && err.to_string().contains("det = -1"));
    /// let ok = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    /// assert!(SphereRotation::from_matrix(ok).is_ok());
    /// ```
    pub fn from_matrix(m: [[f64; 3]; 3]) -> Result<Self> {
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::parameter(
                "rotation",
                "the matrix has a non-finite entry",
            ));
        }
        let r = SphereRotation { m };
        let mtm = mul(&r.inverse().m, &m);
        let off = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| (mtm[i][j] - if i == j { 1.0 } else { 0.0 }).abs())
            .fold(0.0, f64::max);
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if off > 1e-9 || (det - 1.0).abs() > 1e-9 {
            return Err(Error::parameter(
                "rotation",
                format!("not a rotation matrix (|M^T M - I| = {off:.2e}, det = {det})"),
            ));
        }
        Ok(r)
    }

    /// `self` applied after `first`: the rotation of matrix `M_self M_first`.
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// let (a, b) = (SphereRotation::from_degrees(30.0, 0.0, 0.0).unwrap(),
    ///               SphereRotation::from_degrees(0.0, 40.0, 0.0).unwrap());
    /// let p = [0.6, 0.0, 0.8];
    /// let (q, r) = (a.after(&b).apply(p), a.apply(b.apply(p)));
    /// assert!((0..3).all(|k| (q[k] - r[k]).abs() < 1e-15));
    /// ```
    pub fn after(&self, first: &SphereRotation) -> SphereRotation {
        SphereRotation {
            m: mul(&self.m, &first.m),
        }
    }

    /// The matrix, row-major.
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        self.m
    }

    /// The inverse rotation (the transpose).
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// let r = SphereRotation::from_degrees(10.0, 20.0, 30.0).unwrap();
    /// let p = r.inverse().apply(r.apply([0.6, 0.0, 0.8]));
    /// assert!((p[0] - 0.6).abs() < 1e-15 && (p[2] - 0.8).abs() < 1e-15);
    /// ```
    pub fn inverse(&self) -> Self {
        let m = self.m;
        SphereRotation {
            m: [
                [m[0][0], m[1][0], m[2][0]],
                [m[0][1], m[1][1], m[2][1]],
                [m[0][2], m[1][2], m[2][2]],
            ],
        }
    }

    /// `R p`.
    #[inline]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        [
            m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2],
            m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2],
            m[2][0] * p[0] + m[2][1] * p[1] + m[2][2] * p[2],
        ]
    }

    /// When this rotation is a yaw by a whole number `k` of columns of a `width`-column map
    /// (`k * 360 / width` degrees about +Y, to within 1e-9 of a column), `Some(k)` in
    /// `0..width`: then `g` is `f` with its columns turned by `k`, exactly
    /// ([`LatLongMap::roll_columns`](super::LatLongMap::roll_columns)). The identity gives
    /// `Some(0)`.
    ///
    /// ```
    /// use haarshift::sphere::SphereRotation;
    /// let r = SphereRotation::from_degrees(-90.0, 0.0, 0.0).unwrap();
    /// assert_eq!(r.whole_column_yaw(16), Some(12)); // -4 columns = +12 of 16
    /// assert_eq!(SphereRotation::from_degrees(1.0, 0.0, 0.0).unwrap().whole_column_yaw(16), None);
    /// ```
    pub fn whole_column_yaw(&self, width: usize) -> Option<usize> {
        let m = &self.m;
        let tol = 1e-12;
        let about_y = (m[1][1] - 1.0).abs() < tol
            && [m[0][1], m[1][0], m[1][2], m[2][1]]
                .iter()
                .all(|v| v.abs() < tol);
        if !about_y || width == 0 {
            return None;
        }
        // Ry(a) maps azimuth phi to phi + a: columns move by a / (2 pi / width).
        let columns = m[0][2].atan2(m[0][0]) * width as f64 / std::f64::consts::TAU;
        let k = columns.round();
        ((columns - k).abs() < 1e-9).then(|| (k as i64).rem_euclid(width as i64) as usize)
    }
}
