//! Spherical-harmonic transfer: Microsoft 2003's low-frequency precomputed radiance transfer, the
//! method all-frequency relighting is compared against.
//!
//! **Transfer.** For vertex `v` and `B` bands ([`SphericalHarmonics`]: degrees `0..B`, `B^2`
//! functions), the transfer vector is the projection of the same unweighted values the Haar
//! transport starts from, `V(v, t) max(0, n_v . w_t)`, onto the basis:
//! `t_i = sum_t V(v, t) max(0, n_v . w_t) Y_i(w_t) dOmega_t`, a sum over the texel centres `w_t`
//! of the precomputation's [`Parameterization`]. The texel solid angle enters here once (the
//! transfer is the factor that carries it, as the Haar transport does); the basis values
//! `Y_i(w_t) dOmega_t` are tabulated once per texel, not per vertex. The precomputation
//! ([`vertex_major`](crate::vertex_major), [`direction_major`](crate::direction_major)) makes it
//! when [`VisibilityOptions::sh_bands`](crate::VisibilityOptions::sh_bands) asks, and the
//! [`TransportSet`](crate::TransportSet) carries it beside the Haar coefficients.
//!
//! Shading with it (Lambertian `shade_sh` and the glossy baseline `PhongSh`) is a stage of
//! its own: [`shade::sh`](super::shade::sh).

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

use crate::{Error, Result};
use haarshift::faces::Parameterization;
use haarshift::sphere::harmonics::SphericalHarmonics;

/// The most bands of transfer accepted: `16^2 = 256` coefficients per vertex (1 KB each in
/// `f32`), and a basis table of `texels x 256` values (32 MB at `6 x 64^2` texels).
pub const MAX_SH_BANDS: usize = 16;

/// Every vertex's spherical-harmonic transfer vector, `(V, B^2)`; see the [module docs](self).
///
/// ```
/// use haarshift_relight::sh_transfer::ShTransfer;
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

#[cfg(test)]
mod tests;
