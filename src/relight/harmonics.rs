//! Spherical-harmonic transfer: seed 003's low-frequency precomputed radiance transfer, the
//! method all-frequency relighting is compared against.
//!
//! **Transfer.** For vertex `v` and `B` bands ([`SphericalHarmonics`]: degrees `0..B`, `B^2`
//! functions), the transfer vector is the projection of the same unweighted values the Haar
//! transport starts from, `V(v, t) max(0, n_v . w_t)`, onto the basis:
//! `t_i = sum_t V(v, t) max(0, n_v . w_t) Y_i(w_t) dOmega_t`, a sum over the texel centres `w_t`
//! of the precomputation's [`Parameterization`]. The texel solid angle enters here once (the
//! transfer is the factor that carries it, as the Haar transport does); the basis values
//! `Y_i(w_t) dOmega_t` are tabulated once per texel, not per vertex. The precomputation
//! ([`vertex_major`](crate::relight::vertex_major), [`direction_major`](crate::relight::direction_major)) makes it
//! when [`VisibilityOptions::sh_bands`](crate::relight::VisibilityOptions::sh_bands) asks, and the
//! [`TransportSet`](crate::relight::TransportSet) carries it beside the Haar coefficients.
//!
//! **Shading.** The lighting's coefficients are its own projection,
//! `l_i = sum_t L(w_t) Y_i(w_t) dOmega_t` ([`SphericalHarmonics::project`], which weights by
//! the solid angle once, in any parameterisation), and a Lambertian vertex of albedo `a`
//! reflects `R_v = a / pi x sum_i l_i t_i` ([`shade_sh`]). The double sum is the integral of
//! lighting x transfer with both cut to `B` bands: exact (to the texel quadrature) when the
//! lighting has no degree `>= B`, a low-pass approximation otherwise: sharp shadows and small
//! bright lights are what it loses, and what the Haar path keeps.
//!
//! **Glossy baseline (`--basis sh` with `phong:EXP`).** A Phong vertex reflects
//! `B_v = albedo_v x int T_v(w) L(w) rho_v(w) dw`, `rho_v(w) = (e + 2) / (2 pi)
//! max(0, r_v . w)^e` the energy-normalised lobe about the vertex's mirror direction `r_v`. The
//! lobe is zonal about `r_v`, so its coefficients need no rotation machinery:
//! `rho_lm = lambda_l Y_lm(r_v)` with the lobe's Funk-Hecke factors `lambda_l`
//! ([`phong_factors`], exact;
//! [`SphericalHarmonics::rotated_zonal`]). With all three factors cut to `B` bands the integral
//! is the triple product `B_v = albedo_v x sum_ijk G_ijk t_i l_j rho_k`, `G` the real Gaunt
//! coefficients ([`Gaunt`]). [`PhongSh`] holds the Gaunt table and the factors (made once);
//! each frame contracts the lighting once, `M^c_ik = sum_j G_ijk l^c_j` (`B^2 x B^2` per
//! channel, one pass over the sparse table), and each vertex costs one evaluation of the
//! harmonics at `r_v` and `t^T M^c rho_v`: `B^4` multiply-adds per channel, 4,096 at `B = 8`
//! against `B^2 = 64` for a Lambertian vertex. With exponent 0 (and `0^0 = 1`) the lobe is the
//! constant `1 / pi` and a Phong vertex is a Lambertian vertex of albedo 1 (tested to `1e-12`).
//! For inputs of degree below `B` the triple product is the integral of the three functions
//! exactly (tested against their pixel-domain integral to `1e-13`); for real ones it converges
//! as `B` grows (Phong 10, transfer `max(0, y)` and a smooth light: relative error `4.2e-4` at
//! `B = 8`, `3.1e-7` at 16, about `B^-10`).
//!
//! **What it cannot do.** Only zonal lobes, a function of the angle to one axis: Lambert and
//! Phong. Blinn-Phong's lobe about the half vector and measured (MERL) BRDFs are not zonal about
//! any direction, and a rotation of a general `B`-band function costs `B^3` per vertex with
//! Wigner matrices, not implemented here: they are refused with [`non_zonal_material`]. And the
//! cut to `B <= 16` bands blurs sharp lobes: a Phong 200 lobe (9.5 degrees wide at half
//! maximum) needs far more bands than the transfer stores, which is the Haar path's case.

use std::f64::consts::PI;

use ndarray::{Array2, ArrayView1, ArrayView2, Axis, Zip};
use rayon::prelude::*;

use crate::faces::Parameterization;
use crate::sphere::gaunt::Gaunt;
use crate::sphere::harmonics::{SphericalHarmonics, phong_factors};
use crate::{Error, Result};

/// The most bands of transfer accepted: `16^2 = 256` coefficients per vertex (1 KB each in
/// `f32`), and a basis table of `texels x 256` values (32 MB at `6 x 64^2` texels).
pub const MAX_SH_BANDS: usize = 16;

/// Every vertex's spherical-harmonic transfer vector, `(V, B^2)`; see the [module docs](self).
///
/// ```
/// use haarshift::relight::harmonics::ShTransfer;
/// use ndarray::Array2;
/// let t = ShTransfer::new(2, Array2::zeros((5, 4))).unwrap();
/// assert_eq!((t.bands(), t.vertex_count(), t.stored_bytes()), (2, 5, 80));
/// assert!(ShTransfer::new(2, Array2::zeros((5, 9))).is_err()); // 2 bands are 4 coefficients
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ShTransfer {
    bands: usize,
    /// `(V, B^2)`, row-major.
    values: Vec<f32>,
}

impl ShTransfer {
    /// The transfer of `B = bands` bands from its coefficients `(V, B^2)` (finite values).
    pub fn new(bands: usize, coefficients: Array2<f32>) -> Result<Self> {
        check_bands(bands)?;
        let (_, n) = coefficients.dim();
        if n != bands * bands {
            return Err(Error::shape(
                coefficients.shape(),
                format!(
                    "{bands} bands need {} coefficients per vertex",
                    bands * bands
                ),
            ));
        }
        let values = coefficients.as_standard_layout().iter().copied().collect();
        Self::from_flat(bands, values)
    }

    /// The transfer from its row-major values (the cache), checked.
    pub(crate) fn from_flat(bands: usize, values: Vec<f32>) -> Result<Self> {
        check_bands(bands)?;
        if !values.len().is_multiple_of(bands * bands) || !values.iter().all(|v| v.is_finite()) {
            return Err(Error::parameter(
                "sh transfer",
                format!("not finite rows of {} coefficients", bands * bands),
            ));
        }
        Ok(ShTransfer { bands, values })
    }

    /// An empty transfer of `bands` bands, for the precomputation to append to.
    pub(crate) fn empty(bands: usize) -> Result<Self> {
        Self::from_flat(bands, Vec::new())
    }

    /// Appends one vertex's `B^2` coefficients.
    pub(crate) fn push(&mut self, row: &[f32]) {
        debug_assert_eq!(row.len(), self.bands * self.bands);
        self.values.extend_from_slice(row);
    }

    /// The number of bands `B` (degrees `0..B`).
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// Vertices stored.
    pub fn vertex_count(&self) -> usize {
        self.values.len() / (self.bands * self.bands)
    }

    /// The transfer vectors, `(V, B^2)`, coefficient `l (l + 1) + m` as in
    /// [`SphericalHarmonics`].
    pub fn coefficients(&self) -> ArrayView2<'_, f32> {
        ArrayView2::from_shape((self.vertex_count(), self.bands * self.bands), &self.values)
            .expect("the length is a multiple of B^2")
    }

    /// The row-major values (the cache writes them).
    pub(crate) fn as_slice(&self) -> &[f32] {
        &self.values
    }

    /// Bytes held by the coefficients.
    pub fn stored_bytes(&self) -> usize {
        self.values.len() * 4
    }
}

/// An error unless `bands` is from 1 to [`MAX_SH_BANDS`].
pub(crate) fn check_bands(bands: usize) -> Result<()> {
    if !(1..=MAX_SH_BANDS).contains(&bands) {
        return Err(Error::parameter(
            "sh-bands",
            format!("{bands}: transfer takes 1 to {MAX_SH_BANDS} bands"),
        ));
    }
    Ok(())
}

/// The table `Y_i(w_t) dOmega_t` over the texels of a parameterisation, `(texels, B^2)`, and
/// the projection of one vertex's values with it.
pub(crate) struct ShProjector {
    n: usize,
    basis: Vec<f64>,
}

impl ShProjector {
    /// The table for `param`'s texel centres (texel index order `(face, row, col)`).
    pub(crate) fn new(param: Parameterization, bands: usize) -> Result<Self> {
        check_bands(bands)?;
        let sh = SphericalHarmonics::new(bands)?;
        let n = sh.len();
        let s = param.face_size();
        let mut basis = vec![0.0; param.texels() * n];
        basis.par_chunks_mut(n).enumerate().for_each(|(t, row)| {
            let (face, r, c) = (t / (s * s), (t / s) % s, t % s);
            sh.evaluate(param.texel_direction(face, r, c), row);
            let omega = param.texel_solid_angle(face, r, c);
            row.iter_mut().for_each(|y| *y *= omega);
        });
        Ok(ShProjector { n, basis })
    }

    /// The number of bands `B`.
    pub(crate) fn bands(&self) -> usize {
        self.n.isqrt()
    }

    /// The number of functions, `B^2`.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// `out[i] = sum_t values[t] Y_i(w_t) dOmega_t`, accumulated in `f64`; `values` holds one
    /// value per texel and `out` `B^2`. Texels of value 0 (below the horizon, or blocked) cost
    /// nothing.
    pub(crate) fn project(&self, values: &[f32], out: &mut [f32]) {
        let mut acc = vec![0.0f64; self.n];
        for (&v, row) in values.iter().zip(self.basis.chunks_exact(self.n)) {
            if v != 0.0 {
                let v = f64::from(v);
                acc.iter_mut().zip(row).for_each(|(a, y)| *a += v * y);
            }
        }
        out.iter_mut().zip(&acc).for_each(|(o, a)| *o = *a as f32);
    }

    /// Bytes of the table.
    pub(crate) fn bytes(&self) -> usize {
        self.basis.len() * 8
    }
}

/// Lambertian shading from spherical-harmonic transfer: `R_v = albedo_v / pi x sum_i l_i t_i`
/// per channel, `(V, 3)`. `albedo` is `(V, 3)`; `lighting` holds the lighting's coefficients
/// `(B^2, C)` with `C` 1 (gray, the same in every channel) or 3, e.g.
/// [`SphericalHarmonics::project`] of the rotated environment. Both must be finite.
///
/// ```
/// use haarshift::relight::harmonics::{ShTransfer, shade_sh};
/// use ndarray::{Array2, array};
/// let pi = std::f64::consts::PI;
/// // One upward vertex that sees its whole hemisphere: t_00 = int cos Y_00 = pi / (2 sqrt pi).
/// let t = ShTransfer::new(1, array![[(pi.sqrt() / 2.0) as f32]]).unwrap();
/// // Radiance 1 everywhere: l_00 = 4 pi Y_00 = 2 sqrt pi.
/// let l = array![[2.0 * pi.sqrt()]];
/// let r = shade_sh(&t, Array2::from_elem((1, 3), 0.5).view(), l.view()).unwrap();
/// assert!((r[[0, 1]] - 0.5).abs() < 1e-6); // albedo x irradiance pi / pi
/// ```
pub fn shade_sh(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> Result<Array2<f32>> {
    check_shading(transfer, albedo, lighting)?;
    let mut out = Array2::<f32>::zeros((transfer.vertex_count(), 3));
    Zip::from(out.rows_mut())
        .and(transfer.coefficients().rows())
        .and(albedo.rows())
        .par_for_each(|mut o, t, a| {
            let r = lambert(t, a, lighting);
            o.iter_mut().zip(r).for_each(|(o, r)| *o = r as f32);
        });
    Ok(out)
}

/// The checks every shading makes: `albedo` `(V, 3)` and `lighting` `(B^2, 1 or 3)` for the
/// transfer's `V` vertices and `B` bands, both finite.
fn check_shading(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> Result<()> {
    let v = transfer.vertex_count();
    let n = transfer.bands * transfer.bands;
    if albedo.dim() != (v, 3) {
        return Err(Error::shape(
            albedo.shape(),
            format!("the albedo must be ({v}, 3), one RGB row per vertex"),
        ));
    }
    let (rows, channels) = lighting.dim();
    if rows != n || !(channels == 1 || channels == 3) {
        return Err(Error::shape(
            lighting.shape(),
            format!(
                "the lighting's coefficients must be ({n}, 1) or ({n}, 3) for {} bands",
                transfer.bands
            ),
        ));
    }
    check_finite(albedo)?;
    check_finite(lighting)
}

/// An [`Error::NonFinite`] naming the first NaN or infinity of `values`.
fn check_finite<T: Copy + Into<f64>>(values: ArrayView2<'_, T>) -> Result<()> {
    match values
        .indexed_iter()
        .map(|(at, v)| (at, (*v).into()))
        .find(|(_, v): &(_, f64)| !v.is_finite())
    {
        Some(((r, c), v)) => Err(Error::NonFinite {
            value: v,
            index: vec![r, c],
        }),
        None => Ok(()),
    }
}

/// One Lambertian vertex, `albedo / pi x sum_i l_i t_i` per channel, in `f64`.
fn lambert(
    transfer: ArrayView1<'_, f32>,
    albedo: ArrayView1<'_, f32>,
    lighting: ArrayView2<'_, f64>,
) -> [f64; 3] {
    let channels = lighting.ncols();
    std::array::from_fn(|c| {
        let l = lighting.column(c.min(channels - 1));
        let sum: f64 = transfer
            .iter()
            .zip(l)
            .map(|(&ti, &li)| f64::from(ti) * li)
            .sum();
        f64::from(albedo[c]) / PI * sum
    })
}

/// The refusal of a material that is not one zonal lobe (Blinn-Phong, whose lobe about the
/// normal is not a function of one angle to a fixed axis, and measured BRDFs): the spherical
/// harmonics baseline shades Lambert and Phong only. Its message, for `material` =
/// `blinn:50`: `invalid basis: sh shades zonal lobes only (lambert, phong:EXP), not blinn:50;
/// use --basis haar`.
///
/// ```
/// use haarshift::relight::harmonics::non_zonal_material;
/// let e = non_zonal_material("merl:gold.binary");
/// assert_eq!(
///     e.to_string(),
///     "invalid basis: sh shades zonal lobes only (lambert, phong:EXP), not merl:gold.binary; \
///      use --basis haar"
/// );
/// ```
pub fn non_zonal_material(material: &str) -> Error {
    Error::parameter(
        "basis",
        format!(
            "sh shades zonal lobes only (lambert, phong:EXP), not {material}; use --basis haar"
        ),
    )
}

/// The glossy spherical-harmonics baseline for one Phong exponent and `B` bands, made once
/// (its Gaunt table and the lobe's factors) and used for every frame; see the
/// [module docs](self).
///
/// ```
/// use haarshift::relight::harmonics::{PhongSh, ShTransfer};
/// use ndarray::{Array2, array};
/// let pi = std::f64::consts::PI;
/// let phong = PhongSh::new(2, 0.0).unwrap(); // exponent 0: the constant 1 / pi
/// let t = ShTransfer::new(2, array![[(pi.sqrt() / 2.0) as f32, 0.0, 1.0, 0.0]]).unwrap();
/// let l = array![[2.0 * pi.sqrt()], [0.0], [0.0], [0.0]]; // radiance 1 everywhere
/// let mirror = array![[0.0, 1.0, 0.0]];
/// let r = phong.shade(&t, Array2::ones((1, 3)).view(), l.view(), mirror.view(), 1).unwrap();
/// // 1 / pi x the integral of the cosine over the upper hemisphere (pi); t_10 meets no light.
/// assert!((r[[0, 0]] - 1.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug)]
pub struct PhongSh {
    sh: SphericalHarmonics,
    gaunt: Gaunt,
    lambda: Vec<f64>,
}

impl PhongSh {
    /// The baseline for `bands` bands (1 to [`MAX_SH_BANDS`]) and the energy-normalised Phong
    /// lobe `(e + 2) / (2 pi) max(0, r . w)^e`, `e = exponent` from 0 to
    /// [`MAX_PHONG_EXPONENT`](crate::sphere::harmonics::MAX_PHONG_EXPONENT).
    pub fn new(bands: usize, exponent: f64) -> Result<Self> {
        check_bands(bands)?;
        Ok(PhongSh {
            sh: SphericalHarmonics::new(bands)?,
            gaunt: Gaunt::new(bands)?,
            lambda: phong_factors(exponent, bands)?,
        })
    }

    /// The number of bands `B`.
    pub fn bands(&self) -> usize {
        self.sh.bands()
    }

    /// The outgoing radiance `(V, 3)`: vertices `0..glossy` Phong,
    /// `albedo x sum_ijk G_ijk t_i l_j rho_k` with `rho` the lobe turned to the vertex's row of
    /// `mirror`, the rest Lambertian as [`shade_sh`] (in `f64`). `transfer` must have this
    /// baseline's bands; `albedo` `(V, 3)` and `lighting` `(B^2, 1 or 3)` as for [`shade_sh`];
    /// `mirror` `(V, 3)`, one unit direction per vertex (every row is checked; rows
    /// `glossy..` are not used), finite, of length 1 within `1e-6`; `glossy <= V`.
    pub fn shade(
        &self,
        transfer: &ShTransfer,
        albedo: ArrayView2<'_, f32>,
        lighting: ArrayView2<'_, f64>,
        mirror: ArrayView2<'_, f64>,
        glossy: usize,
    ) -> Result<Array2<f64>> {
        let bands = self.bands();
        if transfer.bands() != bands {
            return Err(Error::shape(
                transfer.coefficients().shape(),
                format!(
                    "the transfer has {} bands, the Phong baseline {bands}",
                    transfer.bands()
                ),
            ));
        }
        check_shading(transfer, albedo, lighting)?;
        let v = transfer.vertex_count();
        if mirror.dim() != (v, 3) {
            return Err(Error::shape(
                mirror.shape(),
                format!("the mirror directions must be ({v}, 3), one row per vertex"),
            ));
        }
        check_finite(mirror)?;
        if let Some((row, r)) = mirror
            .rows()
            .into_iter()
            .enumerate()
            .find(|(_, r)| (r.dot(r) - 1.0).abs() > 1e-6)
        {
            return Err(Error::parameter(
                "mirror direction",
                format!(
                    "vertex {row} has length {} (must be a unit vector)",
                    r.dot(&r).sqrt()
                ),
            ));
        }
        if glossy > v {
            return Err(Error::parameter(
                "glossy vertices",
                format!("{glossy} of {v} vertices"),
            ));
        }
        // M^c_ik = sum_j G_ijk l^c_j, once per frame, interleaved [i][k][c]: per vertex then
        // u = sum_i t_i M_i.. (one contiguous axpy per i) and B^c = albedo^c sum_k u_kc rho_k.
        let n = bands * bands;
        let channels = lighting.ncols();
        let mut m = vec![0.0; n * n * channels];
        let mut single = vec![0.0; n * n];
        for (c, column) in lighting.columns().into_iter().enumerate() {
            self.gaunt.contract(&column.to_vec(), &mut single);
            for (at, value) in single.iter().enumerate() {
                m[at * channels + c] = *value;
            }
        }
        let mut out = Array2::<f64>::zeros((v, 3));
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .zip(transfer.coefficients().axis_iter(Axis(0)))
            .zip(albedo.axis_iter(Axis(0)))
            .zip(mirror.axis_iter(Axis(0)))
            .enumerate()
            .for_each_init(
                || (vec![0.0; n * channels], vec![0.0; n]),
                |(u, rho), (vertex, (((mut o, t), a), r))| {
                    let result = if vertex < glossy {
                        self.sh.rotated_zonal(&self.lambda, [r[0], r[1], r[2]], rho);
                        u.fill(0.0);
                        for (&ti, row) in t.iter().zip(m.chunks_exact(n * channels)) {
                            let ti = f64::from(ti);
                            u.iter_mut().zip(row).for_each(|(u, mik)| *u += ti * mik);
                        }
                        let mut sums = [0.0; 3];
                        for (uk, rk) in u.chunks_exact(channels).zip(rho.iter()) {
                            sums.iter_mut().zip(uk).for_each(|(s, x)| *s += x * rk);
                        }
                        std::array::from_fn(|c| f64::from(a[c]) * sums[c.min(channels - 1)])
                    } else {
                        lambert(t, a, lighting)
                    };
                    o.iter_mut().zip(result).for_each(|(o, r)| *o = r);
                },
            );
        Ok(out)
    }
}

/// [`PhongSh::new`]`(transfer.bands(), exponent)` then [`PhongSh::shade`]: one frame of the
/// glossy spherical-harmonics baseline (an animation makes the [`PhongSh`] once instead).
pub fn shade_sh_glossy(
    transfer: &ShTransfer,
    albedo: ArrayView2<'_, f32>,
    lighting: ArrayView2<'_, f64>,
    exponent: f64,
    mirror: ArrayView2<'_, f64>,
    glossy: usize,
) -> Result<Array2<f64>> {
    PhongSh::new(transfer.bands(), exponent)?.shade(transfer, albedo, lighting, mirror, glossy)
}

#[cfg(test)]
mod tests;
