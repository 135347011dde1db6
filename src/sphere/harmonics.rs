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
#[path = "harmonics_tests.rs"]
mod tests;
