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
//! ([`vertex_major`](super::vertex_major), [`direction_major`](super::direction_major)) makes it
//! when [`VisibilityOptions::sh_bands`](super::VisibilityOptions::sh_bands) asks, and the
//! [`TransportSet`](super::TransportSet) carries it beside the Haar coefficients.
//!
//! **Shading.** The lighting's coefficients are its own projection,
//! `l_i = sum_t L(w_t) Y_i(w_t) dOmega_t` ([`SphericalHarmonics::project`], which weights by
//! the solid angle once, in any parameterisation), and a Lambertian vertex of albedo `a`
//! reflects `R_v = a / pi x sum_i l_i t_i` ([`shade_sh`]). The double sum is the integral of
//! lighting x transfer with both cut to `B` bands: exact (to the texel quadrature) when the
//! lighting has no degree `>= B`, a low-pass approximation otherwise: sharp shadows and small
//! bright lights are what it loses, and what the Haar path keeps.

use ndarray::{Array2, ArrayView2, Zip};
use rayon::prelude::*;

use crate::sphere::Parameterization;
use crate::sphere::harmonics::SphericalHarmonics;
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
/// [`SphericalHarmonics::project`] of the rotated environment.
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
    let mut out = Array2::<f32>::zeros((v, 3));
    Zip::from(out.rows_mut())
        .and(transfer.coefficients().rows())
        .and(albedo.rows())
        .par_for_each(|mut o, t, a| {
            for c in 0..3 {
                let l = lighting.column(c.min(channels - 1));
                let sum: f64 = t.iter().zip(l).map(|(&ti, &li)| f64::from(ti) * li).sum();
                o[c] = (f64::from(a[c]) / std::f64::consts::PI * sum) as f32;
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests;
