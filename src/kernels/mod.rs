//! Rotation kernels: 1D fractional shifts of rows, the building block of three-shear rotation
//! (Alnasser 2008's equation 2.26) and of pixel-domain subpixel shifts.
//!
//! Every kernel implements [`ShearKernel`]; the drivers ([`shear_rows`], [`shift_plane`] and
//! the [`rotate`](crate::rotate) module) only talk to that trait, so a user can add a kernel by
//! implementing it. The design follows rustfft: a kernel is a small, immutable, shareable
//! object ([`ShearKernel`]) that hands out per-thread workers ([`RowShifter`]) which own their
//! scratch buffers, so shifting a row never allocates.
//!
//! # Convention
//!
//! A shift by `s` moves content towards higher indices: `out[n] = row(n - s)`, the sign of
//! `scipy.ndimage.shift`. `row(x)` is the kernel's continuous model of the row at a
//! non-integer position `x`, with samples outside `0..len` given by an [`Outside`] rule.
//! All kernels here interpolate (`row(i)` is sample `i` for integer `i`), so the drivers copy
//! rows whose shift is an integer exactly and bit for bit, without calling the kernel.
//!
//! | name | kernel | taps |
//! |---|---|---|
//! | `nearest` | [`Nearest`] | 1 |
//! | `linear` | [`Linear`] | 2 |
//! | `keys` | [`Keys`] cubic convolution, `a = -0.5` | 4 |
//! | `bspline3`, `bspline5` | [`BSpline`] with exact recursive prefilter | 4, 6 (+ IIR) |
//! | `lanczos3`, `lanczos4` | [`Lanczos`], weights normalised to sum 1 | 6, 8 |
//! | `fft` | [`FftShift`] band-limited phase shift | whole row |
//!
//! ```
//! use haarshift::kernels::{Outside, ShiftMethod, shear_rows};
//! use ndarray::array;
//! let kernel = ShiftMethod::Linear.kernel::<f64>();
//! let rows = array![[0.0, 1.0, 2.0, 3.0]];
//! let out = shear_rows(rows.view(), 4, &[0.5], kernel.as_ref(), Outside::Fill(0.0)).unwrap();
//! assert_eq!(out.row(0).to_vec(), vec![0.0, 0.5, 1.5, 2.5]);
//! ```

mod bspline;
mod fft;
pub(crate) mod grid;
mod haar;
mod keys;
mod lanczos;
mod linear;
mod nearest;
pub(crate) mod shear;
mod taps;

pub use bspline::{BSpline, bspline_value};
pub use fft::FftShift;
pub use haar::HaarShift;
pub use keys::{Keys, keys_value};
pub use lanczos::{Lanczos, lanczos_value};
pub use linear::Linear;
pub use nearest::Nearest;
pub use shear::{shear_rows, shift_plane, transpose};

use crate::named::named_enum;
use crate::{BoundaryMode, Error, Result, Sample};

/// Where the samples outside a row (or an image) come from.
///
/// ```
/// use haarshift::BoundaryMode;
/// use haarshift::kernels::Outside;
/// let row = [1.0, 2.0, 3.0];
/// assert_eq!(Outside::Fill(9.0).sample(&row, -1), 9.0);
/// assert_eq!(Outside::Boundary(BoundaryMode::Edge).sample(&row, 5), 3.0);
/// assert_eq!(Outside::default(), Outside::Fill(0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Outside {
    /// A constant value.
    Fill(f64),
    /// The row continued by a boundary mode (`Zero` is the same as `Fill(0.0)`).
    Boundary(BoundaryMode),
}

impl Default for Outside {
    fn default() -> Self {
        Outside::Fill(0.0)
    }
}

impl Outside {
    /// The value at integer position `i` of `row` continued by this rule.
    #[inline]
    pub fn sample<T: Sample>(self, row: &[T], i: isize) -> T {
        if i >= 0 && (i as usize) < row.len() {
            return row[i as usize];
        }
        match self {
            Outside::Fill(v) => T::from_f64(v),
            Outside::Boundary(mode) => mode
                .source_index(i, row.len())
                .map_or_else(T::zero, |j| row[j]),
        }
    }

    /// Rejects a non-finite fill value.
    ///
    /// ```
    /// use haarshift::kernels::Outside;
    /// let nan = Outside::Fill(f64::NAN).validate();
    /// assert!(matches!(nan, Err(haarshift::Error::InvalidParameter { name: "fill", .. })));
    /// assert!(Outside::Fill(1.0).validate().is_ok());
    /// ```
    pub fn validate(self) -> Result<Self> {
        match self {
            Outside::Fill(v) if !v.is_finite() => Err(Error::parameter(
                "fill",
                format!("{v} is not a finite number"),
            )),
            _ => Ok(self),
        }
    }

    /// Writes `buf[b] = row(lo + b)`, continued by this rule: one `memcpy` for the part inside.
    ///
    /// ```
    /// use haarshift::kernels::Outside;
    /// let mut buf = [0.0; 5];
    /// Outside::Fill(-1.0).extend_into(&[1.0, 2.0, 3.0], -1, &mut buf);
    /// assert_eq!(buf, [-1.0, 1.0, 2.0, 3.0, -1.0]);
    /// ```
    pub fn extend_into<T: Sample>(self, row: &[T], lo: isize, buf: &mut [T]) {
        let n = row.len() as isize;
        let len = buf.len() as isize;
        // Part of the buffer that lies inside the row: b in [b0, b1).
        let b0 = (-lo).clamp(0, len);
        let b1 = (n - lo).clamp(b0, len);
        for (b, v) in buf[..b0 as usize].iter_mut().enumerate() {
            *v = self.sample(row, lo + b as isize);
        }
        if b1 > b0 {
            let start = (lo + b0) as usize;
            buf[b0 as usize..b1 as usize].copy_from_slice(&row[start..start + (b1 - b0) as usize]);
        }
        for (b, v) in buf[b1 as usize..].iter_mut().enumerate() {
            *v = self.sample(row, lo + b1 + b as isize);
        }
    }
}

/// Sizes a [`RowShifter`] will see, so that it can size its buffers (and, for the FFT, pick one
/// transform length) once.
///
/// ```
/// use haarshift::kernels::RowGeometry;
/// let g = RowGeometry { len_in: 100, len_out: 120, min_shift: -3.0, max_shift: 7.5 };
/// assert_eq!(g.len_out, 120);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowGeometry {
    /// Length of the input rows.
    pub len_in: usize,
    /// Length of the output rows.
    pub len_out: usize,
    /// Smallest shift that will be asked for (outside the range still works, more slowly).
    pub min_shift: f64,
    /// Largest shift that will be asked for.
    pub max_shift: f64,
}

/// A 1D fractional-shift kernel: the trait every rotation/shift method implements.
///
/// Implementations are immutable and shared between threads; the per-thread work happens in
/// the [`RowShifter`] that [`row_shifter`](Self::row_shifter) returns, which owns its scratch
/// buffers (the drivers create one per worker thread and reuse it for many rows).
///
/// Contract: the kernel interpolates, i.e. a shift by an integer `k` gives `out[n] = row(n-k)`
/// exactly; the drivers rely on this and copy such rows without calling the kernel.
///
/// ```
/// use haarshift::kernels::{Outside, RowGeometry, RowShifter, ShearKernel, shear_rows};
/// use ndarray::array;
///
/// /// A user kernel: nearest neighbour that rounds half down.
/// struct RoundHalfDown;
/// struct Worker(Outside);
/// impl RowShifter<f64> for Worker {
///     fn shift_row(&mut self, row: &[f64], shift: f64, out: &mut [f64]) -> haarshift::Result<()> {
///         for (n, o) in out.iter_mut().enumerate() {
///             let x = n as f64 - shift;
///             *o = self.0.sample(row, (x - 0.5).ceil() as isize);
///         }
///         Ok(())
///     }
/// }
/// impl ShearKernel<f64> for RoundHalfDown {
///     fn name(&self) -> String { "round-half-down".into() }
///     fn support_radius(&self) -> usize { 1 }
///     fn row_shifter(&self, _: RowGeometry, outside: Outside) -> Box<dyn RowShifter<f64> + '_> {
///         Box::new(Worker(outside))
///     }
/// }
/// let out = shear_rows(array![[1.0, 2.0, 3.0]].view(), 3, &[0.5], &RoundHalfDown,
///                      Outside::Fill(0.0)).unwrap();
/// assert_eq!(out.row(0).to_vec(), vec![0.0, 1.0, 2.0]);
/// ```
pub trait ShearKernel<T: Sample>: Send + Sync {
    /// A short description with parameters, for reports (`keys(a=-0.5)`).
    fn name(&self) -> String;

    /// `h` when the kernel works on a grid `2^h` times finer than the pixels: the drivers then
    /// replicate each pixel `2^h` times per axis (nearest), shift on that grid (shifts scaled by
    /// `2^h`) and box-average back at the end. Zero (the default) for ordinary kernels.
    fn grid_exponent(&self) -> u32 {
        0
    }

    /// How many samples content spreads by in one shift (half the kernel's footprint); the
    /// rotation sizes its intermediate images by it.
    fn support_radius(&self) -> usize;

    /// A worker for rows of the given geometry, continuing rows by `outside`.
    fn row_shifter(&self, geometry: RowGeometry, outside: Outside) -> Box<dyn RowShifter<T> + '_>;
}

/// The per-thread worker of a [`ShearKernel`]: shifts one row at a time, reusing its buffers.
///
/// ```
/// use haarshift::kernels::{Outside, RowGeometry, ShearKernel, ShiftMethod};
/// let kernel = ShiftMethod::Keys.kernel::<f64>();
/// let geometry = RowGeometry { len_in: 4, len_out: 4, min_shift: 0.0, max_shift: 1.0 };
/// let mut worker = kernel.row_shifter(geometry, Outside::Fill(0.0));
/// let mut out = [0.0; 4];
/// worker.shift_row(&[1.0, 1.0, 1.0, 1.0], 0.25, &mut out).unwrap();
/// assert!((out[2] - 1.0).abs() < 1e-15);
/// ```
pub trait RowShifter<T: Sample>: Send {
    /// `out[n] = row(n - shift)` for `n` in `0..out.len()`; `row` and `out` may differ in
    /// length. The drivers pass finite shifts of at most `1e15`; a kernel that cannot make a
    /// shift (the Haar kernel given a non-finite one, say) returns the error rather than
    /// writing a wrong row, and the drivers pass it on.
    fn shift_row(&mut self, row: &[T], shift: f64, out: &mut [T]) -> Result<()>;

    /// Shifts several rows of equal length, `outs[i][n] = rows[i](n - shifts[i])`, all `outs`
    /// of equal length. The drivers hand out up to [`ROW_GROUP`] rows at a time; the default
    /// shifts them one by one. A kernel whose work per row is a serial recursion (the
    /// B-splines' prefilter) overrides it to run the rows side by side, one vector lane each.
    ///
    /// ```
    /// use haarshift::kernels::{Outside, RowGeometry, ShearKernel, ShiftMethod};
    /// let kernel = ShiftMethod::BSpline3.kernel::<f64>();
    /// let geometry = RowGeometry { len_in: 3, len_out: 3, min_shift: 0.0, max_shift: 1.0 };
    /// let mut worker = kernel.row_shifter(geometry, Outside::Fill(0.0));
    /// let (mut a, mut b) = ([0.0; 3], [0.0; 3]);
    /// worker.shift_rows(&[&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]], &[0.5, 0.25], &mut [&mut a, &mut b]).unwrap();
    /// let mut single = [0.0; 3];
    /// worker.shift_row(&[4.0, 5.0, 6.0], 0.25, &mut single).unwrap();
    /// assert_eq!(b, single);
    /// ```
    fn shift_rows(&mut self, rows: &[&[T]], shifts: &[f64], outs: &mut [&mut [T]]) -> Result<()> {
        for ((row, &shift), out) in rows.iter().zip(shifts).zip(outs.iter_mut()) {
            self.shift_row(row, shift, out)?;
        }
        Ok(())
    }
}

/// How many rows the drivers pass to [`RowShifter::shift_rows`] at once: eight lanes of f32
/// fill a 256-bit vector.
pub const ROW_GROUP: usize = 8;

named_enum! {
    /// The built-in kernels by their command-line names.
    ///
    /// ```
    /// use haarshift::kernels::ShiftMethod;
    /// let m: ShiftMethod = "bspline3".parse().unwrap();
    /// assert_eq!(m, ShiftMethod::BSpline3);
    /// assert_eq!(m.kernel::<f32>().name(), "bspline3");
    /// let err = "cubic".parse::<ShiftMethod>().unwrap_err();
    /// assert!(err.to_string().contains("unknown value \"cubic\" (expected one of: nearest,"));
    /// ```
    pub enum ShiftMethod ("shift method") {
        /// Nearest neighbour.
        Nearest = "nearest",
        /// Linear interpolation.
        Linear = "linear",
        /// Keys cubic convolution, `a = -0.5`.
        Keys = "keys",
        /// Interpolating cubic B-spline.
        BSpline3 = "bspline3",
        /// Interpolating quintic B-spline.
        BSpline5 = "bspline5",
        /// Lanczos windowed sinc, `a = 3`.
        Lanczos3 = "lanczos3",
        /// Lanczos windowed sinc, `a = 4`.
        Lanczos4 = "lanczos4",
        /// Band-limited FFT phase shift.
        Fft = "fft",
        /// Shift in the Haar domain with precision `1/2^h` ([`HaarShift`]).
        Haar = "haar",
    }
}

/// The parameters a [`ShiftMethod`] may take; each method reads the ones it has.
///
/// ```
/// use haarshift::kernels::{KernelOptions, ShiftMethod};
/// let opts = KernelOptions { precision: 4, retain: true, ..Default::default() };
/// let k = ShiftMethod::Haar.kernel_with::<f32>(&opts).unwrap();
/// assert_eq!(k.name(), "haar(h=4, retained)");
/// assert_eq!(k.grid_exponent(), 4);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KernelOptions {
    /// Haar precision `h`: shifts are rounded to `1/2^h` (default 3).
    pub precision: u32,
    /// Haar: keep the `N + h` levels across shears and rotations (default false: compact).
    pub retain: bool,
    /// Keys' parameter `a` (default -0.5).
    pub keys_a: f64,
}

impl Default for KernelOptions {
    fn default() -> Self {
        KernelOptions {
            precision: 3,
            retain: false,
            keys_a: -0.5,
        }
    }
}

impl KernelOptions {
    /// The options of `method` from optional parameters (`None`: the default), refusing a
    /// parameter that `method` does not take, so that none is silently ignored.
    ///
    /// ```
    /// use haarshift::kernels::{KernelOptions, ShiftMethod};
    /// let o = KernelOptions::for_method(ShiftMethod::Haar, Some(2), true, None).unwrap();
    /// assert_eq!((o.precision, o.retain, o.keys_a), (2, true, -0.5));
    /// let e = KernelOptions::for_method(ShiftMethod::Keys, Some(2), false, None).unwrap_err();
    /// assert_eq!(e.to_string(), "invalid precision: precision applies to method haar only, not keys");
    /// ```
    pub fn for_method(
        method: ShiftMethod,
        precision: Option<u32>,
        retain: bool,
        keys_a: Option<f64>,
    ) -> Result<KernelOptions> {
        let misplaced = |name: &'static str, owner: ShiftMethod| Error::InvalidParameter {
            name,
            reason: format!("{name} applies to method {owner} only, not {method}"),
        };
        if method != ShiftMethod::Haar {
            if precision.is_some() {
                return Err(misplaced("precision", ShiftMethod::Haar));
            }
            if retain {
                return Err(misplaced("retain", ShiftMethod::Haar));
            }
        }
        if method != ShiftMethod::Keys && keys_a.is_some() {
            return Err(misplaced("keys_a", ShiftMethod::Keys));
        }
        let defaults = KernelOptions::default();
        Ok(KernelOptions {
            precision: precision.unwrap_or(defaults.precision),
            retain,
            keys_a: keys_a.unwrap_or(defaults.keys_a),
        })
    }
}

impl ShiftMethod {
    /// The kernel with its default parameters.
    ///
    /// ```
    /// use haarshift::kernels::ShiftMethod;
    /// for m in ShiftMethod::ALL {
    ///     assert!(!m.kernel::<f64>().name().is_empty());
    /// }
    /// ```
    pub fn kernel<T: Sample>(self) -> Box<dyn ShearKernel<T>> {
        self.kernel_with(&KernelOptions::default())
            .expect("the default options are valid")
    }

    /// The kernel with the parameters of `options` that apply to it.
    pub fn kernel_with<T: Sample>(
        self,
        options: &KernelOptions,
    ) -> Result<Box<dyn ShearKernel<T>>> {
        Ok(match self {
            ShiftMethod::Nearest => Box::new(Nearest),
            ShiftMethod::Linear => Box::new(Linear),
            ShiftMethod::Keys => Box::new(Keys::new(options.keys_a)?),
            ShiftMethod::Haar => Box::new(HaarShift::new(options.precision, options.retain)?),
            ShiftMethod::BSpline3 => Box::new(BSpline::cubic()),
            ShiftMethod::BSpline5 => Box::new(BSpline::quintic()),
            ShiftMethod::Lanczos3 => Box::new(Lanczos::new(3)),
            ShiftMethod::Lanczos4 => Box::new(Lanczos::new(4)),
            ShiftMethod::Fft => fft::boxed(),
        })
    }
}

#[cfg(test)]
mod tests;
