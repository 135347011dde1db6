//! Retained precision: keep the `h` added levels across a chain of shifts.
//!
//! The compact shift ([`shift_image`](super::shift_image)) projects back to the original
//! levels after every shift, which box-averages (linearly interpolates) each time; a chain of
//! fractional shifts then blurs cumulatively. A retained signal keeps the upsampled transform
//! (`2^h` times longer per axis, zero details at the added levels initially), so every shift
//! on the `1 / 2^h` grid is an exact whole shift there, and a chain of them equals the single
//! shift by their sum. [`project`](RetainedImage::project) box-averages to the original size
//! only when asked: that is just the top-left block of the coefficient array.

use ndarray::{Array1, Array2, ArrayView1, ArrayView2, s};

use super::dense::{ShiftWorkspace, shift_pyramid_into, shift_slice_in_place};
use super::{GridShift, MAX_PRECISION};
use crate::transform::{Coefficients, Layout, Normalization, TransformInfo, haar1d};
use crate::{Error, Result, Sample};

/// The memory budget of a retained signal or image unless the caller gives one: 1 GiB.
///
/// ```
/// assert_eq!(haarshift::shift::DEFAULT_MEMORY_BUDGET, 1 << 30);
/// ```
pub const DEFAULT_MEMORY_BUDGET: u64 = 1 << 30;

/// Checks the precision and that two arrays of `elements` samples (the retained transform and
/// its double buffer) fit in `budget` bytes; returns the element count.
fn check_budget<T>(what: &str, elements: u128, precision: u32, budget: u64) -> Result<usize> {
    if precision > MAX_PRECISION {
        return Err(Error::parameter(
            "precision",
            format!("{precision} is above the maximum of {MAX_PRECISION}"),
        ));
    }
    let needed = 2 * elements * std::mem::size_of::<T>() as u128;
    if needed > budget as u128 || elements > usize::MAX as u128 {
        return Err(Error::MemoryBudget {
            what: format!("{what} retained at precision {precision}"),
            needed,
            budget: budget as u128,
        });
    }
    Ok(elements as usize)
}

/// A zero-filled buffer, or a budget error when the allocator refuses.
fn try_zeros<T: Sample>(len: usize) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| Error::MemoryBudget {
        what: "retained coefficients".into(),
        needed: (len * std::mem::size_of::<T>()) as u128,
        budget: 0,
    })?;
    v.resize(len, T::zero());
    Ok(v)
}

/// A 1D transform kept at `h` extra levels across shifts.
///
/// ```
/// use haarshift::shift::RetainedSignal;
/// use haarshift::transform::{Normalization, haar1d};
/// use ndarray::array;
/// let norm = Normalization::Average;
/// let c = haar1d::forward(array![0.0, 8.0, 0.0, 0.0].view(), 2, norm).unwrap();
/// let mut r = RetainedSignal::new(c.view(), 2, norm, 2).unwrap();
/// for _ in 0..4 {
///     r.shift(0.25).unwrap(); // four quarter steps: exactly one sample
/// }
/// let x = haar1d::inverse(r.project().view(), 2, norm).unwrap();
/// assert_eq!(x, array![0.0, 0.0, 8.0, 0.0]);
/// ```
#[derive(Debug)]
pub struct RetainedSignal<T> {
    fine: Vec<T>,
    len: usize,
    levels: usize,
    norm: Normalization,
    precision: u32,
    offset: GridShift,
    work: ShiftWorkspace<T>,
}

impl<T: Sample> RetainedSignal<T> {
    /// Retains a `levels`-level transform at `precision` extra levels, within
    /// [`DEFAULT_MEMORY_BUDGET`].
    pub fn new(
        coeffs: ArrayView1<'_, T>,
        levels: usize,
        norm: Normalization,
        precision: u32,
    ) -> Result<Self> {
        Self::with_budget(coeffs, levels, norm, precision, DEFAULT_MEMORY_BUDGET)
    }

    /// Retains with an explicit budget in bytes for the two fine arrays (the retained
    /// transform and its double buffer), refusing with [`Error::MemoryBudget`] beyond it.
    ///
    /// ```
    /// use haarshift::{Error, shift::RetainedSignal, transform::Normalization};
    /// let c = ndarray::Array1::<f64>::zeros(1024);
    /// let err = RetainedSignal::with_budget(c.view(), 10, Normalization::Average, 8, 1 << 20);
    /// assert!(matches!(err, Err(Error::MemoryBudget { .. })));
    /// ```
    pub fn with_budget(
        coeffs: ArrayView1<'_, T>,
        levels: usize,
        norm: Normalization,
        precision: u32,
        budget: u64,
    ) -> Result<Self> {
        let len = coeffs.len();
        haar1d::check_length(len, levels)?;
        let elements = (len as u128) << precision.min(MAX_PRECISION + 1);
        let n = check_budget::<T>("signal", elements, precision, budget)?;
        let mut fine = try_zeros(n)?;
        fine.iter_mut()
            .zip(coeffs.iter())
            .for_each(|(f, &c)| *f = c);
        Ok(RetainedSignal {
            fine,
            len,
            levels,
            norm,
            precision,
            offset: GridShift::whole(0),
            work: ShiftWorkspace::default(),
        })
    }

    /// Shifts by `amount` samples rounded to the `1 / 2^h` grid ([`GridShift`] rules):
    /// exact on the retained grid.
    pub fn shift(&mut self, amount: f64) -> Result<()> {
        let shift = GridShift::new(amount, self.precision)?;
        let levels = self.levels + self.precision as usize;
        shift_slice_in_place(
            &mut self.fine,
            levels,
            self.norm,
            shift.in_grid_units(),
            &mut self.work,
        )?;
        self.offset = self.offset + shift;
        Ok(())
    }

    /// The total shift applied so far, in samples.
    pub fn offset(&self) -> f64 {
        self.offset.amount()
    }

    /// The retained transform (`len << h` values, `levels + h` levels).
    pub fn fine(&self) -> ArrayView1<'_, T> {
        ArrayView1::from(&self.fine[..])
    }

    /// Box-averaged back to the original length and levels: the first `len` coefficients.
    pub fn project(&self) -> Array1<T> {
        Array1::from(self.fine[..self.len].to_vec())
    }
}

/// A 2D pyramid transform kept at `h` extra levels across shifts: the mode for chains of
/// fractional shifts such as three-shear rotations. Memory grows by `4^h`.
///
/// ```
/// use haarshift::shift::RetainedImage;
/// use haarshift::transform::TransformSpec;
/// use ndarray::Array2;
/// let x = Array2::from_shape_fn((8, 8), |(i, j)| (i * 8 + j) as f64);
/// let c = TransformSpec::default().forward(x.view()).unwrap();
/// let mut r = RetainedImage::new(&c, 3).unwrap();
/// r.shift(0.375, -0.125).unwrap();
/// r.shift(0.625, 1.125).unwrap();
/// let y = r.project().inverse().unwrap(); // exactly a shift by (1, 1)
/// assert!((y[[3, 4]] - x[[2, 3]]).abs() < 1e-9);
/// ```
#[derive(Debug)]
pub struct RetainedImage<T> {
    fine: Array2<T>,
    spare: Array2<T>,
    /// The original transform's description (size, levels, normalisation).
    info: TransformInfo,
    precision: u32,
    offset: (GridShift, GridShift),
    work: ShiftWorkspace<T>,
}

impl<T: Sample> RetainedImage<T> {
    /// Retains pyramid coefficients at `precision` extra levels, within
    /// [`DEFAULT_MEMORY_BUDGET`].
    pub fn new(coeffs: &Coefficients<T>, precision: u32) -> Result<Self> {
        Self::with_budget(coeffs, precision, DEFAULT_MEMORY_BUDGET)
    }

    /// Retains with an explicit budget in bytes for the two fine arrays (`2 x 4^h` times the
    /// coefficient array), refusing with [`Error::MemoryBudget`] beyond it.
    ///
    /// ```
    /// use haarshift::{Error, shift::RetainedImage, transform::TransformSpec};
    /// let c = TransformSpec::default().forward(ndarray::Array2::<f32>::zeros((512, 512)).view()).unwrap();
    /// let err = RetainedImage::with_budget(&c, 4, 100 << 20).unwrap_err();
    /// assert!(matches!(err, Error::MemoryBudget { needed, .. } if needed == 2 * 512 * 512 * 256 * 4));
    /// assert!(RetainedImage::with_budget(&c, 2, 100 << 20).is_ok());
    /// ```
    pub fn with_budget(coeffs: &Coefficients<T>, precision: u32, budget: u64) -> Result<Self> {
        let info = coeffs.info();
        if info.layout != Layout::Pyramid {
            return Err(Error::parameter(
                "layout",
                "retained shifting is implemented for the pyramid layout",
            ));
        }
        let (rows, cols) = coeffs.as_array().dim();
        let p = precision.min(MAX_PRECISION + 1);
        let elements = ((rows as u128) << p) * ((cols as u128) << p);
        let n = check_budget::<T>("image", elements, precision, budget)?;
        let shape = (rows << precision, cols << precision);
        let mut fine = Array2::from_shape_vec(shape, try_zeros(n)?)
            .map_err(|e| Error::shape(&[shape.0, shape.1], e.to_string()))?;
        fine.slice_mut(s![..rows, ..cols])
            .assign(&coeffs.as_array());
        let spare = Array2::from_shape_vec(shape, try_zeros(n)?)
            .map_err(|e| Error::shape(&[shape.0, shape.1], e.to_string()))?;
        Ok(RetainedImage {
            fine,
            spare,
            info: *info,
            precision,
            offset: (GridShift::whole(0), GridShift::whole(0)),
            work: ShiftWorkspace::default(),
        })
    }

    /// Shifts by `dx` columns and `dy` rows, each rounded to the `1 / 2^h` grid
    /// ([`GridShift`] rules): exact on the retained grid.
    pub fn shift(&mut self, dx: f64, dy: f64) -> Result<()> {
        let dx = GridShift::new(dx, self.precision)?;
        let dy = GridShift::new(dy, self.precision)?;
        let levels = self.info.levels[0] + self.precision as usize;
        shift_pyramid_into(
            self.fine.view(),
            levels,
            self.info.normalization,
            dx.in_grid_units(),
            dy.in_grid_units(),
            self.spare.view_mut(),
            &mut self.work,
        )?;
        std::mem::swap(&mut self.fine, &mut self.spare);
        self.offset = (self.offset.0 + dx, self.offset.1 + dy);
        Ok(())
    }

    /// The total `(dx, dy)` applied so far, in pixels.
    pub fn offset(&self) -> (f64, f64) {
        (self.offset.0.amount(), self.offset.1.amount())
    }

    /// The precision `h`.
    pub fn precision(&self) -> u32 {
        self.precision
    }

    /// The retained transform: `2^h` times the rows and columns, `levels + h` levels.
    pub fn fine(&self) -> ArrayView2<'_, T> {
        self.fine.view()
    }

    /// Box-averaged back to the original size and levels (the top-left block of the
    /// retained transform), with the original [`TransformInfo`].
    pub fn project(&self) -> Coefficients<T> {
        let (rows, cols) = (
            self.fine.nrows() >> self.precision,
            self.fine.ncols() >> self.precision,
        );
        let data = self.fine.slice(s![..rows, ..cols]).to_owned();
        Coefficients::from_trusted_parts(data, self.info)
    }
}
