//! The chain rule for a zonal map (a lobe about one axis): its derivative is a profile of
//! one angle, looked up in two passes, with an AVX2 gather for one-channel f32 taps.

use crate::Sample;
use crate::sphere::SphereRotation;
use crate::sphere::latlong::atan2_finite;

use super::chain::Along;
use super::gradient::Scheme;

/// A zonal source's `f_theta` along one column, and where it can be nonzero.
#[derive(Clone, Debug)]
pub(super) struct ZonalProfile<T> {
    /// `f_theta` at `theta = i delta`, `i` in `0..=m`: `(m + 1) x C`.
    pub(super) values: Vec<T>,
    /// Rows `r` and `r + 1` of `values` side by side for each `r` in `0..m`: `m x 2 x C`, so
    /// that a linear tap pair is one contiguous read.
    pub(super) spans: Vec<T>,
    /// `(low, high)`: a target whose pre-image has `cos Theta = q_y` outside `[low, high]`
    /// reads only zero rows of `values`, so its value is exactly zero and is not computed.
    /// Every clamped-cosine lobe (Phong, Blinn-Phong about their axes) is zero on a
    /// hemisphere or more.
    pub(super) cos_bounds: (f64, f64),
}

impl<T: Sample> ZonalProfile<T> {
    /// The profile `values` (`C` channels, rows `delta` apart) for `scheme`'s interpolation,
    /// and its bounds: past the first and last nonzero rows by the rows the taps reach (one
    /// for the linear scheme's pair, two for the cubic one's four,
    /// [`SourceGradient::interpolate_zonal`]) and a hundredth of a row more, so that the
    /// rounding of the computed angle never matters; no bound where that would reach a pole,
    /// across which the taps fold back.
    pub(super) fn new(values: Vec<T>, ch: usize, step: f64, scheme: Scheme) -> Self {
        let m = values.len() / ch - 1;
        let reach = match scheme {
            Scheme::Linear => 1.01,
            Scheme::Cubic => 2.01,
        };
        let nonzero = |i: &usize| values[i * ch..][..ch].iter().any(|v| *v != T::zero());
        let cos_bounds = match (0..=m).find(nonzero) {
            // A constant source: every derivative is zero.
            None => (f64::INFINITY, f64::NEG_INFINITY),
            Some(first) => {
                let last = (first..=m).rev().find(nonzero).unwrap_or(first);
                let (near, far) = (first as f64 - reach, last as f64 + reach);
                let high = if near > 0.0 {
                    (near * step).cos()
                } else {
                    f64::INFINITY
                };
                let low = if far < m as f64 {
                    (far * step).cos()
                } else {
                    f64::NEG_INFINITY
                };
                (low, high)
            }
        };
        let spans = (0..m)
            .flat_map(|r| values[r * ch..(r + 2) * ch].iter().copied())
            .collect();
        ZonalProfile {
            values,
            spans,
            cos_bounds,
        }
    }
}

/// For a zonal source, the chain rule's geometry along one row of targets: with `q = R p` the
/// pre-image of the target `p`, `Theta = atan2(rho, q_y)` (`rho` the length of `(q_x, q_z)`)
/// and `scale * dTheta/d(along) = -scale (R dp)_y / rho`. That factor is the general path's
/// `e_Theta(q) . R dp` (the two are equal because `q . R dp = 0`) with the frame at `q` never
/// formed: 18 products fewer per target. Its size is at most `|dp| <= 1`; it is clamped
/// there, so that a pre-image on a pole (`rho = 0`, where a zonal profile is exactly zero)
/// gives a finite factor. Along the row each of `q` and `(R dp)_y` is
/// `a + b sin(phi) + c cos(phi)`: the row's coefficients are formed once, in `G`.
pub(super) struct ZonalRow<G> {
    /// `[a, b, c]` of `q_x`, `q_y`, `q_z`.
    pub(super) q: [[G; 3]; 3],
    /// `[a, b, c]` of `(R dp)_y`.
    pub(super) t: [G; 3],
    pub(super) scale: G,
}

impl<G: Sample> ZonalRow<G> {
    /// The row at `(sin, cos)` of `theta`, for the derivative `along`, times `scale`.
    #[inline(always)]
    pub(super) fn new(
        rotation: &SphereRotation,
        (st, ct): (f64, f64),
        along: Along,
        scale: f64,
    ) -> Self {
        let r = rotation.matrix();
        let g = G::from_f64;
        let q = r.map(|row| [row[1] * ct, row[0] * st, row[2] * st].map(g));
        let t = match along {
            // dp/dtheta = (cos theta sin phi, -sin theta, cos theta cos phi)
            Along::Theta => [-r[1][1] * st, r[1][0] * ct, r[1][2] * ct],
            // dp/dphi = (sin theta cos phi, 0, -sin theta sin phi)
            Along::Phi => [0.0, -r[1][2] * st, r[1][0] * st],
        }
        .map(g);
        ZonalRow {
            q,
            t,
            scale: g(scale),
        }
    }

    #[inline(always)]
    pub(super) fn line([a, b, c]: [G; 3], sp: G, cp: G) -> G {
        a + b * sp + c * cp
    }

    /// Whether some target of the row may have its pre-image's `q_y` in `[low, high]`: along
    /// the row `q_y = a + b sin(phi) + c cos(phi)` stays within `a -+ sqrt(b^2 + c^2)`.
    #[inline(always)]
    pub(super) fn may_reach(&self, (low, high): (G, G)) -> bool {
        let [a, b, c] = self.q[1];
        let swing = (b * b + c * c).sqrt();
        a + swing >= low && a - swing <= high
    }

    /// Whether any target at the columns' `(sin, cos)` of `phi` has its pre-image's `q_y` in
    /// `[low, high]`. No early exit, so that the loop vectorises.
    #[inline(always)]
    pub(super) fn reaches(&self, (sines, cosines): (&[G], &[G]), (low, high): (G, G)) -> bool {
        let targets = sines.iter().zip(cosines);
        targets.fold(false, |any, (&sp, &cp)| {
            let qy = Self::line(self.q[1], sp, cp);
            any | ((qy >= low) & (qy <= high))
        })
    }

    /// `Theta` and the factor of each target at the columns' `(sin, cos)` of `phi` into
    /// `theta` and `alpha`. Branch-free, so that the loop vectorises.
    #[inline(always)]
    pub(super) fn angles(
        &self,
        (sines, cosines): (&[G], &[G]),
        (theta, alpha): (&mut [G], &mut [G]),
    ) {
        let (one, tiny, q, t) = (G::one(), G::min_positive_value(), self.q, self.t);
        let targets = theta.iter_mut().zip(alpha.iter_mut());
        for ((th, al), (&sp, &cp)) in targets.zip(sines.iter().zip(cosines)) {
            let qx = Self::line(q[0], sp, cp);
            let (qy, qz) = (Self::line(q[1], sp, cp), Self::line(q[2], sp, cp));
            let rho = (qx * qx + qz * qz).sqrt();
            *th = atan2_finite(rho, qy);
            let d = -Self::line(t, sp, cp) / rho.max(tiny);
            *al = self.scale * d.max(-one).min(one);
        }
    }
}

/// Targets of a zonal row computed together: four AVX2 vectors of `f32`.
pub(super) const ZONAL_CHUNK: usize = 32;

/// [`SourceGradient::interpolate_zonal`] of one channel of `f32` by the linear scheme, for
/// one chunk: the rows, weights and two taps of eight targets at a time, the taps gathered
/// from `spans` ([`ZonalProfile::spans`]) by the rows found. The operations of the portable
/// loop in the same order and with no fused multiply-adds, so the same bits; the rows are
/// clamped to `0..m` exactly as there, which keeps every gathered index in `spans`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(super) fn interpolate_f32_avx2(
    spans: &[f32],
    inverse_step: f32,
    (theta, alpha): (&[f32; ZONAL_CHUNK], &[f32; ZONAL_CHUNK]),
    out: &mut [f32; ZONAL_CHUNK],
) {
    use std::arch::x86_64::*;
    let m = spans.len() / 2;
    // Every row index is in 0..m, so every gathered index (2 row + 0 or 1) is in spans.
    assert!((1..1 << 24).contains(&m), "a profile of {m} rows");
    let (last, zero, one) = (
        _mm256_set1_ps((m - 1) as f32),
        _mm256_setzero_ps(),
        _mm256_set1_ps(1.0),
    );
    let step = _mm256_set1_ps(inverse_step);
    for k in (0..ZONAL_CHUNK).step_by(8) {
        let (theta, alpha, out) = (&theta[k..k + 8], &alpha[k..k + 8], &mut out[k..k + 8]);
        // SAFETY: the loads and the store touch the eight values of the slices above; every
        // gathered index (`at` and `at + 1`) is below 2m = spans.len() (the assertion above
        // and the clamp of the rows).
        unsafe {
            let y = _mm256_mul_ps(_mm256_loadu_ps(theta.as_ptr()), step);
            // floor, then min and max as the portable loop (a NaN takes the last row there too).
            let r = _mm256_max_ps(_mm256_min_ps(_mm256_floor_ps(y), last), zero);
            let fy = _mm256_sub_ps(y, r);
            let a = _mm256_loadu_ps(alpha.as_ptr());
            let (w0, w1) = (
                _mm256_mul_ps(a, _mm256_sub_ps(one, fy)),
                _mm256_mul_ps(a, fy),
            );
            let at = _mm256_slli_epi32::<1>(_mm256_cvttps_epi32(r));
            let here = _mm256_i32gather_ps::<4>(spans.as_ptr(), at);
            let next = _mm256_i32gather_ps::<4>(spans.as_ptr().add(1), at);
            let value = _mm256_add_ps(_mm256_mul_ps(w0, here), _mm256_mul_ps(w1, next));
            _mm256_storeu_ps(out.as_mut_ptr(), value);
        }
    }
}
