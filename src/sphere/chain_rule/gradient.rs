//! Step 1: the derivatives of the source map `f` on the edges of the working grid
//! ([`SourceGradient`]), in either [`Scheme`].

use std::f64::consts::PI;

use crate::Sample;
use crate::sphere::LatLongMap;
use crate::sphere::latlong::{catmull_rom, continue_index, for_each_row};

use super::zonal::ZonalProfile;

/// How the chain rule reads `f`'s derivatives and turns `g`'s into differences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Alnasser 2008's: two-point differences of `f`, bilinear interpolation at the pre-image,
    /// `g`'s differences as `delta` times its midpoint derivative ([`Method::Haar`]).
    ///
    /// [`Method::Haar`]: crate::sphere::Method::Haar
    #[default]
    Linear,
    /// Higher order: four-point differences of `f`, Catmull-Rom interpolation at the
    /// pre-image, `g`'s differences corrected by the third derivative along the difference
    /// ([`Method::HaarCubic`]).
    ///
    /// [`Method::HaarCubic`]: crate::sphere::Method::HaarCubic
    Cubic,
}

/// The derivatives of a source map on its staggered edge grids (step 1 of the
/// [module docs](super)), ready to be evaluated anywhere on the sphere.
///
/// ```
/// use haarshift::sphere::{LatLongMap, chain_rule::SourceGradient};
/// // f = y = cos theta: f_theta = -sin theta, f_phi = 0.
/// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = d[1]).unwrap();
/// let grad = SourceGradient::new(&f);
/// let (mut ft, mut gp) = ([0.0], [0.0]);
/// grad.eval(1.0, 2.0, &mut ft, &mut gp);
/// assert!((ft[0] + 1.0f64.sin()).abs() < 1e-3 && gp[0].abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct SourceGradient<T> {
    pub(super) scheme: Scheme,
    pub(super) m: usize,
    pub(super) n: usize,
    pub(super) channels: usize,
    pub(super) step: f64,
    /// `1 / step`.
    pub(super) inverse_step: f64,
    /// `f_theta` at `(i delta, (j + 1/2) delta)`, `i` in `0..=m`: `(m + 1) x n x C`.
    pub(super) d_theta: Vec<T>,
    /// `f_phi / sin theta` at `((i + 1/2) delta, (j + 1) delta)`: `m x n x C`.
    pub(super) d_phi: Vec<T>,
    /// For a zonal `f` (constant along every row: a lobe about the pole), `f_theta` of one
    /// column; `d_phi` is then zero.
    pub(super) zonal: Option<ZonalProfile<T>>,
    /// `(sin, cos)` of `k delta / 2`, `k` in `0..=2n + 2`: every angle the target grids use.
    pub(super) trig: Vec<(f64, f64)>,
    /// The column angles of the two target grids as flat arrays, for loops over a row:
    /// `[sin, cos]` of `(j + 1/2) delta` (index 0) and of `(j + 1) delta` (index 1).
    pub(super) columns: [[Vec<T>; 2]; 2],
}

impl<T: Sample> SourceGradient<T> {
    /// The derivative maps of `approx` (an approximation of `f` at the working resolution)
    /// by the two-point differences of [`Scheme::Linear`].
    pub fn new(approx: &LatLongMap<T>) -> Self {
        Self::with_scheme(approx, Scheme::Linear)
    }

    /// The derivative maps of `approx` by `scheme`'s differences: two-point
    /// `(X[k] - X[k-1]) / delta`, or four-point
    /// `(27 (X[k] - X[k-1]) - (X[k+1] - X[k-2])) / (24 delta)` (fourth order for samples).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::{Scheme, SourceGradient}};
    /// let f = LatLongMap::<f64>::from_fn(64, 1, |d, out| out[0] = d[1]).unwrap();
    /// let grad = SourceGradient::with_scheme(&f, Scheme::Cubic);
    /// let (mut ft, mut gp) = ([0.0], [0.0]);
    /// grad.eval(1.0, 2.0, &mut ft, &mut gp);
    /// assert!((ft[0] + 1.0f64.sin()).abs() < 1e-5 && gp[0].abs() < 1e-12);
    /// ```
    pub fn with_scheme(approx: &LatLongMap<T>, scheme: Scheme) -> Self {
        let (m, n, ch) = approx.as_array().dim();
        let x = approx.as_array();
        let x = x.as_slice().expect("maps are in standard layout");
        let step = PI / m as f64;
        let px = |r: isize, c: isize| {
            let (r, c, _) = continue_index(r, c, m, n);
            &x[(r * n + c) * ch..][..ch]
        };
        let mut d_theta = vec![T::zero(); (m + 1) * n * ch];
        for_each_row(&mut d_theta, n * ch, |i, row| {
            let inv = T::from_f64(1.0 / step);
            let i = i as isize;
            for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                let j = j as isize;
                difference(scheme, out, inv, |k| px(i + k, j));
            }
        });
        let mut d_phi = vec![T::zero(); m * n * ch];
        for_each_row(&mut d_phi, n * ch, |i, row| {
            let inv = T::from_f64(1.0 / (step * ((i as f64 + 0.5) * step).sin()));
            let i = i as isize;
            for (j, out) in row.chunks_exact_mut(ch).enumerate() {
                let j = j as isize;
                difference(scheme, out, inv, |k| px(i, j + 1 + k));
            }
        });
        // Zonal exactly, not nearly: the zonal path then gives what the general one would.
        let zonal = (d_phi.iter().all(|v| *v == T::zero())
            && d_theta
                .chunks_exact(n * ch)
                .all(|row| row.chunks_exact(ch).all(|px| px == &row[..ch])))
        .then(|| {
            let values: Vec<T> = d_theta
                .chunks_exact(n * ch)
                .flat_map(|row| row[..ch].to_vec())
                .collect();
            ZonalProfile::new(values, ch, step, scheme)
        });
        let half = 0.5 * step;
        let trig: Vec<(f64, f64)> = (0..=2 * n + 2)
            .map(|k| (k as f64 * half).sin_cos())
            .collect();
        let columns = [1, 2].map(|first| {
            let at = |j: usize| trig[first + 2 * j];
            [
                (0..n).map(|j| T::from_f64(at(j).0)).collect(),
                (0..n).map(|j| T::from_f64(at(j).1)).collect(),
            ]
        });
        SourceGradient {
            scheme,
            m,
            n,
            channels: ch,
            step,
            inverse_step: 1.0 / step,
            d_theta,
            d_phi,
            zonal,
            trig,
            columns,
        }
    }

    /// Whether `f` is constant along every row (a function of `theta` alone, such as a lobe
    /// about the pole): its derivatives are then one column of `f_theta`, and a rotation
    /// needs only the angle of each pre-image from the pole.
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::SourceGradient};
    /// let lobe = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[1].max(0.0).powi(8)).unwrap();
    /// let tilted = LatLongMap::<f64>::from_fn(16, 1, |d, out| out[0] = d[0].max(0.0)).unwrap();
    /// assert!(SourceGradient::new(&lobe).is_zonal() && !SourceGradient::new(&tilted).is_zonal());
    /// ```
    pub fn is_zonal(&self) -> bool {
        self.zonal.is_some()
    }

    /// `f_theta` and `f_phi / sin theta` at `(theta, phi)`, one value per channel each
    /// (step 3 of the [module docs](super)), interpolated as the scheme says.
    pub fn eval(&self, theta: f64, phi: f64, f_theta: &mut [T], f_phi_over_sin: &mut [T]) {
        self.write(theta, phi, 1.0, 0.0, 0, f_theta);
        self.write(theta, phi, 0.0, 1.0, 0, f_phi_over_sin);
    }

    /// Writes `alpha f_theta + beta f_phi / sin theta` at `(theta, phi)` (`theta` in
    /// `[0, pi]`, `phi` in `[0, 2 pi)`) into `out`: the chain rule's combination, fused with
    /// the interpolation so that no temporary is written. The fields are read `turn` columns
    /// further on, which is reading the fields of `f` turned by `turn` columns
    /// ([`yaw_pixels`](super::yaw::yaw_pixels)) with the same taps and weights.
    #[inline]
    pub(super) fn write(
        &self,
        theta: f64,
        phi: f64,
        alpha: f64,
        beta: f64,
        turn: usize,
        out: &mut [T],
    ) {
        if let Some(zonal) = &self.zonal {
            return self.interpolate_zonal(zonal, &[theta], &[alpha], out);
        }
        out.fill(T::zero());
        match self.scheme {
            Scheme::Linear => self.accumulate_linear((theta, phi), (alpha, beta), turn, out),
            Scheme::Cubic => self.accumulate_cubic((theta, phi), (alpha, beta), turn, out),
        }
    }

    /// [`write`](Self::write) of a zonal `f` for a run of targets: writes
    /// `alpha[j] f_theta(theta[j])` into pixel `j` of `out` (`C` values each). `f_phi` is zero
    /// and every column of `f_theta` is `profile`, so the bilinear (Catmull-Rom)
    /// interpolation of the general path reduces to a linear (cubic) one along `theta`, its
    /// weights across the columns summing to 1; across a pole the profile continues negated
    /// (a tangent component). The linear scheme computes in `T` (its two taps need no
    /// more), the cubic one in `f64`, rounded once per value.
    #[inline(always)]
    pub(super) fn interpolate_zonal<A: Sample>(
        &self,
        profile: &ZonalProfile<T>,
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        // The common channel counts as constants, so the channel loop disappears.
        match self.channels {
            1 => self.interpolate_zonal_channels::<1, A>(profile, theta, alpha, out),
            3 => self.interpolate_zonal_channels::<3, A>(profile, theta, alpha, out),
            _ => self.interpolate_zonal_channels::<0, A>(profile, theta, alpha, out),
        }
    }

    /// [`interpolate_zonal`](Self::interpolate_zonal) for `CH` channels (0: any number).
    #[inline(always)]
    pub(super) fn interpolate_zonal_channels<const CH: usize, A: Sample>(
        &self,
        profile: &ZonalProfile<T>,
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        let (m, ch) = (self.m, if CH == 0 { self.channels } else { CH });
        if self.scheme == Scheme::Linear {
            self.interpolate_zonal_linear::<CH, A>(&profile.spans, theta, alpha, out);
            return;
        }
        let profile = &profile.values;
        let targets = out.chunks_exact_mut(ch).zip(theta.iter().zip(alpha));
        for (px, (&theta, &alpha)) in targets {
            let (y, alpha) = (theta.as_f64() * self.inverse_step, alpha.as_f64());
            // (entry, weight) of the four taps along the profile, continued over the poles.
            let mut taps = [(0usize, 0.0); 4];
            let r0 = (y + 1.0) as isize - 1;
            for (dr, w) in catmull_rom(y - r0 as f64).into_iter().enumerate() {
                let row = r0 - 1 + dr as isize;
                let (r, w) = if row < 0 {
                    (-row, -w)
                } else if row > m as isize {
                    (2 * m as isize - row, -w)
                } else {
                    (row, w)
                };
                taps[dr] = (r as usize * ch, alpha * w);
            }
            for k in 0..ch {
                let value: f64 = taps
                    .iter()
                    .map(|&(at, w)| w * profile[at + k].as_f64())
                    .sum();
                px[k] = T::from_f64(value);
            }
        }
    }

    /// The linear interpolation of [`interpolate_zonal`](Self::interpolate_zonal): two taps,
    /// never across a pole (rows `0..=m` hold every `theta` in `[0, pi]`), in `T`. A chunk
    /// of targets at a time: first each target's row and weights, in a loop without lookups
    /// (it vectorises but for the saturating float-to-index conversion), then the lookups:
    /// each reads one span of two neighbouring rows ([`ZonalProfile::spans`]) and takes three
    /// operations a value. The AVX2 build does both for one channel of `f32` with vector
    /// conversions and gathers ([`interpolate_f32_avx2`]).
    #[inline(always)]
    pub(super) fn interpolate_zonal_linear<const CH: usize, A: Sample>(
        &self,
        spans: &[T],
        theta: &[A],
        alpha: &[A],
        out: &mut [T],
    ) {
        const CHUNK: usize = 32;
        let (m, ch) = (self.m, if CH == 0 { self.channels } else { CH });
        let spans = &spans[..2 * m * ch];
        let (inverse_step, last) = (T::from_f64(self.inverse_step), T::from_f64((m - 1) as f64));
        let chunks = theta.chunks(CHUNK).zip(alpha.chunks(CHUNK));
        for ((theta, alpha), out) in chunks.zip(out.chunks_mut(CHUNK * ch)) {
            let (mut at, mut w0, mut w1) = ([0u32; CHUNK], [T::zero(); CHUNK], [T::zero(); CHUNK]);
            let taps = at.iter_mut().zip(w0.iter_mut().zip(w1.iter_mut()));
            for ((at, (w0, w1)), (&theta, &alpha)) in taps.zip(theta.iter().zip(alpha)) {
                let y = T::from_f64(theta.as_f64()) * inverse_step;
                // theta is finite (atan2), so is y: the row is in 0..m and exact.
                let r = y.floor().min(last).max(T::zero());
                let (fy, alpha) = (y - r, T::from_f64(alpha.as_f64()));
                *at = r.as_f64() as u32 * ch as u32;
                *w0 = alpha * (T::one() - fy);
                *w1 = alpha * fy;
            }
            let taps = at.iter().zip(w0.iter().zip(&w1));
            for (px, (&at, (&w0, &w1))) in out.chunks_exact_mut(ch).zip(taps) {
                let (here, next) = spans[2 * at as usize..][..2 * ch].split_at(ch);
                for k in 0..ch {
                    px[k] = w0 * here[k] + w1 * next[k];
                }
            }
        }
    }

    /// [`accumulate`](Self::accumulate) by bilinear interpolation.
    #[inline]
    pub(super) fn accumulate_linear(
        &self,
        (theta, phi): (f64, f64),
        (alpha, beta): (f64, f64),
        turn: usize,
        out: &mut [T],
    ) {
        let (m, n) = (self.m, self.n);
        // Columns from -1 to below 3n (a half turn over a pole plus the turn) onto 0..n.
        let wrap = |c: isize| -> usize {
            let c = c + turn as isize;
            if c < 0 {
                (c + n as isize) as usize
            } else if c >= 2 * n as isize {
                c as usize - 2 * n
            } else if c >= n as isize {
                c as usize - n
            } else {
                c as usize
            }
        };
        // (entry, weight) of the four taps of each field.
        let mut ft = [(0usize, T::zero()); 4];
        let mut gp = [(0usize, T::zero()); 4];
        // f_theta: rows at theta = i delta, i = 0..=m; no continuation needed in theta.
        // (Positions are at least -1, so `(x + 1) as isize - 1` is their floor.)
        let y = theta / self.step;
        let r0 = (y as usize).min(m - 1);
        let fy = y - r0 as f64;
        let x = phi / self.step - 0.5;
        let c0 = (x + 1.0) as isize - 1;
        let fx = x - c0 as f64;
        let (ca, cb) = (wrap(c0), wrap(c0 + 1));
        for (t, (r, wy)) in [(r0, 1.0 - fy), (r0 + 1, fy)].into_iter().enumerate() {
            ft[2 * t] = (r * n + ca, T::from_f64(alpha * wy * (1.0 - fx)));
            ft[2 * t + 1] = (r * n + cb, T::from_f64(alpha * wy * fx));
        }
        // f_phi / sin theta: rows at (i + 1/2) delta, columns at (j + 1) delta; over a pole
        // (rows -1 and m) the row is continued half a turn away and the tangent component
        // flips sign.
        let y = theta / self.step - 0.5;
        let r0 = (y + 1.0) as isize - 1;
        let fy = y - r0 as f64;
        let x = phi / self.step - 1.0;
        let c0 = (x + 1.0) as isize - 1;
        let fx = x - c0 as f64;
        let half = n as isize / 2;
        for (t, (r, wy)) in [(r0, 1.0 - fy), (r0 + 1, fy)].into_iter().enumerate() {
            let (r, across, w) = if r < 0 {
                (0, half, -beta * wy)
            } else if r >= m as isize {
                (m - 1, half, -beta * wy)
            } else {
                (r as usize, 0, beta * wy)
            };
            gp[2 * t] = (r * n + wrap(c0 + across), T::from_f64(w * (1.0 - fx)));
            gp[2 * t + 1] = (r * n + wrap(c0 + 1 + across), T::from_f64(w * fx));
        }
        self.apply_taps(&ft, &gp, out);
    }

    /// `out[k] += sum w d_theta[e][k] + sum w d_phi[e][k]` over the `(entry, weight)` taps
    /// of each field, one channel at a time so that the sum stays in a register.
    #[inline]
    pub(super) fn apply_taps(&self, ft: &[(usize, T)], gp: &[(usize, T)], out: &mut [T]) {
        let ch = self.channels;
        for (k, o) in out.iter_mut().enumerate() {
            let mut acc = *o;
            for &(e, w) in ft {
                acc += w * self.d_theta[e * ch + k];
            }
            for &(e, w) in gp {
                acc += w * self.d_phi[e * ch + k];
            }
            *o = acc;
        }
    }

    /// [`accumulate`](Self::accumulate) by Catmull-Rom interpolation over 4 x 4 edges of
    /// each field, continued over the seam and the poles (a tangent component changes sign
    /// across a pole: `f_theta` on the edge rows `-k` and `m + k` is minus the one on rows
    /// `k` and `m - k` half a turn away).
    #[inline]
    pub(super) fn accumulate_cubic(
        &self,
        (theta, phi): (f64, f64),
        (alpha, beta): (f64, f64),
        turn: usize,
        out: &mut [T],
    ) {
        let (m, n) = (self.m as isize, self.n as isize);
        let turn = turn as isize;
        // f_theta: rows at i delta (i = 0..=m), columns at (j + 1/2) delta.
        let ft = cubic_taps((theta / self.step, phi / self.step - 0.5), alpha, |r, c| {
            let (r, flip) = if r < 0 {
                (-r, true)
            } else if r > m {
                (2 * m - r, true)
            } else {
                (r, false)
            };
            let c = if flip { c + n / 2 } else { c } + turn;
            (r as usize * self.n + c.rem_euclid(n) as usize, flip)
        });
        // f_phi / sin theta: rows at (i + 1/2) delta, columns at (j + 1) delta.
        let gp = cubic_taps(
            (theta / self.step - 0.5, phi / self.step - 1.0),
            beta,
            |r, c| {
                let (r, c, crossed) = continue_index(r, c + turn, self.m, self.n);
                (r * self.n + c, crossed)
            },
        );
        self.apply_taps(&ft, &gp, out);
    }
}

/// The derivative of `scheme` at the edge between samples `at(-1)` and `at(0)`, times
/// `inv` (`1 / delta`, or that over `sin theta`), into `out`.
#[inline]
pub(super) fn difference<'a, T: Sample>(
    scheme: Scheme,
    out: &mut [T],
    inv: T,
    at: impl Fn(isize) -> &'a [T],
) {
    match scheme {
        Scheme::Linear => {
            for ((o, &b), &a) in out.iter_mut().zip(at(0)).zip(at(-1)) {
                *o = (b - a) * inv;
            }
        }
        Scheme::Cubic => {
            let (near, far) = (T::from_f64(27.0 / 24.0), T::from_f64(1.0 / 24.0));
            let (a, b, c, d) = (at(-2), at(-1), at(0), at(1));
            for (k, o) in out.iter_mut().enumerate() {
                *o = (near * (c[k] - b[k]) - far * (d[k] - a[k])) * inv;
            }
        }
    }
}

/// The 16 `(entry, weight)` taps of `scale` times the Catmull-Rom interpolation of a
/// staggered field at continuous grid position `(y, x)` (entries at whole numbers, `y` and
/// `x` at least -1). `index(r, c)` continues an entry position over seam and poles: its
/// entry and whether to negate it.
#[inline]
fn cubic_taps<T: Sample>(
    (y, x): (f64, f64),
    scale: f64,
    index: impl Fn(isize, isize) -> (usize, bool),
) -> [(usize, T); 16] {
    let (r0, c0) = ((y + 1.0) as isize - 1, (x + 1.0) as isize - 1);
    let (wy, wx) = (catmull_rom(y - r0 as f64), catmull_rom(x - c0 as f64));
    let (r0, c0) = (r0 - 1, c0 - 1);
    let mut taps = [(0usize, T::zero()); 16];
    for (dr, &wr) in wy.iter().enumerate() {
        let wr = scale * wr;
        for (dc, &wc) in wx.iter().enumerate() {
            let (at, flip) = index(r0 + dr as isize, c0 + dc as isize);
            taps[4 * dr + dc] = (at, T::from_f64(if flip { -wr * wc } else { wr * wc }));
        }
    }
    taps
}
