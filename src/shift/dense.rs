//! Dense shifting: every coefficient of the shifted transform in O(n).
//!
//! A shift touches every coefficient, so the dense path is about memory traffic. The naive
//! round trip (inverse, pixel shift, forward) streams the image through memory about seven
//! times (each transform reads and writes it once plus its pyramid of intermediates, and the
//! shift reads and writes it once). Here the work is split at a level `T` chosen so that a
//! strip of `2^T` image rows fits in the L2 cache:
//!
//! 1. the `(H >> T) x (W >> T)` top-left block of the coefficients (the transform of the
//!    level-`T` approximation) is inverted: `1 / 4^T` of the data;
//! 2. the image is rebuilt strip by strip (`2^T` rows) from that approximation and the `T`
//!    finest detail levels, the shifted strip is gathered from (at most) two rebuilt source
//!    strips (a periodic roll, or a bilinear blend for a fractional shift), and transformed
//!    forward `T` levels while still in cache, writing its detail coefficients straight to
//!    their bands and its approximation row aside. Runs of strips go to rayon tasks; each
//!    task keeps its two most recent source strips, so a source strip is rebuilt about once;
//! 3. the approximation of the shifted image is transformed forward the remaining levels.
//!
//! The image never exists in main memory: coefficients are read once and written once.
//!
//! A whole shift first moves, without arithmetic, the bands of every fine level whose blocks
//! divide it (see the [exactness rules](super#exactness)); only the remaining coarse block
//! goes through the steps above.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2, ArrayViewMut1, ArrayViewMut2, Axis, s};
use rayon::prelude::*;

use super::GridShift;
use crate::transform::pyramid::{analyse_rows, synthesise_rows};
use crate::transform::{Normalization, haar1d, pyramid};
use crate::{Error, Result, Sample};

/// A strip buffer (`2^T` rows) should stay below this size to live in L2 with its companions.
const STRIP_BYTES: usize = 64 << 10;

/// Reusable buffers for the dense shifts, so that repeated calls allocate nothing.
///
/// ```
/// use haarshift::shift::{GridShift, ShiftWorkspace, dense};
/// use haarshift::transform::Normalization;
/// use ndarray::Array2;
/// let c = Array2::<f32>::ones((64, 64));
/// let mut out = Array2::zeros((64, 64));
/// let mut work = ShiftWorkspace::default();
/// for dx in 0..3 {
///     let (dx, dy) = (GridShift::whole(dx), GridShift::whole(1));
///     dense::shift_pyramid_into(c.view(), 6, Normalization::Average, dx, dy, out.view_mut(), &mut work).unwrap();
/// }
/// ```
#[derive(Debug)]
pub struct ShiftWorkspace<T> {
    /// 1D: the rebuilt signal; 2D: a contiguous copy of a coarse block.
    signal: Vec<T>,
    /// Scratch for the transforms.
    scratch: Vec<T>,
    /// 2D: approximation at the strip level of the input.
    coarse_in: Vec<T>,
    /// 2D: approximation at the strip level of the shifted image.
    coarse_out: Vec<T>,
    /// 2D: per-task strip buffers.
    strips: Vec<StripBuffers<T>>,
    /// 2D whole shifts: contiguous copies of the coarse block that is recomputed.
    block_in: Vec<T>,
    block_out: Vec<T>,
}

impl<T> Default for ShiftWorkspace<T> {
    fn default() -> Self {
        ShiftWorkspace {
            signal: Vec::new(),
            scratch: Vec::new(),
            coarse_in: Vec::new(),
            coarse_out: Vec::new(),
            strips: Vec::new(),
            block_in: Vec::new(),
            block_out: Vec::new(),
        }
    }
}

/// One task's cache-resident buffers.
#[derive(Debug)]
struct StripBuffers<T> {
    /// Two rebuilt source strips, slot `id & 1` for strip `id`.
    sources: [Vec<T>; 2],
    ids: [Option<usize>; 2],
    /// The shifted strip.
    gather: Vec<T>,
    /// One row of a vertical blend.
    line: Vec<T>,
    /// Ping-pong buffers for the intermediate levels inside a strip.
    ping: Vec<T>,
}

impl<T: Sample> StripBuffers<T> {
    fn new() -> Self {
        StripBuffers {
            sources: [Vec::new(), Vec::new()],
            ids: [None, None],
            gather: Vec::new(),
            line: Vec::new(),
            ping: Vec::new(),
        }
    }

    fn reserve(&mut self, strip_len: usize, w: usize) {
        for v in self
            .sources
            .iter_mut()
            .chain([&mut self.gather, &mut self.ping])
        {
            v.resize(strip_len, T::zero());
        }
        self.line.resize(w, T::zero());
        self.ids = [None, None];
    }
}

/// `dst[c] = (1 - b) src[(c - p) mod w] + b src[(c - p - 1) mod w]`: a periodic roll by `p`
/// and, for `b > 0`, a linear blend with the next sample back.
pub(crate) fn gather_row<T: Sample>(dst: &mut [T], src: &[T], p: usize, b: T) {
    let w = src.len();
    if b == T::zero() {
        let (head, tail) = src.split_at(w - p);
        dst[p..].copy_from_slice(head);
        dst[..p].copy_from_slice(tail);
        return;
    }
    let keep = T::one() - b;
    let mix = |d: &mut [T], cur: &[T], prev: &[T]| {
        for ((d, &x), &y) in d.iter_mut().zip(cur).zip(prev) {
            *d = keep * x + b * y;
        }
    };
    dst[p] = keep * src[0] + b * src[w - 1];
    mix(&mut dst[p + 1..], &src[1..w - p], &src[..w - p - 1]);
    mix(&mut dst[..p], &src[w - p..], &src[w - p - 1..w - 1]);
}

/// Shifts the transform in `data` (a `levels`-level [`haar1d`] transform) in place, using
/// `work` for the rebuilt signal.
pub(crate) fn shift_slice_in_place<T: Sample>(
    data: &mut [T],
    levels: usize,
    norm: Normalization,
    shift: GridShift,
    work: &mut ShiftWorkspace<T>,
) -> Result<()> {
    let n = data.len();
    haar1d::check_length(n, levels)?;
    let (q, frac) = shift.split(n)?;
    let (data, levels, q) = if frac == 0 {
        // Whole shift: the `t` finest levels (block sizes `2^s` dividing `q`) only move.
        let t = rolled_levels(q, levels);
        for s in 1..=t {
            let len = n >> s;
            data[len..2 * len].rotate_right(q >> s);
        }
        let coarse = n >> t;
        if t == levels {
            data[..coarse].rotate_right(q >> t);
            return Ok(());
        }
        // The rest is the transform of the level-`t` approximation, shifted by `q / 2^t`.
        (&mut data[..coarse], levels - t, q >> t)
    } else {
        (data, levels, q)
    };
    let b = T::from_f64(shift.weight(frac));
    work.signal.clear();
    work.signal.extend_from_slice(data);
    haar1d::inverse_in_place(&mut work.signal, levels, norm, &mut work.scratch)?;
    gather_row(data, &work.signal, q, b);
    haar1d::forward_in_place(data, levels, norm, &mut work.scratch)
}

/// How many of the finest of `levels` levels a whole shift by `q` samples only permutes: those
/// whose blocks (`2^s` samples at the `s`-th finest) divide `q`. There, the shifted
/// coefficient at block `i` is the old one at block `i - q / 2^s` (periodically), because the
/// shifted signal's block is exactly the old block moved: the module docs' exactness rule.
fn rolled_levels(q: usize, levels: usize) -> usize {
    (q.trailing_zeros() as usize).min(levels)
}

/// `dst[(r + dy) mod h][(c + dx) mod w] = src[r][c]`: a periodic 2D roll, copies only.
fn roll_into<T: Copy>(src: ArrayView2<'_, T>, mut dst: ArrayViewMut2<'_, T>, dy: usize, dx: usize) {
    let (h, w) = src.dim();
    let (ky, kx) = (h - dy, w - dx);
    dst.slice_mut(s![dy.., dx..])
        .assign(&src.slice(s![..ky, ..kx]));
    dst.slice_mut(s![dy.., ..dx])
        .assign(&src.slice(s![..ky, kx..]));
    dst.slice_mut(s![..dy, dx..])
        .assign(&src.slice(s![ky.., ..kx]));
    dst.slice_mut(s![..dy, ..dx])
        .assign(&src.slice(s![ky.., kx..]));
}

/// Writes the transform of the shifted 1D signal into `out`, allocating nothing once `work`
/// has grown to the size.
///
/// ```
/// use haarshift::shift::{GridShift, ShiftWorkspace, dense};
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::{Array1, array};
/// let norm = Normalization::Average;
/// let c = haar1d::forward(array![1.0, 2.0, 3.0, 4.0].view(), 2, norm).unwrap();
/// let mut out = Array1::zeros(4);
/// let half = GridShift::new(0.5, 1).unwrap();
/// dense::shift_signal_into(c.view(), 2, norm, half, out.view_mut(), &mut ShiftWorkspace::default()).unwrap();
/// // Linear interpolation half way back: 2.5 1.5 2.5 3.5
/// assert_eq!(haar1d::inverse(out.view(), 2, norm).unwrap(), array![2.5, 1.5, 2.5, 3.5]);
/// ```
pub fn shift_signal_into<T: Sample>(
    coeffs: ArrayView1<'_, T>,
    levels: usize,
    norm: Normalization,
    shift: GridShift,
    mut out: ArrayViewMut1<'_, T>,
    work: &mut ShiftWorkspace<T>,
) -> Result<()> {
    if out.len() != coeffs.len() {
        return Err(Error::shape(
            &[out.len()],
            format!("output must have {} values", coeffs.len()),
        ));
    }
    out.assign(&coeffs);
    let mut lane = Vec::new();
    haar1d::with_contiguous(out, &mut lane, |data| {
        shift_slice_in_place(data, levels, norm, shift, work)
    })
}

/// The transform of the 1D signal shifted by `shift` (`out[n] = in[n - shift]`, periodic).
///
/// ```
/// use haarshift::shift::{GridShift, dense};
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::array;
/// let norm = Normalization::Orthonormal;
/// let c = haar1d::forward(array![1.0f64, 2.0, 3.0, 4.0].view(), 1, norm).unwrap();
/// let shifted = dense::shift_signal(c.view(), 1, norm, GridShift::whole(-1)).unwrap();
/// let x = haar1d::inverse(shifted.view(), 1, norm).unwrap();
/// assert!(x.iter().zip([2.0, 3.0, 4.0, 1.0]).all(|(a, b)| (a - b).abs() < 1e-12));
/// ```
pub fn shift_signal<T: Sample>(
    coeffs: ArrayView1<'_, T>,
    levels: usize,
    norm: Normalization,
    shift: GridShift,
) -> Result<Array1<T>> {
    let mut out = coeffs.to_owned();
    let data = out.as_slice_mut().expect("owned arrays are contiguous");
    shift_slice_in_place(data, levels, norm, shift, &mut ShiftWorkspace::default())?;
    Ok(out)
}

/// How many levels a strip of an image `w` samples wide keeps in cache, at most `levels`.
fn strip_levels<T>(w: usize, levels: usize) -> usize {
    let row_bytes = w * std::mem::size_of::<T>();
    let mut t = 1;
    while t < 6 && (row_bytes << (t + 1)) <= STRIP_BYTES {
        t += 1;
    }
    t.min(levels)
}

/// The detail bands of one strip-level of the output, restricted to a run of strips.
struct LevelRows<'a, T> {
    /// Rows of band `a` (horizontal).
    a: ArrayViewMut2<'a, T>,
    /// Rows of bands `b` and `c` side by side.
    bc: ArrayViewMut2<'a, T>,
}

/// A run of strips for one task, with the parts of the output it alone writes.
struct Job<'a, T> {
    first: usize,
    count: usize,
    /// Index 0 is the finest level.
    levels: Vec<LevelRows<'a, T>>,
    /// Approximation rows (one per strip) of the shifted image.
    approx: ArrayViewMut2<'a, T>,
}

/// Splits `view` along rows into pieces of `rows` (the last may be shorter).
fn split_rows<T>(mut view: ArrayViewMut2<'_, T>, rows: usize) -> Vec<ArrayViewMut2<'_, T>> {
    let mut pieces = Vec::with_capacity(view.nrows().div_ceil(rows.max(1)));
    while view.nrows() > 0 {
        let take = rows.min(view.nrows());
        let (head, tail) = view.split_at(Axis(0), take);
        pieces.push(head);
        view = tail;
    }
    pieces
}

/// Everything the strip tasks share, read-only.
struct StripContext<'a, T> {
    coeffs: &'a [T],
    coarse_in: &'a [T],
    h: usize,
    w: usize,
    /// Levels done inside a strip (`T`); a strip has `2^fine` rows.
    fine: usize,
    /// Whole and fractional parts of the row and column shifts.
    qy: usize,
    ay: T,
    qx: usize,
    bx: T,
    f2: T,
    g2: T,
}

impl<T: Sample> StripContext<'_, T> {
    fn strips(&self) -> usize {
        self.h >> self.fine
    }

    /// Rebuilds image rows `[sigma 2^T, (sigma + 1) 2^T)` into `dst` from the level-`T`
    /// approximation and the `T` finest detail levels.
    fn synthesise(&self, sigma: usize, dst: &mut [T], ping: &mut [T]) {
        let (h, w, fine) = (self.h, self.w, self.fine);
        let cw = w >> fine;
        let approx_row = &self.coarse_in[sigma * cw..(sigma + 1) * cw];
        if fine == 0 {
            dst[..w].copy_from_slice(approx_row);
            return;
        }
        let half_len = ping.len() / 2;
        let (x, y) = ping.split_at_mut(half_len);
        for (k, t) in (1..=fine).rev().enumerate() {
            let (prev, next): (&[T], &mut [T]) = if k % 2 == 0 {
                (&*y, &mut *x)
            } else {
                (&*x, &mut *y)
            };
            let cur = if k == 0 { approx_row } else { prev };
            let target: &mut [T] = if t == 1 { &mut *dst } else { next };
            let (rows, bh, bw) = (1 << (fine - t), h >> t, w >> t);
            for rho in 0..rows {
                let br = sigma * rows + rho;
                let top = &self.coeffs[br * w..][..2 * bw];
                let (b, c) = self.coeffs[(bh + br) * w..][..2 * bw].split_at(bw);
                let (r0, r1) = target[2 * rho * 2 * bw..][..4 * bw].split_at_mut(2 * bw);
                synthesise_rows(&cur[rho * bw..][..bw], &top[bw..], b, c, r0, r1, self.g2);
            }
        }
    }

    /// Makes sure source strip `id` is in its slot.
    fn load(&self, bufs: &mut StripBuffers<T>, id: usize) {
        let slot = id & 1;
        if bufs.ids[slot] != Some(id) {
            self.synthesise(id, &mut bufs.sources[slot], &mut bufs.ping);
            bufs.ids[slot] = Some(id);
        }
    }

    /// Image row `y` from the loaded source strips.
    fn source_row<'b>(&self, sources: &'b [Vec<T>; 2], y: usize) -> &'b [T] {
        let id = y >> self.fine;
        let row = y & ((1 << self.fine) - 1);
        &sources[id & 1][row * self.w..][..self.w]
    }

    /// Fills the gather buffer with rows `[strip 2^T, (strip + 1) 2^T)` of the shifted image.
    fn gather(&self, bufs: &mut StripBuffers<T>, strip: usize) {
        let (h, w) = (self.h, self.w);
        let first = strip << self.fine;
        let blend = self.ay != T::zero();
        let lowest = (first + 2 * h - self.qy - usize::from(blend)) % h;
        let id = lowest >> self.fine;
        self.load(bufs, id);
        self.load(bufs, (id + 1) % self.strips());
        let StripBuffers {
            sources,
            gather,
            line,
            ..
        } = bufs;
        for (rho, dst) in gather.chunks_exact_mut(w).take(1 << self.fine).enumerate() {
            let y0 = (first + rho + h - self.qy) % h;
            let row0 = self.source_row(sources, y0);
            if !blend {
                gather_row(dst, row0, self.qx, self.bx);
                continue;
            }
            let row1 = self.source_row(sources, (y0 + h - 1) % h);
            let keep = T::one() - self.ay;
            for ((l, &u), &v) in line.iter_mut().zip(row0).zip(row1) {
                *l = keep * u + self.ay * v;
            }
            gather_row(dst, line, self.qx, self.bx);
        }
    }

    /// Transforms the gathered strip forward `T` levels: details into the job's band rows
    /// (strip `local` of the job), the approximation into `approx`.
    fn analyse(
        &self,
        bufs: &mut StripBuffers<T>,
        levels: &mut [LevelRows<'_, T>],
        local: usize,
        approx: &mut [T],
    ) {
        let (w, fine) = (self.w, self.fine);
        if fine == 0 {
            approx.copy_from_slice(&bufs.gather[..w]);
            return;
        }
        let gather = &bufs.gather;
        let half_len = bufs.ping.len() / 2;
        let (x, y) = bufs.ping.split_at_mut(half_len);
        for (t, level) in levels.iter_mut().enumerate() {
            let (prev, next): (&[T], &mut [T]) = if t % 2 == 0 {
                (&*y, &mut *x)
            } else {
                (&*x, &mut *y)
            };
            let cur = if t == 0 { &gather[..] } else { prev };
            let target: &mut [T] = if t + 1 == fine { &mut *approx } else { next };
            let (rows, width) = (1 << (fine - t - 1), w >> t);
            let half = width / 2;
            for rho in 0..rows {
                let (r0, r1) = cur[2 * rho * width..][..2 * width].split_at(width);
                let mut a_row = level.a.row_mut(local * rows + rho);
                let mut bc_row = level.bc.row_mut(local * rows + rho);
                let a = a_row.as_slice_mut().expect("output rows are contiguous");
                let bc = bc_row.as_slice_mut().expect("output rows are contiguous");
                let (b, c) = bc.split_at_mut(half);
                let approx_row = &mut target[rho * half..][..half];
                analyse_rows(r0, r1, approx_row, a, b, c, self.f2);
            }
        }
    }

    fn run(&self, job: &mut Job<'_, T>, bufs: &mut StripBuffers<T>) {
        for local in 0..job.count {
            self.gather(bufs, job.first + local);
            let mut approx_row = job.approx.row_mut(local);
            let approx = approx_row
                .as_slice_mut()
                .expect("workspace rows are contiguous");
            self.analyse(bufs, &mut job.levels, local, approx);
        }
    }
}

/// A contiguous `rows x cols` view of the front of a buffer sized for it.
fn view2<T>(buf: &[T], rows: usize, cols: usize) -> ArrayView2<'_, T> {
    ArrayView2::from_shape((rows, cols), &buf[..rows * cols]).expect("buffer sized for the view")
}

fn view2_mut<T>(buf: &mut [T], rows: usize, cols: usize) -> ArrayViewMut2<'_, T> {
    ArrayViewMut2::from_shape((rows, cols), &mut buf[..rows * cols])
        .expect("buffer sized for the view")
}

/// Writes the pyramid transform of the shifted image into `out` (same shape, standard
/// layout): `dx` columns (content moves right for `dx > 0`) and `dy` rows (down for
/// `dy > 0`), periodic, fractional parts as in the [module docs](super). Allocates nothing
/// once `work` has grown to the size, apart from a few view handles.
///
/// ```
/// use haarshift::shift::{GridShift, ShiftWorkspace, dense};
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::{Array2, array};
/// let norm = Normalization::Average;
/// let x = array![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]];
/// let c = pyramid::forward(x.view(), 1, norm).unwrap();
/// let mut out = Array2::zeros((2, 4));
/// let (dx, dy) = (GridShift::whole(1), GridShift::whole(1));
/// dense::shift_pyramid_into(c.view(), 1, norm, dx, dy, out.view_mut(), &mut ShiftWorkspace::default()).unwrap();
/// let y = pyramid::inverse(out.view(), 1, norm).unwrap();
/// assert_eq!(y, array![[8.0, 5.0, 6.0, 7.0], [4.0, 1.0, 2.0, 3.0]]);
/// ```
pub fn shift_pyramid_into<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    dx: GridShift,
    dy: GridShift,
    mut out: ArrayViewMut2<'_, T>,
    work: &mut ShiftWorkspace<T>,
) -> Result<()> {
    let (h, w) = coeffs.dim();
    pyramid::check((h, w), levels)?;
    check_output(out.dim(), out.is_standard_layout(), (h, w))?;
    let (qy, fy) = dy.split(h)?;
    let (qx, fx) = dx.split(w)?;
    let t = if fy == 0 && fx == 0 {
        rolled_levels(qy, levels).min(rolled_levels(qx, levels))
    } else {
        0
    };
    if t == 0 {
        let fine = strip_levels::<T>(w, levels);
        return shift_pyramid_in_strips(coeffs, levels, norm, (dx, dy), out, work, fine);
    }
    // Whole shift: the `t` finest levels' bands (blocks of `2^s x 2^s` dividing the shift)
    // only move; see `rolled_levels`.
    for s in 1..=t {
        let (bh, bw) = (h >> s, w >> s);
        let bands = [
            s![..bh, bw..2 * bw],
            s![bh..2 * bh, ..bw],
            s![bh..2 * bh, bw..2 * bw],
        ];
        for band in bands {
            roll_into(coeffs.slice(band), out.slice_mut(band), qy >> s, qx >> s);
        }
    }
    let (ch, cw) = (h >> t, w >> t);
    let (cy, cx) = (qy >> t, qx >> t);
    if t == levels {
        roll_into(
            coeffs.slice(s![..ch, ..cw]),
            out.slice_mut(s![..ch, ..cw]),
            cy,
            cx,
        );
        return Ok(());
    }
    // The top-left block is the transform of the level-`t` approximation, shifted by
    // `(cx, cy)`: through the strip path on contiguous copies.
    let mut block_in = std::mem::take(&mut work.block_in);
    let mut block_out = std::mem::take(&mut work.block_out);
    block_in.resize(ch * cw, T::zero());
    block_out.resize(ch * cw, T::zero());
    view2_mut(&mut block_in, ch, cw).assign(&coeffs.slice(s![..ch, ..cw]));
    let shifted = shift_pyramid_in_strips(
        view2(&block_in, ch, cw),
        levels - t,
        norm,
        (GridShift::whole(cx as i64), GridShift::whole(cy as i64)),
        view2_mut(&mut block_out, ch, cw),
        work,
        strip_levels::<T>(cw, levels - t),
    );
    out.slice_mut(s![..ch, ..cw])
        .assign(&view2(&block_out, ch, cw));
    (work.block_in, work.block_out) = (block_in, block_out);
    shifted
}

/// Refuses an output that is not an `h x w` standard-layout array.
fn check_output(dim: (usize, usize), standard: bool, (h, w): (usize, usize)) -> Result<()> {
    if dim != (h, w) || !standard {
        return Err(Error::shape(
            &[dim.0, dim.1],
            format!("output must be a {h}x{w} standard-layout array"),
        ));
    }
    Ok(())
}

/// [`shift_pyramid_into`] with `fine` levels done inside strips (`fine <= levels`); exposed to
/// the tests so that every split between strip and coarse levels is checked.
pub(crate) fn shift_pyramid_in_strips<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    (dx, dy): (GridShift, GridShift),
    mut out: ArrayViewMut2<'_, T>,
    work: &mut ShiftWorkspace<T>,
    fine: usize,
) -> Result<()> {
    let (h, w) = coeffs.dim();
    pyramid::check((h, w), levels)?;
    check_output(out.dim(), out.is_standard_layout(), (h, w))?;
    let (qy, fy) = dy.split(h)?;
    let (qx, fx) = dx.split(w)?;
    let coeffs = coeffs.as_standard_layout();
    let fine = fine.min(levels);
    let (ch, cw) = (h >> fine, w >> fine);

    // 1. The level-`fine` approximation of the input, from the coarse block.
    work.signal.resize(ch * cw, T::zero());
    work.coarse_in.resize(ch * cw, T::zero());
    work.coarse_out.resize(ch * cw, T::zero());
    view2_mut(&mut work.signal, ch, cw).assign(&coeffs.slice(s![..ch, ..cw]));
    pyramid::inverse_into(
        view2(&work.signal, ch, cw),
        levels - fine,
        norm,
        view2_mut(&mut work.coarse_in, ch, cw),
        &mut work.scratch,
    )?;

    // 2. Strips, in parallel runs.
    let context = StripContext {
        coeffs: coeffs.as_slice().expect("standard layout is contiguous"),
        coarse_in: &work.coarse_in,
        h,
        w,
        fine,
        qy,
        ay: T::from_f64(dy.weight(fy)),
        qx,
        bx: T::from_f64(dx.weight(fx)),
        f2: norm.forward_factor_2d(),
        g2: norm.inverse_factor_2d(),
    };
    let strips = ch;
    let per_task = strips.div_ceil(strips.min(4 * rayon::current_num_threads()).max(1));
    let tasks = strips.div_ceil(per_task);
    let mut jobs: Vec<Job<'_, T>> = split_rows(view2_mut(&mut work.coarse_out, ch, cw), per_task)
        .into_iter()
        .enumerate()
        .map(|(k, approx)| Job {
            first: k * per_task,
            count: approx.nrows(),
            levels: Vec::with_capacity(fine),
            approx,
        })
        .collect();
    let mut rest = out.view_mut();
    for t in 0..fine {
        let (rows, cols) = rest.dim();
        let (top, bottom) = rest.split_at(Axis(0), rows / 2);
        let (top_left, top_right) = top.split_at(Axis(1), cols / 2);
        let band_rows = per_task << (fine - t - 1);
        let pieces = split_rows(top_right, band_rows)
            .into_iter()
            .zip(split_rows(bottom, band_rows));
        for (job, (a, bc)) in jobs.iter_mut().zip(pieces) {
            job.levels.push(LevelRows { a, bc });
        }
        rest = top_left;
    }
    if work.strips.len() < tasks {
        work.strips.resize_with(tasks, StripBuffers::new);
    }
    let strip_len = w << fine;
    jobs.par_iter_mut()
        .zip(work.strips[..tasks].par_iter_mut())
        .for_each(|(job, bufs)| {
            bufs.reserve(strip_len, w);
            context.run(job, bufs);
        });
    drop(jobs);

    // 3. The coarse levels of the shifted image.
    pyramid::forward_into(
        view2(&work.coarse_out, ch, cw),
        levels - fine,
        norm,
        view2_mut(&mut work.signal, ch, cw),
        &mut work.scratch,
    )?;
    rest.assign(&view2(&work.signal, ch, cw));
    Ok(())
}

/// The pyramid transform of the image shifted by `dx` columns and `dy` rows.
///
/// ```
/// use haarshift::shift::{GridShift, dense};
/// use haarshift::transform::{Normalization, pyramid};
/// use ndarray::array;
/// let norm = Normalization::Average;
/// let c = pyramid::forward(array![[0.0, 4.0], [8.0, 12.0]].view(), 1, norm).unwrap();
/// let half = GridShift::new(0.5, 1).unwrap();
/// let s = dense::shift_pyramid(c.view(), 1, norm, half, GridShift::whole(0)).unwrap();
/// // Bilinear (here linear along rows) interpolation half a pixel back, periodic.
/// let y = pyramid::inverse(s.view(), 1, norm).unwrap();
/// assert_eq!(y, array![[2.0, 2.0], [10.0, 10.0]]);
/// ```
pub fn shift_pyramid<T: Sample>(
    coeffs: ArrayView2<'_, T>,
    levels: usize,
    norm: Normalization,
    dx: GridShift,
    dy: GridShift,
) -> Result<Array2<T>> {
    pyramid::check(coeffs.dim(), levels)?;
    let mut out = Array2::zeros(coeffs.dim());
    let mut work = ShiftWorkspace::default();
    shift_pyramid_into(coeffs, levels, norm, dx, dy, out.view_mut(), &mut work)?;
    Ok(out)
}
