//! Step 5: the rotated map's difference fields and the detail coefficients read off them at
//! every level by the exact recursive filters ((4.18)-(4.22)).

use ndarray::{
    Array2, Array3, ArrayBase, ArrayView3, ArrayViewMut2, Axis, CowArray, Data, Dimension, Ix2, s,
};

use crate::sphere::latlong::rows_from_fn;
use crate::sphere::{LatLongMap, SphereCoefficients, SphereRotation};
use crate::transform::{Band, pyramid};
use crate::{Error, Result, Sample};

use super::chain::{Along, ChainRule};
use super::gradient::{Scheme, SourceGradient};

/// The differences of the rotated map at one resolution (steps 2-4 of the
/// [module docs](super)): `V` (between rows), `U` (between columns, periodic) and `C` (mixed).
///
/// ```
/// use haarshift::sphere::{LatLongMap, SphereRotation, chain_rule::{DifferenceFields, Scheme}};
/// let f = LatLongMap::<f64>::from_fn(8, 1, |_, out| out[0] = 1.0).unwrap();
/// let r = SphereRotation::from_degrees(0.0, 40.0, 0.0).unwrap();
/// let d = DifferenceFields::rotated(&f, &r, Scheme::Linear);
/// assert_eq!(d.vertical().dim(), (7, 16, 1));
/// assert!(d.horizontal().iter().all(|v| v.abs() < 1e-15)); // a constant has no differences
/// ```
#[derive(Clone, Debug)]
pub struct DifferenceFields<T> {
    pub(super) v: Array3<T>,
    pub(super) u: Array3<T>,
}

impl<T: Sample> DifferenceFields<T> {
    /// The fields of `g = f(R p)` from `approx` (`f` at the working resolution) by `scheme`.
    pub fn rotated(approx: &LatLongMap<T>, rotation: &SphereRotation, scheme: Scheme) -> Self {
        Self::from_gradient(&SourceGradient::with_scheme(approx, scheme), rotation, 0)
    }

    /// The fields of `g = f_k(R p)`, `f_k` the source of `grad` turned by `turn` columns.
    pub(super) fn from_gradient(
        grad: &SourceGradient<T>,
        rotation: &SphereRotation,
        turn: usize,
    ) -> Self {
        let (m, n, ch, scheme) = (grad.m, grad.n, grad.channels, grad.scheme);
        let rule = ChainRule::new(grad, rotation, turn);
        let (v, u) = match scheme {
            // V[i][j] = -delta g_theta((i + 1) delta, (j + 1/2) delta),
            // U[i][j] = -delta g_phi((i + 1/2) delta, (j + 1) delta).
            Scheme::Linear => (
                rule.field(m - 1, |i| 2 * i + 2, 1, Along::Theta, -grad.step),
                rule.field(m, |i| 2 * i + 1, 2, Along::Phi, -grad.step),
            ),
            Scheme::Cubic => {
                // Midpoint derivatives on every row edge, the two across the poles included,
                // then the differences of samples to fourth order:
                // X[k] - X[k+1] = -delta (g_1 + delta^2 g_3 / 24) at the edge between them,
                // g_3 (the third derivative) from second differences of the midpoint values.
                let vm = rule.field(m + 1, |e| 2 * e, 1, Along::Theta, -grad.step);
                let um = rule.field(m, |i| 2 * i + 1, 2, Along::Phi, -grad.step);
                let w = T::from_f64(1.0 / 24.0);
                let two = T::from_f64(2.0);
                let (vm, um, len) = (flat(&vm), flat(&um), n * ch);
                let v = rows_from_fn((m - 1, n, ch), |i, out| {
                    let (above, here, below) =
                        (row(vm, len, i), row(vm, len, i + 1), row(vm, len, i + 2));
                    for (e, o) in out.iter_mut().enumerate() {
                        let c = here[e];
                        *o = c + w * (above[e] - two * c + below[e]);
                    }
                });
                let u = rows_from_fn((m, n, ch), |i, out| {
                    let here = row(um, len, i);
                    for (e, o) in out.iter_mut().enumerate() {
                        let c = here[e];
                        let (left, right) = (here[before(e, ch, len)], here[after(e, ch, len)]);
                        *o = c + w * (left - two * c + right);
                    }
                });
                (v, u)
            }
        };
        DifferenceFields { v, u }
    }

    /// The exact differences of a map `x` (the identity a rotation's fields approximate).
    ///
    /// ```
    /// use haarshift::sphere::{LatLongMap, chain_rule::DifferenceFields};
    /// let x = LatLongMap::<f64>::from_fn(4, 1, |d, out| out[0] = d[0]).unwrap();
    /// let d = DifferenceFields::of_map(&x);
    /// let a = x.as_array();
    /// assert_eq!(d.vertical()[[1, 3, 0]], a[[1, 3, 0]] - a[[2, 3, 0]]);
    /// assert_eq!(d.horizontal()[[2, 7, 0]], a[[2, 7, 0]] - a[[2, 0, 0]]); // periodic
    /// ```
    pub fn of_map(x: &LatLongMap<T>) -> Self {
        let a = x.as_array();
        let (m, n, ch) = a.dim();
        let (x, len) = (flat_view(&a), n * ch);
        let v = rows_from_fn((m - 1, n, ch), |i, out| {
            let (here, below) = (row(x, len, i), row(x, len, i + 1));
            for ((o, &a), &b) in out.iter_mut().zip(here).zip(below) {
                *o = a - b;
            }
        });
        let u = rows_from_fn((m, n, ch), |i, out| {
            let here = row(x, len, i);
            for (e, o) in out.iter_mut().enumerate() {
                *o = here[e] - here[after(e, ch, len)];
            }
        });
        DifferenceFields { v, u }
    }

    /// `V`: `(m - 1, n, C)`, `V[i][j] = X[i][j] - X[i+1][j]`.
    pub fn vertical(&self) -> ArrayView3<'_, T> {
        self.v.view()
    }

    /// `U`: `(m, n, C)`, `U[i][j] = X[i][j] - X[i][j+1]` (periodic).
    pub fn horizontal(&self) -> ArrayView3<'_, T> {
        self.u.view()
    }

    /// `C`: `(m - 1, n, C)`, `C[i][j] = X[i][j] - X[i][j+1] - X[i+1][j] + X[i+1][j+1]`, the
    /// mean of its two expressions in `V` and `U` (step 4). Not stored: the diagonal
    /// details read it where they need it (step 5).
    pub fn diagonal(&self) -> Array3<T> {
        mixed_from(&self.v, &self.u)
    }

    /// All detail levels of the `m x 2m` pyramid these fields describe, the root's two
    /// scaling coefficients set to `(+d/2, -d/2)` with `d` their difference from the root
    /// field (the constant is fixed later by [`set_mean_from_energy`](super::set_mean_from_energy)).
    pub fn to_coefficients(&self) -> Result<SphereCoefficients<T>> {
        let (m, n, ch) = self.u.dim();
        if m < 2 || !m.is_power_of_two() || n != 2 * m {
            return Err(Error::shape(
                &[m, n, ch],
                "fields of an m x 2m grid, m >= 2",
            ));
        }
        let mut out = Array3::zeros((ch, m, n));
        let half = T::from_f64(0.5);
        for (k, mut plane) in out.axis_iter_mut(Axis(0)).enumerate() {
            // One channel at a time (a view when there is one channel), so that the column
            // pairs of a row are `[T; 2]` chunks.
            let mut fields = ChannelFields {
                v: channel(&self.v, k),
                u: channel(&self.u, k),
            };
            while fields.u.nrows() > 1 {
                let (v, u) = fields.next_level(&mut plane);
                fields = ChannelFields {
                    v: v.into(),
                    u: u.into(),
                };
            }
            // At the 1 x 2 root, U[0][0] = A0 - A1 and U[0][1] = A1 - A0.
            let d = half * (fields.u[[0, 0]] - fields.u[[0, 1]]);
            plane[[0, 0]] = half * d;
            plane[[0, 1]] = -half * d;
        }
        SphereCoefficients::from_array(out)
    }
}

/// One channel's `V` and `U` (step 5 runs channel by channel).
struct ChannelFields<'a, T> {
    pub(super) v: CowArray<'a, T, Ix2>,
    pub(super) u: CowArray<'a, T, Ix2>,
}

impl<T: Sample> ChannelFields<'_, T> {
    /// One level of step 5: writes the details of the level whose blocks are 2 x 2 cells of
    /// this grid into `plane`, `b = (V[2I][2J] + V[2I][2J+1]) / 4`,
    /// `a = (U[2I][2J] + U[2I+1][2J]) / 4` and `c = C[2I][2J] / 4` (`C` from `V` and `U`),
    /// and returns the fields `(V', U')` one level coarser (the recursive filters (4.21)-(4.22)):
    /// `V' = h_t (along theta) x h_s (along phi) of V / 4`, `U'` with the roles swapped.
    /// Alnasser 2008's third recursion, `C' = h_t x h_t of C / 4`, is not needed: it is the mixed
    /// difference of `V'` and `U'` exactly (`h_t` applied to a difference along an axis is
    /// the difference of `h_s` applied along it: `[1 2 1] * [1 -1] = [1 1] * [1 0 -1]`), so
    /// `C` is read off `V` and `U` at every level.
    pub(super) fn next_level(&self, plane: &mut ArrayViewMut2<'_, T>) -> (Array2<T>, Array2<T>) {
        let (m, n) = self.u.dim();
        let (mh, nh) = (m / 2, n / 2);
        let (q, two) = (T::from_f64(0.25), T::from_f64(2.0));
        let (v, u) = (flat(&self.v), flat(&self.u));
        let level = mh.trailing_zeros() as usize;
        let size = plane.dim();
        let levels = size.0.trailing_zeros() as usize;
        // Row i of band b is written by `f(i, row)`.
        let mut band = |b: Band, f: &dyn Fn(usize, &mut [T])| {
            let (rows, cols) = pyramid::band_ranges(size, levels, b, level).expect("level exists");
            let mut view = plane.slice_mut(s![rows, cols]);
            for (i, mut band_row) in view.rows_mut().into_iter().enumerate() {
                f(
                    i,
                    band_row.as_slice_mut().expect("plane rows are contiguous"),
                );
            }
        };
        band(Band::Vertical, &|i, out| {
            for (o, p) in out.iter_mut().zip(pairs(row(v, n, 2 * i))) {
                *o = q * (p[0] + p[1]);
            }
        });
        band(Band::Horizontal, &|i, out| {
            let (u0, u1) = (pairs(row(u, n, 2 * i)), pairs(row(u, n, 2 * i + 1)));
            for (o, (p0, p1)) in out.iter_mut().zip(u0.iter().zip(u1)) {
                *o = q * (p0[0] + p1[0]);
            }
        });
        band(Band::Diagonal, &|i, out| {
            let vr = pairs(row(v, n, 2 * i));
            let (u0, u1) = (pairs(row(u, n, 2 * i)), pairs(row(u, n, 2 * i + 1)));
            for (o, (pv, (p0, p1))) in out.iter_mut().zip(vr.iter().zip(u0.iter().zip(u1))) {
                *o = q * mixed(pv[0], pv[1], p0[0], p1[0]);
            }
        });
        let v = rows_of((mh.saturating_sub(1), nh), |i, out| {
            let (a, b, d) = (
                pairs(row(v, n, 2 * i)),
                pairs(row(v, n, 2 * i + 1)),
                pairs(row(v, n, 2 * i + 2)),
            );
            for (o, (a, (b, d))) in out.iter_mut().zip(a.iter().zip(b.iter().zip(d))) {
                let c0 = a[0] + two * b[0] + d[0];
                let c1 = a[1] + two * b[1] + d[1];
                *o = q * (c0 + c1);
            }
        });
        let u = rows_of((mh, nh), |i, out| {
            let (a, b) = (row(u, n, 2 * i), row(u, n, 2 * i + 1));
            // `[1 2 1]` along each row from column 2j: columns 2j, 2j + 1 and the next pair's
            // first (periodic).
            let cell = |a: [T; 3], b: [T; 3]| {
                let t0 = a[0] + two * a[1] + a[2];
                let t1 = b[0] + two * b[1] + b[2];
                q * (t0 + t1)
            };
            let (last, out) = out.split_last_mut().expect("a row has columns");
            let (here, next) = (
                pairs(a).iter().zip(pairs(b)),
                pairs(&a[2..]).iter().zip(pairs(&b[2..])),
            );
            for (o, ((a, b), (a2, b2))) in out.iter_mut().zip(here.zip(next)) {
                *o = cell([a[0], a[1], a2[0]], [b[0], b[1], b2[0]]);
            }
            *last = cell([a[n - 2], a[n - 1], a[0]], [b[n - 2], b[n - 1], b[0]]);
        });
        (v, u)
    }
}

/// Channel `k` of a grid in standard layout: a view when it is the only one.
pub(super) fn channel<T: Sample>(a: &Array3<T>, k: usize) -> CowArray<'_, T, Ix2> {
    let view = a.index_axis(Axis(2), k);
    if view.is_standard_layout() {
        view.into()
    } else {
        view.as_standard_layout().into_owned().into()
    }
}

/// The column pairs `(2j, 2j + 1)` of a one-channel row (a trailing odd entry left out).
#[inline]
fn pairs<T>(row: &[T]) -> &[[T; 2]] {
    row.as_chunks::<2>().0
}

/// A `(rows, cols)` array whose row `i` is written by `f(i, row)`: [`rows_from_fn`] of one
/// channel.
fn rows_of<T: Sample>(shape: (usize, usize), f: impl Fn(usize, &mut [T]) + Sync) -> Array2<T> {
    rows_from_fn((shape.0, shape.1, 1), f)
        .into_shape_with_order(shape)
        .expect("one channel")
}

/// The values of a grid of this module (always built in standard layout).
pub(super) fn flat<T, S: Data<Elem = T>, D: Dimension>(a: &ArrayBase<S, D>) -> &[T] {
    a.as_slice().expect("standard layout")
}

/// The values of a standard-layout view.
fn flat_view<'a, T>(a: &ArrayView3<'a, T>) -> &'a [T] {
    a.to_slice().expect("maps are in standard layout")
}

/// Row `i` of a grid with rows of `len` values.
#[inline]
pub(super) fn row<T>(values: &[T], len: usize, i: usize) -> &[T] {
    &values[i * len..][..len]
}

/// The entry one column on from entry `e` of a periodic row of `len` values, `ch` a column.
#[inline]
fn after(e: usize, ch: usize, len: usize) -> usize {
    if e + ch < len { e + ch } else { e + ch - len }
}

/// The entry one column back from entry `e` of a periodic row.
#[inline]
pub(super) fn before(e: usize, ch: usize, len: usize) -> usize {
    if e >= ch { e - ch } else { e + len - ch }
}

/// `C = (V[i][j] - V[i][j+1] + U[i][j] - U[i+1][j]) / 2`, the mixed difference from both
/// first-difference fields (step 4).
fn mixed_from<T: Sample>(v: &Array3<T>, u: &Array3<T>) -> Array3<T> {
    let (rows, n, ch) = v.dim();
    let (v, u, len) = (flat(v), flat(u), n * ch);
    rows_from_fn((rows, n, ch), |i, out| {
        let (vr, u0, u1) = (row(v, len, i), row(u, len, i), row(u, len, i + 1));
        for (e, o) in out.iter_mut().enumerate() {
            *o = mixed(vr[e], vr[after(e, ch, len)], u0[e], u1[e]);
        }
    })
}

/// `C[i][j]` from `V[i][j]`, `V[i][j+1]`, `U[i][j]` and `U[i+1][j]`: the mean of its two
/// expressions (step 4).
#[inline(always)]
fn mixed<T: Sample>(v0: T, v1: T, u0: T, u1: T) -> T {
    T::from_f64(0.5) * (v0 - v1 + u0 - u1)
}
