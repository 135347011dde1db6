//! The numerical-stability experiment: the library at its extremes (angles, sizes, value
//! ranges, long shift chains, precisions), each check with a measured figure, a stated
//! tolerance and a pass/fail.
//!
//! Every check has an oracle that does not come from the code under test: a quarter-turn
//! permutation, the transform of a rolled image, a pixel-domain interpolation, a bound
//! derived from the angle and the image's gradient, or a documented cost formula. A check
//! whose right answer is an error (a non-finite input, a precision beyond the maximum, a size
//! beyond the memory budget) passes when the library returns that typed error, with the error
//! in the `detail`; a panic, an unexpected error or a figure above its tolerance fails.
//!
//! The families, one module each:
//!
//! * [`angle`]: 0, 1e-9, 45 +- 1e-6, 90 +- 1e-9, 180, -180, 359.999 and 1e6 degrees, for the
//!   linear, Keys, cubic B-spline, FFT and compact Haar kernels.
//! * [`size`]: 1x1, 1xN, Nx1, 2x2, prime and 2:1 sizes through the transform, Haar shifts and
//!   rotations; the largest square the rotation's memory budget allows.
//! * [`values`]: images scaled from 1e-30 to 1e30 (and f32 subnormals), constant images, a
//!   single impulse, a Nyquist checkerboard, NaN and infinity.
//! * [`chain`]: 10^4 successive whole Haar shifts (bit-exact where the arithmetic is) and
//!   10^3 fractional ones in f32 against f64.
//! * [`precision`]: the Haar precision `h` from 0 to [`MAX_PRECISION`] (compact) and to the
//!   memory budget (retained).
//!
//! [`MAX_PRECISION`]: haarshift::shift::MAX_PRECISION

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};

use ndarray::{Array2, ArrayView2, s};
use serde::{Deserialize, Serialize};

use crate::rotation_cycle::MemoryMeter;
use haarshift::Sample;
use haarshift::kernels::{KernelOptions, ShearKernel, ShiftMethod};
use haarshift::named_enum;
use haarshift::transform::Coefficients;
use haarshift::{Error, Result};

pub mod angle;
pub mod chain;
pub mod precision;
pub mod size;
pub mod values;

named_enum! {
    /// The family a check belongs to.
    pub enum Category ("category") {
        /// Rotation angles.
        Angle = "angle",
        /// Array sizes and the memory budget.
        Size = "size",
        /// Value ranges and special images.
        Values = "values",
        /// Long chains of shifts.
        Shift = "shift",
        /// The Haar precision `h`.
        Precision = "precision",
    }
}

/// One check's result.
///
/// ```
/// use haarshift_experiments::stability::{Category, StabilityRecord};
/// let r = StabilityRecord::measured(Category::Angle, "0", 0.0, 0.0, "bit-exact");
/// assert!(r.pass);
/// assert!(!StabilityRecord::measured(Category::Angle, "0", 1e-3, 0.0, "").pass);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StabilityRecord {
    /// Family.
    pub category: Category,
    /// Name of the check.
    pub check: String,
    /// The check's parameters (kernel, angle, size, scale, ...), one column each in CSV.
    #[serde(flatten)]
    pub parameters: BTreeMap<String, serde_json::Value>,
    /// The measured number (an error, a drift, a byte count); null when the right answer was
    /// an error.
    pub figure: Option<f64>,
    /// What `figure` is compared against (`figure <= tolerance` passes); null for error checks.
    pub tolerance: Option<f64>,
    /// Whether the check passed.
    pub pass: bool,
    /// One line: what was compared, or the error returned.
    pub detail: String,
}

impl StabilityRecord {
    /// A measured check: passes when `figure` is a number no larger than `tolerance`.
    pub fn measured(
        category: Category,
        check: impl Into<String>,
        figure: f64,
        tolerance: f64,
        detail: impl Into<String>,
    ) -> Self {
        StabilityRecord {
            category,
            check: check.into(),
            parameters: BTreeMap::new(),
            figure: Some(figure),
            tolerance: Some(tolerance),
            pass: figure <= tolerance,
            detail: detail.into(),
        }
    }

    /// Adds a parameter.
    ///
    /// ```
    /// use haarshift_experiments::stability::{Category, StabilityRecord};
    /// let r = StabilityRecord::measured(Category::Size, "round trip", 0.0, 0.0, "")
    ///     .with("size", "13x17");
    /// assert_eq!(r.parameters["size"], "13x17");
    /// ```
    pub fn with(mut self, name: &str, value: impl Into<serde_json::Value>) -> Self {
        self.parameters.insert(name.to_owned(), value.into());
        self
    }

    /// A failed check whose code returned `error` or panicked.
    fn broken(category: Category, check: String, detail: String) -> Self {
        StabilityRecord {
            category,
            check,
            parameters: BTreeMap::new(),
            figure: None,
            tolerance: None,
            pass: false,
            detail,
        }
    }
}

/// What a check measured: the figure and a one-line description.
pub(crate) type Measured = (f64, String);

/// Runs a measured check: `measure` returns the figure and detail; an error or a panic
/// inside it becomes a failed record naming it.
pub(crate) fn measure(
    category: Category,
    check: impl Into<String>,
    tolerance: f64,
    measure: impl FnOnce() -> Result<Measured>,
) -> StabilityRecord {
    let check = check.into();
    match catch_unwind(AssertUnwindSafe(measure)) {
        Ok(Ok((figure, detail))) => {
            StabilityRecord::measured(category, check, figure, tolerance, detail)
        }
        Ok(Err(e)) => StabilityRecord::broken(category, check, format!("unexpected error: {e}")),
        Err(panic) => StabilityRecord::broken(category, check, panic_text(panic)),
    }
}

/// Runs a check whose right answer is an error: passes when `attempt` returns an error that
/// `accept` recognises (its text becomes the detail); fails when it succeeds (`attempt`
/// describes what it returned), returns another error, or panics.
pub(crate) fn expect_error(
    category: Category,
    check: impl Into<String>,
    accept: impl Fn(&Error) -> bool,
    attempt: impl FnOnce() -> Result<String>,
) -> StabilityRecord {
    let check = check.into();
    let (pass, detail) = match catch_unwind(AssertUnwindSafe(attempt)) {
        Ok(Err(e)) if accept(&e) => (true, format!("error as expected: {e}")),
        Ok(Err(e)) => (false, format!("wrong error: {e}")),
        Ok(Ok(what)) => (false, format!("no error: {what}")),
        Err(panic) => (false, panic_text(panic)),
    };
    StabilityRecord {
        pass,
        detail,
        ..StabilityRecord::broken(category, check, String::new())
    }
}

/// [`expect_error`] for a refusal on memory grounds: also measures with `meter` what the
/// refused call allocated, which must stay below [`REFUSAL_ALLOWANCE`] (the figure, when the
/// meter can tell).
pub(crate) fn expect_refusal(
    category: Category,
    check: impl Into<String>,
    meter: &dyn MemoryMeter,
    accept: impl Fn(&Error) -> bool,
    attempt: impl FnOnce() -> Result<String>,
) -> StabilityRecord {
    meter.reset_peak();
    let mut record = expect_error(category, check, accept, attempt);
    if let Some(bytes) = meter.peak_bytes() {
        record.figure = Some(bytes as f64);
        record.tolerance = Some(REFUSAL_ALLOWANCE as f64);
        record.pass &= bytes <= REFUSAL_ALLOWANCE;
        record
            .detail
            .push_str(&format!("; allocated while refusing: {bytes} bytes"));
    }
    record
}

/// The code the experiment puts to the test: the shear kernels (through every rotation) and
/// the compact Haar shift of an image's coefficients. [`Library`] is haarshift's own; the
/// experiment's tests hand each family deliberately wrong ones and see it report failure, so
/// that no check passes whatever the code does.
///
/// ```
/// use haarshift_experiments::stability::{Library, Subject};
/// use haarshift::kernels::{KernelOptions, ShiftMethod};
/// let keys = Library.kernel::<f64>(ShiftMethod::Keys, &KernelOptions::default()).unwrap();
/// assert!(keys.name().starts_with("keys"));
/// ```
pub trait Subject {
    /// The kernel of `method` with `options` (as [`ShiftMethod::kernel_with`]).
    fn kernel<T: Sample>(
        &self,
        method: ShiftMethod,
        options: &KernelOptions,
    ) -> Result<Box<dyn ShearKernel<T>>>;

    /// `coeffs` shifted by `(dx, dy)` at precision `h` (as [`haarshift::shift::shift_image`]).
    fn shift_image<T: Sample>(
        &self,
        coeffs: &Coefficients<T>,
        dx: f64,
        dy: f64,
        h: u32,
    ) -> Result<Coefficients<T>>;
}

/// haarshift's own kernels and Haar shift: what [`run_stability`] checks.
///
/// ```
/// use haarshift_experiments::stability::{Library, Subject};
/// use haarshift::transform::TransformSpec;
/// let c = TransformSpec::default().forward(ndarray::array![[1.0, 2.0], [3.0, 4.0]].view()).unwrap();
/// let shifted = Library.shift_image(&c, 1.0, 0.0, 0).unwrap().inverse().unwrap();
/// assert_eq!(shifted, ndarray::array![[2.0, 1.0], [4.0, 3.0]]);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct Library;

impl Subject for Library {
    fn kernel<T: Sample>(
        &self,
        method: ShiftMethod,
        options: &KernelOptions,
    ) -> Result<Box<dyn ShearKernel<T>>> {
        method.kernel_with(options)
    }

    fn shift_image<T: Sample>(
        &self,
        coeffs: &Coefficients<T>,
        dx: f64,
        dy: f64,
        h: u32,
    ) -> Result<Coefficients<T>> {
        haarshift::shift::shift_image(coeffs, dx, dy, h)
    }
}

/// What a refusal on memory grounds may allocate: 1 MiB.
pub const REFUSAL_ALLOWANCE: u64 = 1 << 20;

fn panic_text(panic: Box<dyn std::any::Any + Send>) -> String {
    let message = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    format!("panicked: {message}")
}

/// The inputs of the experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityConfig {
    /// An 8-bit photograph (integer values 0..=255), at least 128x128; see [`eight_bit`].
    pub photo: Array2<f64>,
    /// Length of the whole-shift chains (the issue asks for 10^4).
    pub integer_shifts: usize,
    /// Length of the fractional f32-against-f64 chain (the issue asks for 10^3).
    pub fractional_shifts: usize,
}

impl StabilityConfig {
    /// The full experiment on `photo`: 10^4 whole shifts, 10^3 fractional ones.
    pub fn new(photo: Array2<f64>) -> Self {
        StabilityConfig {
            photo,
            integer_shifts: 10_000,
            fractional_shifts: 1_000,
        }
    }
}

/// The experiment's results: every check, and the drift of the f32 fractional chain against
/// the f64 one after each number of shifts (for the plot).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StabilityReport {
    /// Every check, in the order run.
    pub records: Vec<StabilityRecord>,
    /// `(shifts, drift)`: the f32 chain's largest deviation from the f64 chain, relative to
    /// the image's peak, after that many shifts.
    pub drift: Vec<(usize, f64)>,
}

impl StabilityReport {
    /// How many checks failed.
    pub fn failures(&self) -> usize {
        self.records.iter().filter(|r| !r.pass).count()
    }
}

/// Rounds a plane to 8-bit code values (0..=255): the photograph input of the experiment,
/// whose dyadic exactness some checks rely on.
///
/// ```
/// let p = haarshift_experiments::stability::eight_bit(ndarray::array![[-3.0, 12.4], [300.0, 7.5]].view());
/// assert_eq!(p, ndarray::array![[0.0, 12.0], [255.0, 8.0]]);
/// ```
pub fn eight_bit(plane: ArrayView2<'_, f64>) -> Array2<f64> {
    plane.mapv(|v| v.round().clamp(0.0, 255.0))
}

/// How many checks [`run_stability`] runs (for a progress bar): one per family step.
pub const FAMILIES: usize = 5;

/// Runs every family on `config`; `meter` measures what the budget refusals allocate;
/// `progress` is called after each family with its name.
///
/// ```
/// use haarshift_experiments::rotation_cycle::NoMeter;
/// use haarshift_experiments::stability::{StabilityConfig, eight_bit, run_stability};
/// let photo = ndarray::Array2::from_shape_fn((160, 160), |(i, j)| ((i * 7 + j * 13) % 256) as f64);
/// let mut config = StabilityConfig::new(eight_bit(photo.view()));
/// (config.integer_shifts, config.fractional_shifts) = (20, 5);
/// let report = run_stability(&config, &NoMeter, |_| {}).unwrap();
/// assert_eq!(report.failures(), 0);
/// assert_eq!(report.drift.last().unwrap().0, 5);
/// ```
pub fn run_stability(
    config: &StabilityConfig,
    meter: &dyn MemoryMeter,
    mut progress: impl FnMut(&str),
) -> Result<StabilityReport> {
    let (h, w) = config.photo.dim();
    if h < 128 || w < 128 {
        return Err(Error::shape(
            &[h, w],
            "the photograph must be at least 128x128",
        ));
    }
    let crop = |side: usize| centre_crop(config.photo.view(), side);
    let subject = &Library;
    let mut records = angle::checks(crop(64).view(), subject);
    progress("angle");
    records.extend(size::checks(crop(131).view(), meter, subject));
    progress("size");
    records.extend(values::checks(crop(64).view(), subject));
    progress("values");
    let (chain_records, drift) = chain::checks(
        crop(128).view(),
        config.integer_shifts,
        config.fractional_shifts,
        subject,
    );
    records.extend(chain_records);
    progress("shift");
    records.extend(precision::checks(crop(32).view(), meter, subject));
    progress("precision");
    Ok(StabilityReport { records, drift })
}

/// The centred `side x side` crop (the whole plane when smaller).
pub(crate) fn centre_crop(plane: ArrayView2<'_, f64>, side: usize) -> Array2<f64> {
    let (h, w) = plane.dim();
    let (sh, sw) = (side.min(h), side.min(w));
    let (top, left) = ((h - sh) / 2, (w - sw) / 2);
    plane.slice(s![top..top + sh, left..left + sw]).to_owned()
}

/// A kernel with its name in the experiment's records.
pub(crate) type NamedKernel<T> = (String, Box<dyn ShearKernel<T>>);

/// The kernels the angle and value checks run: linear, Keys, cubic B-spline, FFT and compact
/// Haar at `h = 3`, from `subject`.
pub(crate) fn kernels<T: Sample>(subject: &impl Subject) -> Result<Vec<NamedKernel<T>>> {
    let haar = KernelOptions {
        precision: 3,
        ..Default::default()
    };
    let default = KernelOptions::default();
    [
        ShiftMethod::Linear,
        ShiftMethod::Keys,
        ShiftMethod::BSpline3,
        ShiftMethod::Fft,
    ]
    .into_iter()
    .map(|m| (m.name().to_owned(), m, &default))
    .chain([("haar-compact".to_owned(), ShiftMethod::Haar, &haar)])
    .map(|(name, method, options)| Ok((name, subject.kernel::<T>(method, options)?)))
    .collect()
}

/// Largest absolute difference (as f64) between two arrays of one shape; infinite when the
/// shapes differ or a value is not finite, so that such a result can never pass.
pub(crate) fn max_abs_diff<T: Sample>(a: ArrayView2<'_, T>, b: ArrayView2<'_, T>) -> f64 {
    if a.dim() != b.dim() {
        return f64::INFINITY;
    }
    a.iter().zip(b.iter()).fold(0.0, |m, (&x, &y)| {
        let d = (x.as_f64() - y.as_f64()).abs();
        if d.is_nan() { f64::INFINITY } else { m.max(d) }
    })
}

/// Largest absolute value (as f64).
pub(crate) fn peak<T: Sample>(a: ArrayView2<'_, T>) -> f64 {
    a.iter().fold(0.0, |m, &v| m.max(v.as_f64().abs()))
}

#[cfg(test)]
mod tests;
