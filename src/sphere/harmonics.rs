//! Real spherical harmonics: evaluation, projection of a [`SphereMap`], reconstruction, and the
//! Lambertian (clamped-cosine) convolution of low-frequency precomputed radiance transfer
//! (seed `003_...`; Ramamoorthi and Hanrahan 2001).
//!
//! # Convention
//!
//! Degrees `l = 0..B-1` ("`B` bands"), orders `m = -l..=l`, `B^2` functions in all, coefficient
//! `l (l + 1) + m`. In the sphere module's angles (`theta` from +Y, `phi = atan2(x, z)`,
//! [`latlong`](super::latlong)):
//!
//! * `Y_l0 = K_l0 P_l^0(cos theta)`,
//! * `Y_lm = sqrt 2 K_lm P_l^m(cos theta) cos(m phi)` for `m > 0`,
//! * `Y_l,-m = sqrt 2 K_lm P_l^m(cos theta) sin(m phi)` for `m > 0`,
//!
//! with `K_lm = sqrt((2l + 1) / (4 pi) (l - m)! / (l + m)!)` and the associated Legendre
//! functions `P_l^m` **including the Condon-Shortley phase** `(-1)^m`. The functions are
//! orthonormal over the sphere (`int Y_i Y_j dOmega = delta_ij`). In Cartesian terms, with
//! `(x, y, z)` a direction of the world (Y up): `Y_00 = 1 / (2 sqrt pi)`,
//! `Y_1,-1 = -sqrt(3 / 4 pi) x`, `Y_10 = sqrt(3 / 4 pi) y`, `Y_11 = -sqrt(3 / 4 pi) z`: the
//! textbook real harmonics with the polar axis along +Y and `phi = 0` along +Z.
//!
//! # Evaluation
//!
//! No factorials: the normalised `K_lm P_l^m` follow the stable three-term recurrences
//! `P_mm = -sqrt((2m + 1) / 2m) sin theta P_m-1,m-1`, `P_m+1,m = sqrt(2m + 3) cos theta P_mm`,
//! `P_lm = a_lm (cos theta P_l-1,m - b_lm P_l-2,m)` with `a_lm = sqrt((4l^2 - 1) / (l^2 - m^2))`,
//! `b_lm = sqrt(((l - 1)^2 - m^2) / (4 (l - 1)^2 - 1))`, and `sin^m theta (cos m phi, sin m phi)`
//! is the real and imaginary part of `(z + i x)^m`, so nothing divides by `sin theta` at the
//! poles.
//!
//! # Projection
//!
//! [`SphericalHarmonics::project`] is the solid-angle-weighted sum over texels,
//! `c_i = sum_t f(w_t) Y_i(w_t) dOmega_t`, at the texel centres `w_t` of either
//! parameterisation; [`SphericalHarmonics::reconstruct`] evaluates `sum_i c_i Y_i` at the texel
//! centres. For a function of degree below `B`, projection then reconstruction returns it to the
//! accuracy of the texel quadrature (second order in the texel size).
//!
//! # Lambertian convolution
//!
//! The irradiance `E(n) = int L(w) max(0, n . w) dOmega` has coefficients
//! `E_lm = A_l L_lm` with `A_0 = pi`, `A_1 = 2 pi / 3`, `A_l = 0` for odd `l > 1` and
//! `A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) C(l, l/2) / 2^l` for even `l >= 2`
//! ([`lambert_factor`]): the clamped cosine's zonal coefficients `t_l` times
//! `sqrt(4 pi / (2l + 1))` (the Funk-Hecke theorem). A Lambertian vertex of albedo `a` and
//! normal `n` then reflects `a / pi x E(n)`.
//!
//! # Zonal lobes rotated to a direction
//!
//! A function of the angle to one axis `r`, `f(r . w)`, has the coefficients
//! `f_lm = lambda_l Y_lm(r)` with `lambda_l = 2 pi int_{-1}^{1} P_l(x) f(x) dx` (Funk-Hecke;
//! [`SphericalHarmonics::rotated_zonal`]). `A_l` above is `lambda_l` of the clamped cosine;
//! [`phong_factors`] gives those of the energy-normalised Phong lobe
//! `f(x) = (e + 2) / (2 pi) max(0, x)^e`: `lambda_l = (e + 2) I_l` with
//! `I_l = int_0^1 x^e P_l(x) dx`, `I_0 = 1 / (e + 1)`, `I_1 = 1 / (e + 2)` and
//! `I_l+2 = I_l (e - l) / (e + l + 3)`, the ratio of consecutive values of the closed form
//! `int_0^1 x^e P_l = sqrt(pi) 2^(-e-1) Gamma(e + 1) / (Gamma(1 + (e - l) / 2)
//! Gamma((e + l + 3) / 2))`: exact (to rounding) for any real `e > 0`, with no Gamma function
//! or factorial to overflow at `e = 10,000`. With `0^0 = 1`, exponent 0 is the constant
//! `1 / pi` over the whole sphere, `lambda = (4, 0, 0, ...)`: a Lambertian BRDF of albedo 1 (the
//! clamped cosine is the transfer's, not the lobe's).
//!
//! (A zonal function's coefficient on `Y_l0` about its own axis is
//! `z_l = sqrt((2l + 1) / (4 pi)) lambda_l`, so `f_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(r)`:
//! the factor `sqrt(4 pi / (2l + 1))` belongs with `z_l`, not with `lambda_l`.)

use ndarray::{Array2, Array3, ArrayView2, Axis};
use rayon::prelude::*;

use crate::faces::param::{Parameterization, SphereMap};
use crate::{Error, Result, Sample};

/// The most bands accepted (degrees 0 to 63).
const MAX_BANDS: usize = 64;

/// Real spherical harmonics of `B` bands (degrees `0..B`), with the recurrence coefficients
/// computed once.
///
/// ```
/// use haarshift::sphere::harmonics::SphericalHarmonics;
/// let sh = SphericalHarmonics::new(3).unwrap();
/// assert_eq!(sh.len(), 9);
/// let mut y = vec![0.0; 9];
/// sh.evaluate([0.0, 1.0, 0.0], &mut y); // the north pole: only the zonal functions survive
/// let y10 = (3.0 / (4.0 * std::f64::consts::PI)).sqrt();
/// assert!((y[2] - y10).abs() < 1e-15 && y[1] == 0.0 && y[3] == 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SphericalHarmonics {
    bands: usize,
    /// `(a_lm, b_lm)` at index `l (l + 1) / 2 + m`, for `l >= m + 2`.
    ab: Vec<(f64, f64)>,
}

impl SphericalHarmonics {
    /// Harmonics of degrees `0..bands` (`bands` from 1 to 64).
    pub fn new(bands: usize) -> Result<Self> {
        if !(1..=MAX_BANDS).contains(&bands) {
            return Err(Error::parameter(
                "sh-bands",
                format!("{bands} (expected 1 to {MAX_BANDS} bands)"),
            ));
        }
        let mut ab = vec![(0.0, 0.0); bands * (bands + 1) / 2];
        for l in 2..bands {
            for m in 0..l - 1 {
                let (lf, mf) = (l as f64, m as f64);
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let l1 = lf - 1.0;
                let b = ((l1 * l1 - mf * mf) / (4.0 * l1 * l1 - 1.0)).sqrt();
                ab[l * (l + 1) / 2 + m] = (a, b);
            }
        }
        Ok(SphericalHarmonics { bands, ab })
    }

    /// The number of bands `B`.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The number of functions, `B^2`.
    pub fn len(&self) -> usize {
        self.bands * self.bands
    }

    /// Always false: there is at least one band.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Every `Y_lm(d)` into `out` (`B^2` values, index `l (l + 1) + m`); `d` must be a unit
    /// vector.
    pub fn evaluate(&self, d: [f64; 3], out: &mut [f64]) {
        let [x, y, z] = d;
        let b = self.bands;
        debug_assert_eq!(out.len(), b * b);
        // (re, im) of (z + i x)^m: sin^m theta (cos m phi, sin m phi).
        let (mut re, mut im) = (1.0, 0.0);
        // K_mm P_mm without its sin^m theta factor.
        let mut pmm = 0.5 / std::f64::consts::PI.sqrt();
        for m in 0..b {
            if m > 0 {
                pmm *= -((2 * m + 1) as f64 / (2 * m) as f64).sqrt();
                (re, im) = (re * z - im * x, re * x + im * z);
            }
            let (c, s) = if m == 0 {
                (1.0, 0.0)
            } else {
                (std::f64::consts::SQRT_2 * re, std::f64::consts::SQRT_2 * im)
            };
            let mut store = |l: usize, p: f64| {
                let base = l * (l + 1);
                out[base + m] = p * c;
                if m > 0 {
                    out[base - m] = p * s;
                }
            };
            store(m, pmm);
            if m + 1 < b {
                let mut prev = pmm;
                let mut cur = ((2 * m + 3) as f64).sqrt() * y * pmm;
                store(m + 1, cur);
                for l in m + 2..b {
                    let (a, bb) = self.ab[l * (l + 1) / 2 + m];
                    let next = a * (y * cur - bb * prev);
                    store(l, next);
                    (prev, cur) = (cur, next);
                }
            }
        }
    }

    /// The coefficients `lambda_l Y_lm(axis)` of the zonal function with factors `lambda`
    /// (`B` values, e.g. [`phong_factors`] or [`lambert_factor`]s) turned to the unit vector
    /// `axis`, into `out` (`B^2` values); see the [module docs](self).
    ///
    /// ```
    /// use haarshift::sphere::harmonics::{SphericalHarmonics, lambert_factor};
    /// let sh = SphericalHarmonics::new(3).unwrap();
    /// let lambda: Vec<f64> = (0..3).map(lambert_factor).collect();
    /// let mut c = vec![0.0; 9];
    /// sh.rotated_zonal(&lambda, [1.0, 0.0, 0.0], &mut c); // max(0, x)
    /// let mut y = vec![0.0; 9];
    /// sh.evaluate([1.0, 0.0, 0.0], &mut y);
    /// let peak: f64 = c.iter().zip(&y).map(|(a, b)| a * b).sum();
    /// // sum_l A_l (2l + 1) / (4 pi) = 1/4 + 1/2 + 5/16: the peak of 1, cut to 3 bands.
    /// assert!((peak - 1.0625).abs() < 1e-15);
    /// ```
    pub fn rotated_zonal(&self, lambda: &[f64], axis: [f64; 3], out: &mut [f64]) {
        debug_assert_eq!(lambda.len(), self.bands);
        self.evaluate(axis, out);
        for (l, factor) in lambda.iter().enumerate() {
            out[l * l..(l + 1) * (l + 1)]
                .iter_mut()
                .for_each(|v| *v *= factor);
        }
    }

    /// The coefficients `(B^2, C)` of `map`: `c_i = sum over texels of f Y_i dOmega`, at the
    /// texel centres (see the [module docs](self)).
    ///
    /// ```
    /// use haarshift::sphere::harmonics::SphericalHarmonics;
    /// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
    /// let p = Parameterization::new(ParamKind::Cube, 32).unwrap();
    /// let f = SphereMap::<f64>::from_fn(p, 1, |d, o| o[0] = 1.0 + d[1]).unwrap();
    /// let c = SphericalHarmonics::new(2).unwrap().project(&f);
    /// let pi = std::f64::consts::PI;
    /// assert!((c[[0, 0]] - 2.0 * pi.sqrt()).abs() < 1e-3); // 1 = sqrt(4 pi) Y_00
    /// assert!((c[[2, 0]] - (4.0 * pi / 3.0).sqrt()).abs() < 1e-3); // y = sqrt(4 pi / 3) Y_10
    /// ```
    pub fn project<T: Sample>(&self, map: &SphereMap<T>) -> Array2<f64> {
        let param = map.param();
        let s = param.face_size();
        let ch = map.channels();
        let n = self.len();
        let values = map.as_array();
        let values = values.as_slice().expect("standard layout");
        // One partial sum per row, added in row order: the same bits however rayon shares the
        // rows out (a parallel fold's grouping depends on work stealing).
        let rows: Vec<Array2<f64>> = (0..param.faces() * s)
            .into_par_iter()
            .map(|fr| {
                let (face, row) = (fr / s, fr % s);
                let mut acc = Array2::<f64>::zeros((n, ch));
                let mut y = vec![0.0; n];
                for col in 0..s {
                    self.evaluate(param.texel_direction(face, row, col), &mut y);
                    let omega = param.texel_solid_angle(face, row, col);
                    let texel = &values[((face * s + row) * s + col) * ch..][..ch];
                    for (i, &yi) in y.iter().enumerate() {
                        let w = yi * omega;
                        for (a, v) in acc.row_mut(i).iter_mut().zip(texel) {
                            *a += w * v.as_f64();
                        }
                    }
                }
                acc
            })
            .collect();
        rows.into_iter()
            .fold(Array2::zeros((n, ch)), |sum, row| sum + row)
    }

    /// `sum_i c_i Y_i` at every texel centre of `param`; `coefficients` is `(B^2, C)`.
    ///
    /// ```
    /// use haarshift::sphere::harmonics::SphericalHarmonics;
    /// use haarshift::faces::param::{ParamKind, Parameterization};
    /// use ndarray::array;
    /// let sh = SphericalHarmonics::new(1).unwrap();
    /// let p = Parameterization::new(ParamKind::LatLong, 4).unwrap();
    /// let two = (16.0 * std::f64::consts::PI).sqrt(); // 2 = sqrt(16 pi) Y_00
    /// let m = sh.reconstruct(array![[two]].view(), p).unwrap();
    /// assert!(m.as_array().iter().all(|&v| (v - 2.0).abs() < 1e-14));
    /// ```
    pub fn reconstruct(
        &self,
        coefficients: ArrayView2<'_, f64>,
        param: Parameterization,
    ) -> Result<SphereMap<f64>> {
        let (n, ch) = self.check_coefficients(coefficients)?;
        let s = param.face_size();
        let mut data = Array3::<f64>::zeros((param.faces() * s, s, ch));
        // One harmonics buffer per worker, not per texel.
        data.outer_iter_mut()
            .into_par_iter()
            .enumerate()
            .for_each_init(
                || vec![0.0; n],
                |y, (fr, mut texels)| {
                    let (face, row) = (fr / s, fr % s);
                    for (col, mut out) in texels.outer_iter_mut().enumerate() {
                        self.evaluate(param.texel_direction(face, row, col), y);
                        for (o, c) in out.iter_mut().zip(coefficients.axis_iter(Axis(1))) {
                            *o = c.iter().zip(y.iter()).map(|(a, b)| a * b).sum();
                        }
                    }
                },
            );
        let data = data
            .into_shape_with_order((param.faces(), s, s, ch))
            .expect("faces x rows is the outer axis");
        SphereMap::new(param, data)
    }

    /// `(B^2, C)` of a coefficient array, or a shape error when it has not `B^2` rows.
    fn check_coefficients(&self, coefficients: ArrayView2<'_, f64>) -> Result<(usize, usize)> {
        let (n, ch) = coefficients.dim();
        if n != self.len() {
            return Err(Error::shape(
                &[n, ch],
                format!(
                    "{} bands need {} coefficients per channel",
                    self.bands,
                    self.len()
                ),
            ));
        }
        Ok((n, ch))
    }

    /// The irradiance coefficients `E_lm = A_l L_lm` of lighting coefficients `L` (`(B^2, C)`):
    /// the Lambertian convolution ([`lambert_factor`]).
    ///
    /// ```
    /// use haarshift::sphere::harmonics::SphericalHarmonics;
    /// use ndarray::array;
    /// let sh = SphericalHarmonics::new(1).unwrap();
    /// let pi = std::f64::consts::PI;
    /// let constant = array![[(4.0 * pi).sqrt()]]; // radiance 1 everywhere
    /// let e = sh.lambert_irradiance(constant.view()).unwrap();
    /// let mut y = [0.0];
    /// sh.evaluate([0.0, 1.0, 0.0], &mut y);
    /// assert!((e[[0, 0]] * y[0] - pi).abs() < 1e-14); // E = pi
    /// ```
    pub fn lambert_irradiance(&self, lighting: ArrayView2<'_, f64>) -> Result<Array2<f64>> {
        self.check_coefficients(lighting)?;
        let mut out = lighting.to_owned();
        for l in 0..self.bands {
            let a = lambert_factor(l);
            out.slice_mut(ndarray::s![l * l..(l + 1) * (l + 1), ..])
                .mapv_inplace(|v| v * a);
        }
        Ok(out)
    }
}

/// The largest Phong exponent [`phong_factors`] accepts (a lobe 0.67 degrees wide at half
/// maximum, far sharper than 16 bands resolve).
pub const MAX_PHONG_EXPONENT: f64 = 10_000.0;

/// `lambda_l`, `l = 0..bands`, of the energy-normalised Phong lobe
/// `(e + 2) / (2 pi) max(0, x)^e`, `e = exponent` from 0 to [`MAX_PHONG_EXPONENT`]: the factors
/// that [`SphericalHarmonics::rotated_zonal`] turns into the lobe's coefficients about any
/// direction (see the [module docs](self); exponent 0 is the constant `1 / pi`).
///
/// ```
/// use haarshift::sphere::harmonics::{lambert_factor, phong_factors};
/// let pi = std::f64::consts::PI;
/// assert_eq!(phong_factors(0.0, 3).unwrap(), vec![4.0, 0.0, 0.0]); // the constant 1 / pi
/// // Exponent 1 is the clamped cosine times 3 / (2 pi).
/// let one = phong_factors(1.0, 5).unwrap();
/// assert!((0..5).all(|l| (one[l] - 1.5 / pi * lambert_factor(l)).abs() < 1e-15));
/// assert!(phong_factors(-1.0, 3).is_err() && phong_factors(f64::NAN, 3).is_err());
/// ```
pub fn phong_factors(exponent: f64, bands: usize) -> Result<Vec<f64>> {
    if !(0.0..=MAX_PHONG_EXPONENT).contains(&exponent) {
        return Err(Error::parameter(
            "phong exponent",
            format!("{exponent} (expected 0 to {MAX_PHONG_EXPONENT})"),
        ));
    }
    if !(1..=MAX_BANDS).contains(&bands) {
        return Err(Error::parameter(
            "sh-bands",
            format!("{bands} (expected 1 to {MAX_BANDS} bands)"),
        ));
    }
    let e = exponent;
    if e == 0.0 {
        let mut out = vec![0.0; bands];
        out[0] = 4.0;
        return Ok(out);
    }
    let mut integrals = vec![1.0 / (e + 1.0), 1.0 / (e + 2.0)];
    for l in 2..bands {
        let k = (l - 2) as f64;
        integrals.push(integrals[l - 2] * (e - k) / (e + k + 3.0));
    }
    Ok(integrals[..bands].iter().map(|i| (e + 2.0) * i).collect())
}

/// `A_l`, the factor that turns lighting coefficients of degree `l` into irradiance
/// coefficients (Ramamoorthi and Hanrahan 2001, eq. 8): `pi`, `2 pi / 3`, `pi / 4`, 0,
/// `-pi / 24`, ... (see the [module docs](self)); computed without factorials.
///
/// ```
/// use haarshift::sphere::harmonics::lambert_factor;
/// let pi = std::f64::consts::PI;
/// assert!((lambert_factor(0) - pi).abs() < 1e-15);
/// assert!((lambert_factor(2) - pi / 4.0).abs() < 1e-15);
/// assert_eq!(lambert_factor(3), 0.0);
/// ```
pub fn lambert_factor(l: usize) -> f64 {
    use std::f64::consts::PI;
    match l {
        0 => PI,
        1 => 2.0 * PI / 3.0,
        l if l % 2 == 1 => 0.0,
        l => {
            // C(l, l/2) / 2^l as a product of l/2 factors (2k - 1) / 2k.
            let central: f64 = (1..=l / 2)
                .map(|k| (2 * k - 1) as f64 / (2 * k) as f64)
                .product();
            let sign = if (l / 2) % 2 == 1 { 1.0 } else { -1.0 };
            2.0 * PI * sign * central / ((l + 2) as f64 * (l - 1) as f64)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::faces::param::ParamKind;
    use std::f64::consts::PI;

    fn param(kind: ParamKind, size: usize) -> Parameterization {
        Parameterization::new(kind, size).unwrap()
    }

    /// Deterministic unit vectors spread over the sphere, the poles included.
    fn directions() -> Vec<[f64; 3]> {
        let mut out = vec![[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]];
        for k in 0..40 {
            let t = 0.05 + 3.0 * (k as f64 * 0.618_034).fract();
            let p = k as f64 * 2.399_963;
            out.push(crate::sphere::latlong::direction(t, p));
        }
        out
    }

    #[test]
    fn low_degrees_match_their_closed_forms() {
        let sh = SphericalHarmonics::new(3).unwrap();
        let mut y = vec![0.0; 9];
        for d in directions() {
            sh.evaluate(d, &mut y);
            // The textbook (x, y, z) with z the polar axis is the world's (z, x, y).
            let (xs, ys, zs) = (d[2], d[0], d[1]);
            let c1 = (3.0 / (4.0 * PI)).sqrt();
            let c2 = (15.0 / (4.0 * PI)).sqrt();
            let want = [
                0.5 / PI.sqrt(),
                -c1 * ys,
                c1 * zs,
                -c1 * xs,
                c2 * xs * ys,
                -c2 * ys * zs,
                0.25 * (5.0 / PI).sqrt() * (3.0 * zs * zs - 1.0),
                -c2 * xs * zs,
                0.5 * c2 * (xs * xs - ys * ys),
            ];
            for (i, (g, w)) in y.iter().zip(want).enumerate() {
                assert!((g - w).abs() < 1e-14, "Y[{i}] at {d:?}: {g} vs {w}");
            }
        }
    }

    /// The largest entry of `G - I`, `G` the Gram matrix of the first `bands` bands by the
    /// texel quadrature of `p`.
    fn gram_error(bands: usize, p: Parameterization) -> f64 {
        let sh = SphericalHarmonics::new(bands).unwrap();
        let n = sh.len();
        let mut gram = Array2::<f64>::zeros((n, n));
        let mut y = vec![0.0; n];
        let s = p.face_size();
        for face in 0..p.faces() {
            for row in 0..s {
                for col in 0..s {
                    sh.evaluate(p.texel_direction(face, row, col), &mut y);
                    let omega = p.texel_solid_angle(face, row, col);
                    for i in 0..n {
                        for j in 0..n {
                            gram[[i, j]] += y[i] * y[j] * omega;
                        }
                    }
                }
            }
        }
        gram.indexed_iter()
            .map(|((i, j), &g)| (g - if i == j { 1.0 } else { 0.0 }).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn the_first_nine_bands_are_orthonormal() {
        // Every pair of the 81 functions; the texel quadrature is second order, so the error
        // must fall about 4x per doubling of the resolution (it is quadrature, not a bias).
        // Measured: 1.6e-3 at lat-long 64, 4.0e-4 at 128, 1.5e-4 on the 6 x 64^2 cube.
        let coarse = gram_error(9, param(ParamKind::LatLong, 64));
        let fine = gram_error(9, param(ParamKind::LatLong, 128));
        assert!(fine < 5e-4, "{fine:e}");
        let ratio = coarse / fine;
        assert!(
            (3.6..4.4).contains(&ratio),
            "{coarse:e} / {fine:e} = {ratio}"
        );
        let cube = gram_error(9, param(ParamKind::Cube, 64));
        assert!(cube < 2e-4, "{cube:e}");
    }

    #[test]
    fn the_addition_theorem_holds() {
        let bands = 64;
        let sh = SphericalHarmonics::new(bands).unwrap();
        let (mut ya, mut yb) = (vec![0.0; bands * bands], vec![0.0; bands * bands]);
        let dirs = directions();
        for (a, b) in dirs.iter().zip(dirs.iter().rev()) {
            sh.evaluate(*a, &mut ya);
            sh.evaluate(*b, &mut yb);
            let x: f64 = (0..3).map(|k| a[k] * b[k]).sum();
            // Legendre polynomials by Bonnet's recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for l in 0..bands {
                let pl = if l == 0 { p0 } else { p1 };
                let sum: f64 = (l * l..(l + 1) * (l + 1)).map(|i| ya[i] * yb[i]).sum();
                let want = (2 * l + 1) as f64 / (4.0 * PI) * pl;
                let tol = 1e-12 * (2 * l + 1) as f64;
                assert!((sum - want).abs() < tol, "l = {l}: {sum} vs {want}");
                if l >= 1 {
                    let next = ((2 * l + 1) as f64 * x * p1 - l as f64 * p0) / (l + 1) as f64;
                    (p0, p1) = (p1, next);
                }
            }
        }
    }

    #[test]
    fn a_projection_has_the_same_bits_on_any_number_of_threads() {
        let p = Parameterization::new(ParamKind::LatLong, 64).unwrap();
        let f = SphereMap::<f64>::from_fn(p, 3, |d, o| {
            o.copy_from_slice(&[1.0 + d[1], (9.0 * d[0]).sin(), (d[2] * 40.0).exp()]);
        })
        .unwrap();
        let sh = SphericalHarmonics::new(6).unwrap();
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| sh.project(&f))
        };
        let one = on(1);
        for threads in [2, 3, 7] {
            assert_eq!(on(threads), one, "{threads} threads");
        }
    }

    #[test]
    fn projection_then_reconstruction_returns_a_band_limited_function() {
        let bands = 9;
        let sh = SphericalHarmonics::new(bands).unwrap();
        let n = sh.len();
        let coeffs = Array2::from_shape_fn((n, 2), |(i, c)| {
            ((i * 37 + c * 11) % 17) as f64 / 17.0 - 0.5
        });
        for p in [param(ParamKind::LatLong, 128), param(ParamKind::Cube, 64)] {
            let f = SphereMap::<f64>::from_fn(p, 2, |d, out| {
                let mut y = vec![0.0; n];
                sh.evaluate(d, &mut y);
                for (c, o) in out.iter_mut().enumerate() {
                    *o = (0..n).map(|i| coeffs[[i, c]] * y[i]).sum();
                }
            })
            .unwrap();
            let got = sh.project(&f);
            let err = (&got - &coeffs).iter().fold(0.0f64, |a, v| a.max(v.abs()));
            // The Gram matrix's quadrature error times the coefficients' size (<= 0.5 x 81).
            assert!(err < 5e-3, "{:?}: {err:e}", p.kind());
            let back = sh.reconstruct(got.view(), p).unwrap();
            let diff = (&back.as_array() - &f.as_array())
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(diff < 5e-3, "{:?}: {diff:e}", p.kind());
        }
    }

    #[test]
    fn lambert_factors_match_the_clamped_cosine_by_quadrature() {
        // A_l = sqrt(4 pi / (2l + 1)) t_l with t_l the clamped cosine's zonal coefficients,
        // here by quadrature (the equator is a row edge, so the kink costs no accuracy).
        let bands = 9;
        let sh = SphericalHarmonics::new(bands).unwrap();
        let p = param(ParamKind::LatLong, 256);
        let cosine = SphereMap::<f64>::from_fn(p, 1, |d, o| o[0] = d[1].max(0.0)).unwrap();
        let t = sh.project(&cosine);
        for l in 0..bands {
            let want = (4.0 * PI / (2 * l + 1) as f64).sqrt() * t[[l * (l + 1), 0]];
            let got = lambert_factor(l);
            assert!((got - want).abs() < 1e-4, "l = {l}: {got} vs {want}");
        }
    }

    /// `c_i = int f(r . w) Y_i(w) dOmega` of a zonal `f` about `axis`, by a quadrature in the
    /// lobe's own frame: Gauss-Legendre in `x = r . w` on `[lo, 1]` (`nodes`, exact for the
    /// polynomial `f(x) x^l` when `f` is one) times uniform azimuths about `axis`, the harmonics
    /// evaluated at the world directions: independent of Funk-Hecke and of the recurrence.
    fn project_zonal(
        sh: &SphericalHarmonics,
        f: impl Fn(f64) -> f64,
        axis: [f64; 3],
        lo: f64,
        nodes: usize,
    ) -> Vec<f64> {
        let n = sh.len();
        // An orthonormal frame (u, v, axis).
        let helper = if axis[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let u = cross(axis, helper);
        let norm = u.iter().map(|c| c * c).sum::<f64>().sqrt();
        let u = u.map(|c| c / norm);
        let v = cross(axis, u);
        let phis = 2 * sh.bands() + 1;
        let mut out = vec![0.0; n];
        let mut y = vec![0.0; n];
        for (t, w) in crate::sphere::gaunt::gauss_legendre(nodes) {
            let x = lo + (1.0 - lo) * (t + 1.0) / 2.0;
            let weight = w * (1.0 - lo) / 2.0 * f(x) * 2.0 * PI / phis as f64;
            let s = (1.0 - x * x).max(0.0).sqrt();
            for p in 0..phis {
                let phi = 2.0 * PI * p as f64 / phis as f64;
                let (c, si) = (s * phi.cos(), s * phi.sin());
                let d = [0, 1, 2].map(|k| x * axis[k] + c * u[k] + si * v[k]);
                sh.evaluate(d, &mut y);
                out.iter_mut().zip(&y).for_each(|(o, yi)| *o += weight * yi);
            }
        }
        out
    }

    #[test]
    fn phong_lobes_rotated_to_a_direction_match_their_projection() {
        let bands = 12;
        let sh = SphericalHarmonics::new(bands).unwrap();
        let axes = [[0.0, 1.0, 0.0], [0.48, -0.6, 0.64], [0.0, 0.0, -1.0]];
        let mut got = vec![0.0; bands * bands];
        for e in [0.0, 1.0, 10.0, 50.0, 10_000.0] {
            let lambda = phong_factors(e, bands).unwrap();
            let f = |x: f64| (e + 2.0) / (2.0 * PI) * if e == 0.0 { 1.0 } else { x.powf(e) };
            // The lobe lives on [0, 1] in x, except exponent 0 (0^0 = 1: the whole sphere).
            let lo = if e == 0.0 { -1.0 } else { 0.0 };
            let nodes = (e as usize + bands) / 2 + 2;
            let mut worst = 0.0f64;
            for axis in axes {
                sh.rotated_zonal(&lambda, axis, &mut got);
                let want = project_zonal(&sh, f, axis, lo, nodes);
                for (g, w) in got.iter().zip(&want) {
                    worst = worst.max((g - w).abs());
                }
            }
            eprintln!("phong {e}: worst {worst:e}");
            assert!(worst < 1e-10, "phong {e}: {worst:e}");
        }
        // Exponent 0 is the constant 1 / pi exactly: 4 Y_00 Y_00 = 1 / pi.
        sh.rotated_zonal(&phong_factors(0.0, bands).unwrap(), axes[1], &mut got);
        assert!((got[0] * 0.5 / PI.sqrt() - 1.0 / PI).abs() < 1e-16);
        assert!(got[1..].iter().all(|c| *c == 0.0));
    }

    #[test]
    fn phong_factors_refuse_exponents_out_of_range() {
        for bad in [-0.5, 10_000.5, f64::NAN, f64::INFINITY] {
            assert_err!(
                phong_factors(bad, 4),
                InvalidParameter {
                    name: "phong exponent",
                    ..
                },
                "(expected 0 to 10000)"
            );
        }
        assert_err!(
            phong_factors(2.0, 0),
            InvalidParameter {
                name: "sh-bands",
                ..
            },
            "0 (expected 1 to 64 bands)"
        );
    }

    #[test]
    fn a_constant_environment_gives_irradiance_pi_times_its_radiance() {
        let sh = SphericalHarmonics::new(9).unwrap();
        let p = param(ParamKind::Cube, 32);
        let env =
            SphereMap::<f32>::from_fn(p, 3, |_, o| o.copy_from_slice(&[1.0, 0.5, 2.0])).unwrap();
        let e = sh.lambert_irradiance(sh.project(&env).view()).unwrap();
        let irradiance = sh.reconstruct(e.view(), p).unwrap();
        for px in irradiance.as_array().as_slice().unwrap().chunks_exact(3) {
            for (v, l) in px.iter().zip([1.0, 0.5, 2.0]) {
                assert!((v - PI * l).abs() < 1e-3 * l, "{v} vs {}", PI * l);
            }
        }
    }

    #[test]
    fn bad_band_counts_and_shapes_are_errors() {
        assert_err!(
            SphericalHarmonics::new(0),
            InvalidParameter {
                name: "sh-bands",
                ..
            },
            "0 (expected 1 to 64 bands)"
        );
        assert_err!(
            SphericalHarmonics::new(65),
            InvalidParameter {
                name: "sh-bands",
                ..
            },
            "65 (expected"
        );
        let sh = SphericalHarmonics::new(2).unwrap();
        let wrong = Array2::<f64>::zeros((3, 1));
        assert_err!(
            sh.reconstruct(wrong.view(), param(ParamKind::Cube, 2)),
            InvalidShape { .. },
            "need 4 coefficients"
        );
        assert_err!(
            sh.lambert_irradiance(wrong.view()),
            InvalidShape { .. },
            "need 4 coefficients"
        );
    }
}
