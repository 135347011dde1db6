//! Steps 2 to 4: the chain rule at each edge's pre-image ((4.12)-(4.16) of Alnasser 2008),
//! giving the rotated map's differences.

use std::any::Any;

use ndarray::Array3;

use crate::Sample;
use crate::sphere::SphereRotation;
use crate::sphere::latlong::{atan2_finite, azimuth, for_each_row};

use super::gradient::{Scheme, SourceGradient};
use super::zonal::{ZONAL_CHUNK, ZonalProfile, ZonalRow, interpolate_f32_avx2};

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Which derivative of `g` the chain rule evaluates.
#[derive(Clone, Copy)]
pub(super) enum Along {
    Theta,
    Phi,
}

/// Where a target direction comes from: its pre-image `q = R p`, the rotated tangent
/// `R dp/d(along)`, the angle `Theta` of `q` from the pole, the frame's azimuth `(sin, cos)`
/// and the tangent's component along `e_Theta(q)` (step 2 of the [module docs](super)).
struct PreImage {
    pub(super) q: [f64; 3],
    pub(super) tangent: [f64; 3],
    pub(super) theta: f64,
    pub(super) sin_phi: f64,
    pub(super) cos_phi: f64,
    pub(super) along_theta: f64,
}

/// The [`PreImage`] of the target at `(sin, cos)` of `theta` and of `phi`. Branch-free, so
/// that a loop over a row vectorises.
#[inline(always)]
fn pre_image(
    rotation: &SphereRotation,
    (st, ct): (f64, f64),
    (sp, cp): (f64, f64),
    along: Along,
) -> PreImage {
    let p = [st * sp, ct, st * cp];
    let tangent = match along {
        Along::Theta => [ct * sp, -st, ct * cp],
        Along::Phi => [st * cp, 0.0, -st * sp],
    };
    let q = rotation.apply(p);
    let tq = rotation.apply(tangent);
    // The frame at q straight from q (atan2's convention at the poles: Phi = 0).
    let rho = (q[0] * q[0] + q[2] * q[2]).sqrt();
    let inv = 1.0 / rho;
    let (s_p, c_p) = if rho > 0.0 {
        (q[0] * inv, q[2] * inv)
    } else {
        (0.0, 1.0)
    };
    let c_t = q[1].clamp(-1.0, 1.0);
    PreImage {
        q,
        tangent: tq,
        theta: atan2_finite(rho, q[1]),
        sin_phi: s_p,
        cos_phi: c_p,
        along_theta: dot([c_t * s_p, -rho, c_t * c_p], tq),
    }
}

/// The chain rule (4.15)/(4.16) for one rotation and one source.
pub(super) struct ChainRule<'a, T> {
    pub(super) grad: &'a SourceGradient<T>,
    pub(super) rotation: &'a SphereRotation,
    /// Columns the source is turned by before the rotation (exact, [`SourceGradient`]).
    pub(super) turn: usize,
}

impl<'a, T: Sample> ChainRule<'a, T> {
    pub(super) fn new(
        grad: &'a SourceGradient<T>,
        rotation: &'a SphereRotation,
        turn: usize,
    ) -> Self {
        ChainRule {
            grad,
            rotation,
            turn,
        }
    }

    /// `scale * dg/d(along)` at the angles `(theta, phi) = (kt, kp) * delta / 2` into `out`.
    #[inline]
    pub(super) fn derivative(&self, kt: usize, kp: usize, along: Along, scale: f64, out: &mut [T]) {
        let (st, ct) = self.grad.trig[kt];
        let (sp, cp) = self.grad.trig[kp];
        if let Some(zonal) = &self.grad.zonal {
            // No azimuth needed: f has no phi derivative.
            let (mut theta, mut alpha) = ([T::zero()], [T::zero()]);
            let columns = ([T::from_f64(sp)], [T::from_f64(cp)]);
            let row = ZonalRow::new(self.rotation, (st, ct), along, scale);
            row.angles((&columns.0, &columns.1), (&mut theta, &mut alpha));
            self.grad.interpolate_zonal(zonal, &theta, &alpha, out);
            return;
        }
        let at = pre_image(self.rotation, (st, ct), (sp, cp), along);
        let (q, tq) = (at.q, at.tangent);
        let beta = scale * dot([at.cos_phi, 0.0, -at.sin_phi], tq);
        let big_p = azimuth(q[0], q[2]);
        let alpha = scale * at.along_theta;
        self.grad
            .write(at.theta, big_p, alpha, beta, self.turn, out);
    }

    /// One row of [`derivative`](Self::derivative): `theta = kt delta / 2` and the columns
    /// `phi = (2j + first) delta / 2` (`first` 1 or 2), `n x C` values into `row`. A zonal
    /// source takes [`zonal_row`](Self::zonal_row); the values are those of `derivative`.
    pub(super) fn derivative_row(
        &self,
        kt: usize,
        first: usize,
        along: Along,
        scale: f64,
        row: &mut [T],
    ) {
        let ch = self.grad.channels;
        let Some(profile) = &self.grad.zonal else {
            for (j, px) in row.chunks_exact_mut(ch).enumerate() {
                self.derivative(kt, first + 2 * j, along, scale, px);
            }
            return;
        };
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, the only feature `zonal_row_avx2` is compiled for.
            unsafe { self.zonal_row_avx2(profile, (kt, first), along, scale, row) };
            return;
        }
        self.zonal_row::<false>(profile, (kt, first), along, scale, row)
    }

    /// [`zonal_row`](Self::zonal_row) compiled for AVX2: four lanes of `f64`, eight of `f32`
    /// (whose one-channel linear lookups gather, [`interpolate_f32_avx2`]), and no fused
    /// multiply-adds, so that every CPU gets the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn zonal_row_avx2(
        &self,
        profile: &ZonalProfile<T>,
        at: (usize, usize),
        along: Along,
        scale: f64,
        row: &mut [T],
    ) {
        self.zonal_row::<true>(profile, at, along, scale, row)
    }

    /// A row of a zonal source's derivative in two passes over chunks of the row: the
    /// geometry ([`ZonalRow::angles`]), then the interpolation
    /// ([`interpolate_zonal`](SourceGradient::interpolate_zonal)); the first vectorises, the
    /// second is a table lookup per target. A chunk whose pre-images all lie where the
    /// profile is zero ([`ZonalProfile::cos_bounds`]) is zero without either.
    /// `AVX2` says the caller runs on an AVX2 CPU.
    #[inline(always)]
    pub(super) fn zonal_row<const AVX2: bool>(
        &self,
        profile: &ZonalProfile<T>,
        (kt, first): (usize, usize),
        along: Along,
        scale: f64,
        row: &mut [T],
    ) {
        let ch = self.grad.channels;
        let geometry = ZonalRow::<T>::new(self.rotation, self.grad.trig[kt], along, scale);
        let (low, high) = profile.cos_bounds;
        let bounds = (T::from_f64(low), T::from_f64(high));
        if !geometry.may_reach(bounds) {
            row.fill(T::zero());
            return;
        }
        let [sines, cosines] = &self.grad.columns[first - 1];
        let (mut theta, mut alpha) = ([T::zero(); ZONAL_CHUNK], [T::zero(); ZONAL_CHUNK]);
        for (c, pixels) in row.chunks_mut(ZONAL_CHUNK * ch).enumerate() {
            let count = pixels.len() / ch;
            let at = c * ZONAL_CHUNK;
            let columns = (&sines[at..][..count], &cosines[at..][..count]);
            if !geometry.reaches(columns, bounds) {
                pixels.fill(T::zero());
                continue;
            }
            if count < ZONAL_CHUNK {
                let (theta, alpha) = (&mut theta[..count], &mut alpha[..count]);
                geometry.angles(columns, (&mut *theta, &mut *alpha));
                self.grad.interpolate_zonal(profile, theta, alpha, pixels);
                continue;
            }
            geometry.angles(columns, (&mut theta[..], &mut alpha[..]));
            #[cfg(target_arch = "x86_64")]
            if AVX2 && ch == 1 && self.grad.scheme == Scheme::Linear {
                // One channel of f32 (the types checked at run time; nothing is cast).
                let spans = (&profile.spans as &dyn Any).downcast_ref::<Vec<f32>>();
                let angles = (&theta as &dyn Any).downcast_ref::<[f32; ZONAL_CHUNK]>();
                let factors = (&alpha as &dyn Any).downcast_ref::<[f32; ZONAL_CHUNK]>();
                let out = <&mut [T; ZONAL_CHUNK]>::try_from(&mut *pixels).ok();
                let out =
                    out.and_then(|o| (o as &mut dyn Any).downcast_mut::<[f32; ZONAL_CHUNK]>());
                if let (Some(spans), Some(theta), Some(alpha), Some(out)) =
                    (spans, angles, factors, out)
                {
                    let step = self.grad.inverse_step as f32;
                    // SAFETY: `AVX2` is true only in `zonal_row_avx2`, which runs on AVX2 CPUs.
                    unsafe { interpolate_f32_avx2(spans, step, (theta, alpha), out) };
                    continue;
                }
            }
            self.grad.interpolate_zonal(profile, &theta, &alpha, pixels);
        }
    }

    /// `rows x n x C` values of `scale * dg/d(along)`, row `i` at `theta = kt(i) delta / 2`,
    /// column `j` at `phi = (2j + first) delta / 2`.
    pub(super) fn field(
        &self,
        rows: usize,
        kt: impl Fn(usize) -> usize + Sync,
        first: usize,
        along: Along,
        scale: f64,
    ) -> Array3<T> {
        let (n, ch) = (self.grad.n, self.grad.channels);
        let mut data = Array3::zeros((rows, n, ch));
        let flat = data.as_slice_mut().expect("standard layout");
        for_each_row(flat, n * ch, |i, row| {
            self.derivative_row(kt(i), first, along, scale, row)
        });
        data
    }

    /// `V[i][j] = -delta g_theta((i + 1) delta, (j + 1/2) delta)`.
    pub(super) fn vertical(&self, i: usize, j: usize, out: &mut [T]) {
        self.derivative(2 * i + 2, 2 * j + 1, Along::Theta, -self.grad.step, out);
    }

    /// `U[i][j] = -delta g_phi((i + 1/2) delta, (j + 1) delta)`.
    pub(super) fn horizontal(&self, i: usize, j: usize, out: &mut [T]) {
        self.derivative(2 * i + 1, 2 * j + 2, Along::Phi, -self.grad.step, out);
    }
}
