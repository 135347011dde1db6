//! Random access: one coefficient of the shifted transform in O(1), from prefix sums of the
//! D tables prepared once in O(n).
//!
//! Every Haar coefficient is a signed sum of samples over at most four aligned boxes (the
//! quadrants of its support), divided by its normalisation. After a shift those boxes move,
//! and a box sum of the *shifted* signal is a box sum of the *original* one over the moved box
//! (for a fractional shift, the integral of the piecewise-constant upsampled signal over it).
//! With the prefix sums (1D) or the summed-area table (2D) of `D = x - mean` (Alnasser 2008's
//! `D^N`, eq. 2.4 / 3.3: the finest approximation minus the DC value) a box sum is four table
//! reads, and a fractional corner is the (bi)linear interpolation of the table, because the
//! integral of a piecewise-constant signal is piecewise (bi)linear. Subtracting the mean keeps
//! the tables near zero (they close to exactly zero around the period), so the sums keep their
//! precision on large images.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2, s};
use rayon::prelude::*;

use super::GridShift;
use crate::transform::{Band, Band1d, Coefficients, Layout, Normalization, haar1d, pyramid};
use crate::{Error, Result, Sample};

/// Weight of a box sum in a coefficient whose support is `w` samples along each of `dims`
/// axes: the height of the basis function (see [`basis`](crate::transform::basis)).
fn box_weight(norm: Normalization, w: usize, dims: i32) -> f64 {
    match norm {
        Normalization::Average => 1.0 / (w as f64).powi(dims),
        Normalization::Orthonormal => 1.0 / (w as f64).powi(dims).sqrt(),
    }
}

/// A shift as the query uses it: the fine-grid offset `r = q * 2^p + frac` to subtract from
/// window positions counted in fine steps.
#[derive(Clone, Copy)]
struct Offset {
    steps: i64,
    precision: u32,
}

impl Offset {
    /// Resolves `shift` (samples of the full-resolution signal) for a query of `n` samples at
    /// `resolution` (each query sample is `2^resolution` signal samples).
    fn new(shift: GridShift, n: usize, resolution: u32) -> Result<Self> {
        let shift = match resolution {
            0 => shift,
            t => shift.whole_multiple_of(t).ok_or_else(|| {
                Error::parameter(
                    "shift",
                    format!(
                        "{} is not a whole multiple of {} samples, the resolution of this query",
                        shift.amount(),
                        1u64 << t
                    ),
                )
            })?,
        };
        let (q, frac) = shift.split(n)?;
        let precision = shift.precision();
        Ok(Offset {
            steps: ((q as i64) << precision) + frac as i64,
            precision,
        })
    }

    /// Fine-grid position of sample boundary `a` of the output, in the input.
    fn position(self, a: usize) -> i64 {
        ((a as i64) << self.precision) - self.steps
    }

    /// Whole part (floor) and interpolation weight of a fine-grid position.
    fn split(self, u: i64) -> (i64, f64) {
        let frac = u & ((1 << self.precision) - 1);
        (
            u >> self.precision,
            // A multiplication by the exact power of two, not a division: this is the hot path.
            frac as f64 * f64::powi(0.5, self.precision as i32),
        )
    }
}

/// Checks that `t` coarse levels can be dropped from a `levels`-level transform.
fn check_resolution(levels: usize, resolution: u32) -> Result<usize> {
    levels.checked_sub(resolution as usize).ok_or_else(|| {
        Error::parameter(
            "resolution",
            format!("{resolution} exceeds the {levels} levels of the transform"),
        )
    })
}

/// Random access to the coefficients of a shifted 1D signal (layout of [`haar1d`]).
///
/// Built once from the coefficients in O(n) (an inverse transform and a prefix sum, in f64);
/// then [`coefficient`](Self::coefficient) answers any shift, integer or fractional, in O(1).
///
/// ```
/// use haarshift::shift::{GridShift, ShiftQuery1d, oracle};
/// use haarshift::transform::{Band1d, Normalization, haar1d};
/// use ndarray::array;
/// let norm = Normalization::Average;
/// let c = haar1d::forward(array![3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0].view(), 3, norm).unwrap();
/// let query = ShiftQuery1d::new(c.view(), 3, norm).unwrap();
/// let s = GridShift::whole(-3);
/// let want = oracle::shift_signal(c.view(), 3, norm, s).unwrap();
/// // Detail level 1 (length-4 supports), index 1 lives at position 3 of the array.
/// let got = query.coefficient(s, Band1d::Detail(1), 1).unwrap();
/// assert!((got - want[3]).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct ShiftQuery1d {
    /// `prefix[i]` = sum of `x[m] - mean` for `m < i`; length `n + 1`.
    prefix: Vec<f64>,
    mean: f64,
    levels: usize,
    norm: Normalization,
    resolution: u32,
}

impl ShiftQuery1d {
    /// Prepares the query from a `levels`-level transform.
    pub fn new<T: Sample>(
        coeffs: ArrayView1<'_, T>,
        levels: usize,
        norm: Normalization,
    ) -> Result<Self> {
        Self::with_resolution(coeffs, levels, norm, 0)
    }

    /// Prepares a query that only answers shifts by whole multiples of `2^resolution` samples,
    /// and only the coefficients of the `levels - resolution` coarsest levels, from the first
    /// `n >> resolution` coefficients alone: O(n / 2^resolution) preparation and memory.
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery1d};
    /// use haarshift::transform::{Band1d, Normalization, haar1d};
    /// use ndarray::Array1;
    /// let norm = Normalization::Orthonormal;
    /// let x = Array1::from_shape_fn(1024, |i| ((i * 37) % 101) as f64);
    /// let c = haar1d::forward(x.view(), 10, norm).unwrap();
    /// let coarse = ShiftQuery1d::with_resolution(c.view(), 10, norm, 6).unwrap();
    /// let full = ShiftQuery1d::new(c.view(), 10, norm).unwrap();
    /// let s = GridShift::whole(-192); // 3 * 64
    /// let (a, b) = (coarse.coefficient(s, Band1d::Detail(2), 1), full.coefficient(s, Band1d::Detail(2), 1));
    /// assert!((a.unwrap() - b.unwrap()).abs() < 1e-9);
    /// let off_grid = coarse.coefficient(GridShift::whole(1), Band1d::Detail(2), 1); // not a multiple of 64
    /// assert!(matches!(off_grid, Err(haarshift::Error::InvalidParameter { name: "shift", .. })));
    /// ```
    pub fn with_resolution<T: Sample>(
        coeffs: ArrayView1<'_, T>,
        levels: usize,
        norm: Normalization,
        resolution: u32,
    ) -> Result<Self> {
        haar1d::check_length(coeffs.len(), levels)?;
        let coarse_levels = check_resolution(levels, resolution)?;
        let coarse = coeffs
            .slice(s![..coeffs.len() >> resolution])
            .mapv(|v| v.as_f64());
        let x = haar1d::inverse(coarse.view(), coarse_levels, norm)?;
        let mean = x.sum() / x.len() as f64;
        let mut prefix = Vec::with_capacity(x.len() + 1);
        prefix.push(0.0);
        let mut acc = 0.0;
        for &v in &x {
            acc += v - mean;
            prefix.push(acc);
        }
        Ok(ShiftQuery1d {
            prefix,
            mean,
            levels: coarse_levels,
            norm,
            resolution,
        })
    }

    /// Length of the signal the query works on (`n >> resolution`).
    pub fn len(&self) -> usize {
        self.prefix.len() - 1
    }

    /// Always false: a query holds at least one sample.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The prefix sum at any integer position, continued periodically.
    fn extended(&self, k: i64) -> f64 {
        // The length is a power of two: floor division and remainder are a shift and a mask.
        let n = self.len();
        let (wraps, m) = (k >> n.trailing_zeros(), (k & (n as i64 - 1)) as usize);
        self.prefix[m] + wraps as f64 * self.prefix[self.len()]
    }

    /// The integral of `D` up to a fine-grid position: the prefix sum, linearly interpolated.
    fn integral(&self, offset: Offset, a: usize) -> f64 {
        let (k, beta) = offset.split(offset.position(a));
        let base = self.extended(k);
        if beta == 0.0 {
            return base;
        }
        base + beta * (self.extended(k + 1) - base)
    }

    /// Coefficient `i` of `band` of the transform of the signal shifted by `shift`
    /// (`out[n] = in[n - shift]`, periodic; fractional shifts as in the
    /// [module docs](super)). O(1).
    pub fn coefficient(&self, shift: GridShift, band: Band1d, i: usize) -> Result<f64> {
        let offset = Offset::new(shift, self.len(), self.resolution)?;
        self.at(offset, band, i)
    }

    fn at(&self, offset: Offset, band: Band1d, i: usize) -> Result<f64> {
        let n0 = self.len() >> self.levels;
        let (w, count) = match band {
            Band1d::Scaling => (1 << self.levels, n0),
            Band1d::Detail(l) if l < self.levels => (1 << (self.levels - l), n0 << l),
            Band1d::Detail(l) => {
                return Err(Error::parameter(
                    "level",
                    format!("detail level {l} does not exist in {} levels", self.levels),
                ));
            }
        };
        if i >= count {
            return Err(Error::parameter(
                "index",
                format!("{i} is out of range for a band of {count}"),
            ));
        }
        let f = box_weight(self.norm, w, 1);
        let start = i * w;
        let value = match band {
            Band1d::Scaling => {
                self.mean * w as f64 + self.integral(offset, start + w)
                    - self.integral(offset, start)
            }
            Band1d::Detail(_) => {
                2.0 * self.integral(offset, start + w / 2)
                    - self.integral(offset, start)
                    - self.integral(offset, start + w)
            }
        };
        Ok(f * value)
    }

    /// Several coefficients of the same shifted signal (the sparse use: a few coefficients,
    /// or the largest ones of a compressed signal).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery1d};
    /// use haarshift::transform::{Band1d, Normalization};
    /// use ndarray::array;
    /// let q = ShiftQuery1d::new(array![2.0, 1.0, 0.0, 0.0].view(), 2, Normalization::Average).unwrap();
    /// let v = q.coefficients(GridShift::whole(2), &[(Band1d::Scaling, 0), (Band1d::Detail(0), 0)]).unwrap();
    /// assert_eq!(v, [2.0, -1.0]); // the signal 3 3 1 1 becomes 1 1 3 3
    /// ```
    pub fn coefficients(&self, shift: GridShift, which: &[(Band1d, usize)]) -> Result<Vec<f64>> {
        let offset = Offset::new(shift, self.len(), self.resolution)?;
        which
            .iter()
            .map(|&(band, i)| self.at(offset, band, i))
            .collect()
    }

    /// The first `n0 << detail_levels` coefficients of the shifted transform: the scaling
    /// coefficients and the `detail_levels` coarsest detail levels, in O(their number).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery1d};
    /// use haarshift::transform::Normalization;
    /// use ndarray::array;
    /// let q = ShiftQuery1d::new(array![2.0, 1.0, 0.0, 0.0].view(), 2, Normalization::Average).unwrap();
    /// assert_eq!(q.coarse(GridShift::whole(2), 1).unwrap(), array![2.0, -1.0]);
    /// ```
    pub fn coarse(&self, shift: GridShift, detail_levels: usize) -> Result<Array1<f64>> {
        if detail_levels > self.levels {
            return Err(Error::parameter(
                "levels",
                format!("{detail_levels} detail levels requested of {}", self.levels),
            ));
        }
        let offset = Offset::new(shift, self.len(), self.resolution)?;
        let n0 = self.len() >> self.levels;
        let mut out = Array1::zeros(n0 << detail_levels);
        for (k, v) in out.iter_mut().enumerate() {
            let (band, i) = match k {
                k if k < n0 => (Band1d::Scaling, k),
                k => {
                    let l = (k / n0).ilog2() as usize;
                    (Band1d::Detail(l), k - (n0 << l))
                }
            };
            *v = self.at(offset, band, i)?;
        }
        Ok(out)
    }
}

/// Random access to the coefficients of a shifted 2D image in the pyramid layout.
///
/// Built once in O(n) (an inverse transform and a summed-area table of `x - mean`, in f64);
/// then any coefficient `(band, level, i, j)` for any shift `(dx, dy)`, integer or fractional,
/// costs O(1): nine interpolated table reads at most.
///
/// ```
/// use haarshift::shift::{GridShift, ShiftQuery2d, oracle};
/// use haarshift::transform::{Band, Normalization, pyramid};
/// use ndarray::Array2;
/// let norm = Normalization::Average;
/// let x = Array2::from_shape_fn((8, 16), |(i, j)| ((i * 13 + j * 7) % 11) as f64);
/// let c = pyramid::forward(x.view(), 3, norm).unwrap();
/// let query = ShiftQuery2d::new(c.view(), 3, norm).unwrap();
/// let (dx, dy) = (GridShift::whole(5), GridShift::whole(-3));
/// let want = oracle::shift_pyramid(c.view(), 3, norm, dx, dy).unwrap();
/// // Level 1 (4x4 supports) has bands of 2x4; `c` (diagonal) starts at row 2, column 4.
/// let got = query.coefficient(dx, dy, Band::Diagonal, 1, 1, 3).unwrap();
/// assert!((got - want[[2 + 1, 4 + 3]]).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct ShiftQuery2d {
    /// Inclusive summed-area table of `x - mean`: entry `(i, j)` sums rows `..=i`, columns
    /// `..=j`.
    table: Array2<f64>,
    mean: f64,
    levels: usize,
    norm: Normalization,
    resolution: u32,
}

/// One coefficient of a pyramid: band, detail level (0 coarsest; 0 for scaling), row, column.
pub type PyramidIndex = (Band, usize, usize, usize);

impl ShiftQuery2d {
    /// Prepares the query from a `levels`-level pyramid transform.
    pub fn new<T: Sample>(
        coeffs: ArrayView2<'_, T>,
        levels: usize,
        norm: Normalization,
    ) -> Result<Self> {
        Self::with_resolution(coeffs, levels, norm, 0)
    }

    /// Prepares the query from [`Coefficients`] in the pyramid layout (their padded size is
    /// the period of the shift).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery2d};
    /// use haarshift::transform::{Band, TransformSpec};
    /// use ndarray::array;
    /// let c = TransformSpec::default().forward(array![[1.0, 2.0], [3.0, 4.0]].view()).unwrap();
    /// let q = ShiftQuery2d::from_coefficients(&c).unwrap();
    /// let s = GridShift::whole(1);
    /// // Moving the columns swaps left and right: `a` changes sign.
    /// assert_eq!(q.coefficient(s, GridShift::whole(0), Band::Horizontal, 0, 0, 0).unwrap(), 0.5);
    /// ```
    pub fn from_coefficients<T: Sample>(coeffs: &Coefficients<T>) -> Result<Self> {
        let info = coeffs.info();
        if info.layout != Layout::Pyramid {
            return Err(Error::parameter(
                "layout",
                "random access is implemented for the pyramid layout",
            ));
        }
        Self::new(coeffs.as_array(), info.levels[0], info.normalization)
    }

    /// Prepares a query that only answers shifts by whole multiples of `2^resolution` pixels
    /// along both axes, and only the coefficients of the `levels - resolution` coarsest
    /// levels, from the top-left `(rows >> resolution) x (cols >> resolution)` block alone:
    /// preparation and memory shrink by `4^resolution` (the "coarse levels only" use).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery2d};
    /// use haarshift::transform::{Band, Normalization, pyramid};
    /// use ndarray::Array2;
    /// let norm = Normalization::Average;
    /// let x = Array2::from_shape_fn((64, 64), |(i, j)| ((i * 31 + j * 17) % 29) as f64);
    /// let c = pyramid::forward(x.view(), 6, norm).unwrap();
    /// let coarse = ShiftQuery2d::with_resolution(c.view(), 6, norm, 3).unwrap();
    /// let full = ShiftQuery2d::new(c.view(), 6, norm).unwrap();
    /// let (dx, dy) = (GridShift::whole(24), GridShift::whole(-8));
    /// let a = coarse.coefficient(dx, dy, Band::Vertical, 1, 1, 0).unwrap();
    /// let b = full.coefficient(dx, dy, Band::Vertical, 1, 1, 0).unwrap();
    /// assert!((a - b).abs() < 1e-9);
    /// ```
    pub fn with_resolution<T: Sample>(
        coeffs: ArrayView2<'_, T>,
        levels: usize,
        norm: Normalization,
        resolution: u32,
    ) -> Result<Self> {
        let (rows, cols) = coeffs.dim();
        pyramid::check((rows, cols), levels)?;
        let coarse_levels = check_resolution(levels, resolution)?;
        let block = coeffs
            .slice(s![..rows >> resolution, ..cols >> resolution])
            .mapv(|v| v.as_f64());
        let mut table = pyramid::inverse(block.view(), coarse_levels, norm)?;
        drop(block);
        let (h, w) = table.dim();
        let mean = table.sum() / (h * w) as f64;
        // The inclusive summed-area table of `x - mean`, in place: prefix sums along each row
        // (rows in parallel), then each row accumulates the one above.
        let data = table.as_slice_mut().expect("owned arrays are contiguous");
        data.par_chunks_mut(w).for_each(|row| {
            let mut acc = 0.0;
            for v in row {
                acc += *v - mean;
                *v = acc;
            }
        });
        for i in 1..h {
            let (above, below) = data[(i - 1) * w..(i + 1) * w].split_at_mut(w);
            below.iter_mut().zip(&*above).for_each(|(v, &up)| *v += up);
        }
        Ok(ShiftQuery2d {
            table,
            mean,
            levels: coarse_levels,
            norm,
            resolution,
        })
    }

    /// Rows and columns of the image the query works on (`>> resolution`).
    pub fn dim(&self) -> (usize, usize) {
        self.table.dim()
    }

    /// The summed-area table at any integer corner, continued periodically.
    fn extended(&self, k: i64, l: i64) -> f64 {
        // Sides are powers of two: floor division and remainder are a shift and a mask.
        let (h, w) = self.dim();
        let (bh, bw) = (h.trailing_zeros(), w.trailing_zeros());
        let (wk, mk) = (k >> bh, (k & (h as i64 - 1)) as usize);
        let (wl, ml) = (l >> bw, (l & (w as i64 - 1)) as usize);
        // Exclusive prefix at (k, l) < (h, w) is inclusive entry (k - 1, l - 1); row or column
        // 0 sums nothing.
        let p = |k: usize, l: usize| match (k, l) {
            (0, _) | (_, 0) => 0.0,
            _ => self.table[[k - 1, l - 1]],
        };
        p(mk, ml) + wk as f64 * p(h, ml) + wl as f64 * p(mk, w) + (wk * wl) as f64 * p(h, w)
    }

    /// The integral of `D` over `[0, row) x [0, col)` at fine-grid corner positions: the
    /// summed-area table, bilinearly interpolated.
    fn integral(&self, (oy, ox): (Offset, Offset), row: usize, col: usize) -> f64 {
        let (k, a) = oy.split(oy.position(row));
        let (l, b) = ox.split(ox.position(col));
        let along_cols = |k| {
            let p = self.extended(k, l);
            if b == 0.0 {
                return p;
            }
            p + b * (self.extended(k, l + 1) - p)
        };
        let top = along_cols(k);
        if a == 0.0 {
            return top;
        }
        top + a * (along_cols(k + 1) - top)
    }

    /// Coefficient `(i, j)` of `band` at detail `level` (0 coarsest; scaling coefficients are
    /// at level 0) of the image shifted by `dx` columns and `dy` rows (`out[r][c] =
    /// in[r - dy][c - dx]`, periodic). O(1).
    pub fn coefficient(
        &self,
        dx: GridShift,
        dy: GridShift,
        band: Band,
        level: usize,
        i: usize,
        j: usize,
    ) -> Result<f64> {
        let offsets = self.offsets(dx, dy)?;
        self.at(offsets, (band, level, i, j))
    }

    fn offsets(&self, dx: GridShift, dy: GridShift) -> Result<(Offset, Offset)> {
        let (h, w) = self.dim();
        Ok((
            Offset::new(dy, h, self.resolution)?,
            Offset::new(dx, w, self.resolution)?,
        ))
    }

    fn at(&self, offsets: (Offset, Offset), (band, level, i, j): PyramidIndex) -> Result<f64> {
        let (h, w) = self.dim();
        let (h0, w0) = (h >> self.levels, w >> self.levels);
        let (side, bh, bw) = match band {
            Band::Scaling if level == 0 => (1 << self.levels, h0, w0),
            Band::Scaling => {
                return Err(Error::parameter(
                    "level",
                    "scaling coefficients are stored at level 0 only",
                ));
            }
            _ if level < self.levels => (1 << (self.levels - level), h0 << level, w0 << level),
            _ => {
                return Err(Error::parameter(
                    "level",
                    format!(
                        "detail level {level} does not exist in {} levels",
                        self.levels
                    ),
                ));
            }
        };
        if i >= bh || j >= bw {
            return Err(Error::parameter(
                "index",
                format!("({i}, {j}) is out of range for a {bh}x{bw} band"),
            ));
        }
        let f = box_weight(self.norm, side, 2);
        let (r0, c0) = (i * side, j * side);
        let g = |dr: usize, dc: usize| self.integral(offsets, r0 + dr, c0 + dc);
        if band == Band::Scaling {
            let area = (side * side) as f64;
            let sum = g(side, side) - g(0, side) - g(side, 0) + g(0, 0);
            return Ok(f * (self.mean * area + sum));
        }
        let half = side / 2;
        let corners = [0, half, side].map(|dr| [0, half, side].map(|dc| g(dr, dc)));
        let quadrant = |qr: usize, qc: usize| {
            corners[qr + 1][qc + 1] - corners[qr][qc + 1] - corners[qr + 1][qc] + corners[qr][qc]
        };
        let (tl, tr, bl, br) = (
            quadrant(0, 0),
            quadrant(0, 1),
            quadrant(1, 0),
            quadrant(1, 1),
        );
        Ok(f * match band {
            Band::Horizontal => tl - tr + bl - br,
            Band::Vertical => tl + tr - bl - br,
            Band::Diagonal | Band::Scaling => tl - tr - bl + br,
        })
    }

    /// Several coefficients of the same shifted image (the sparse use).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery2d};
    /// use haarshift::transform::{Band, Normalization};
    /// use ndarray::array;
    /// let c = array![[2.5, -0.5], [-1.0, 0.0]]; // the image [[1, 2], [3, 4]], average
    /// let q = ShiftQuery2d::new(c.view(), 1, Normalization::Average).unwrap();
    /// let (dx, dy) = (GridShift::whole(0), GridShift::whole(1));
    /// let v = q.coefficients(dx, dy, &[(Band::Scaling, 0, 0, 0), (Band::Vertical, 0, 0, 0)]).unwrap();
    /// assert_eq!(v, [2.5, 1.0]); // rows swapped: top minus bottom changes sign
    /// ```
    pub fn coefficients(
        &self,
        dx: GridShift,
        dy: GridShift,
        which: &[PyramidIndex],
    ) -> Result<Vec<f64>> {
        let offsets = self.offsets(dx, dy)?;
        which.iter().map(|&idx| self.at(offsets, idx)).collect()
    }

    /// The top-left `(h0 << detail_levels) x (w0 << detail_levels)` block of the shifted
    /// transform (scaling coefficients and the `detail_levels` coarsest levels), in
    /// O(its size).
    ///
    /// ```
    /// use haarshift::shift::{GridShift, ShiftQuery2d};
    /// use haarshift::transform::Normalization;
    /// use ndarray::array;
    /// let c = array![[2.5, -0.5], [-1.0, 0.0]];
    /// let q = ShiftQuery2d::new(c.view(), 1, Normalization::Average).unwrap();
    /// let block = q.coarse(GridShift::whole(1), GridShift::whole(0), 1).unwrap();
    /// assert_eq!(block, array![[2.5, 0.5], [-1.0, 0.0]]);
    /// ```
    pub fn coarse(
        &self,
        dx: GridShift,
        dy: GridShift,
        detail_levels: usize,
    ) -> Result<Array2<f64>> {
        if detail_levels > self.levels {
            return Err(Error::parameter(
                "levels",
                format!("{detail_levels} detail levels requested of {}", self.levels),
            ));
        }
        let offsets = self.offsets(dx, dy)?;
        let (h, w) = self.dim();
        let (h0, w0) = (h >> self.levels, w >> self.levels);
        let mut out = Array2::zeros((h0 << detail_levels, w0 << detail_levels));
        for ((r, c), v) in out.indexed_iter_mut() {
            *v = self.at(offsets, pyramid_index(h0, w0, r, c))?;
        }
        Ok(out)
    }
}

/// The band, level and position of array entry `(r, c)` of a pyramid with an `h0 x w0`
/// scaling block.
pub(crate) fn pyramid_index(h0: usize, w0: usize, r: usize, c: usize) -> PyramidIndex {
    // The level is set by the larger of the two band ratios.
    let lr = if r < h0 { None } else { Some((r / h0).ilog2()) };
    let lc = if c < w0 { None } else { Some((c / w0).ilog2()) };
    match (lr, lc) {
        (None, None) => (Band::Scaling, 0, r, c),
        _ => {
            let l = lr.max(lc).unwrap_or(0) as usize;
            let (bh, bw) = (h0 << l, w0 << l);
            match (r >= bh, c >= bw) {
                (false, _) => (Band::Horizontal, l, r, c - bw),
                (true, false) => (Band::Vertical, l, r - bh, c),
                (true, true) => (Band::Diagonal, l, r - bh, c - bw),
            }
        }
    }
}
