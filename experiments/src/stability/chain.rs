//! Long chains of Haar shifts: whole shifts (bit-exact where the arithmetic is, see the
//! [`shift`](haarshift::shift#exactness) module docs) and fractional ones in f32 against f64.

use ndarray::{Array2, ArrayView2};

use super::{Category, StabilityRecord, Subject, max_abs_diff, measure, peak};
use haarshift::Result;
use haarshift::kernels::{Outside, ShiftMethod, shift_plane};
use haarshift::patterns::whole_shifts;
use haarshift::transform::{Coefficients, Levels, Normalization, TransformSpec};
use haarshift::{BoundaryMode, Sample};

/// `x` rolled periodically by `(dx, dy)` (content right and down): the linear kernel with
/// wrapped rows, which copies rows for whole shifts.
fn roll(x: ArrayView2<'_, f64>, dx: i64, dy: i64) -> Result<Array2<f64>> {
    let (h, w) = (x.nrows() as i64, x.ncols() as i64);
    let linear = ShiftMethod::Linear.kernel::<f64>();
    shift_plane(
        x,
        dx.rem_euclid(w) as f64,
        dy.rem_euclid(h) as f64,
        linear.as_ref(),
        Outside::Boundary(BoundaryMode::Wrap),
    )
}

/// Applies the chain to the transform of `x` and returns the final coefficients and those of
/// `x` rolled by the chain's sum.
fn run_whole_chain(
    subject: &impl Subject,
    x: ArrayView2<'_, f64>,
    spec: &TransformSpec,
    shifts: &[(i64, i64)],
) -> Result<(Coefficients<f64>, Coefficients<f64>)> {
    let mut c = spec.forward(x)?;
    for &(dx, dy) in shifts {
        c = subject.shift_image(&c, dx as f64, dy as f64, 0)?;
    }
    let (tx, ty) = shifts
        .iter()
        .fold((0, 0), |(a, b), &(dx, dy)| (a + dx, b + dy));
    let want = spec.forward(roll(x, tx, ty)?.view())?;
    Ok((c, want))
}

/// The chain checks on `image` (8-bit, 128x128): `integer` whole shifts in four settings and
/// `fractional` compact shifts in f32 against f64. Returns the records and the f32 drift
/// after each logged number of shifts. The shifts are `subject`'s.
pub fn checks(
    image: ArrayView2<'_, f64>,
    integer: usize,
    fractional: usize,
    subject: &impl Subject,
) -> (Vec<StabilityRecord>, Vec<(usize, f64)>) {
    let exact = |name: &str, x: &Array2<f64>, spec: TransformSpec, unit: i64, what: &str| {
        let shifts = whole_shifts(integer, 100, unit);
        measure(Category::Shift, name, 0.0, || {
            let (got, want) = run_whole_chain(subject, x.view(), &spec, &shifts)?;
            Ok((
                max_abs_diff(got.as_array(), want.as_array()),
                format!("{what}: max |chain - transform of the rolled image|"),
            ))
        })
        .with("shifts", integer)
    };
    let floats = image.mapv(|v| (v + 0.5) * std::f64::consts::FRAC_1_SQRT_2 / 3.0);
    let orthonormal = TransformSpec {
        normalization: Normalization::Orthonormal,
        ..Default::default()
    };
    let partial = TransformSpec {
        levels: Levels::Count(4),
        ..Default::default()
    };
    let photo = image.to_owned();
    let mut records = vec![
        exact(
            "whole shifts, 8-bit, average",
            &photo,
            TransformSpec::default(),
            1,
            "8-bit photo, full depth",
        ),
        exact(
            "whole shifts, 8-bit, orthonormal",
            &photo,
            orthonormal,
            1,
            "8-bit photo, orthonormal pyramid",
        ),
        exact(
            "multiples of 2^L, floats",
            &floats,
            partial,
            16,
            "arbitrary floats, 4 levels, shifts by multiples of 16",
        ),
    ];
    let shifts = whole_shifts(integer, 100, 1);
    records.push(
        measure(
            Category::Shift,
            "whole shifts, floats (drift)",
            1e-12,
            || {
                let (got, want) =
                    run_whole_chain(subject, floats.view(), &TransformSpec::default(), &shifts)?;
                let drift = max_abs_diff(got.as_array(), want.as_array()) / peak(want.as_array());
                Ok((
                    drift,
                    "arbitrary floats, arbitrary whole shifts: relative drift; cannot be 0, \
                 forward(inverse(c)) rounds"
                        .into(),
                ))
            },
        )
        .with("shifts", integer),
    );
    let mut drift = Vec::new();
    records.push(
        measure(
            Category::Shift,
            "fractional shifts, f32 vs f64",
            fractional_tolerance(fractional),
            || {
                drift = fractional_drift(subject, image, fractional)?;
                let worst = drift.iter().fold(0.0f64, |m, d| m.max(d.1));
                Ok((
                    worst,
                    format!(
                        "compact h={FRACTIONAL_H} steps of {FRACTIONAL_STEP:?}: max |f32 - f64| / \
                         peak, worst of the logged steps"
                    ),
                ))
            },
        )
        .with("shifts", fractional),
    );
    (records, drift)
}

/// Precision of the fractional chain.
const FRACTIONAL_H: u32 = 8;
/// Each step of the fractional chain (rounded to `1/2^8`: 0.31640625 and -0.70703125).
const FRACTIONAL_STEP: (f64, f64) = (
    std::f64::consts::FRAC_1_PI,
    -std::f64::consts::FRAC_1_SQRT_2,
);

/// The stated bound on the f32 chain's relative drift after `k` shifts: each shift rounds at
/// most twice per level in each transform direction (7 levels at 128x128), about
/// `28 eps` relative, and linear interpolation never amplifies: `28 k eps_f32`.
///
/// ```
/// let t = haarshift_experiments::stability::chain::fractional_tolerance(1000);
/// assert!((t - 28000.0 * f64::from(f32::EPSILON)).abs() < 1e-12);
/// ```
pub fn fractional_tolerance(k: usize) -> f64 {
    28.0 * k as f64 * f64::from(f32::EPSILON)
}

/// `(k, max |f32 chain - f64 chain| / peak)` after `k = 1, 2, 5, 10, 20, 50, ...` shifts and at
/// the end.
pub fn fractional_drift(
    subject: &impl Subject,
    image: ArrayView2<'_, f64>,
    count: usize,
) -> Result<Vec<(usize, f64)>> {
    let spec = TransformSpec::default();
    let mut c64 = spec.forward(image)?;
    let mut c32 = spec.forward(image.mapv(|v| v as f32).view())?;
    let scale = peak(image);
    let mut out = Vec::new();
    for k in 1..=count {
        c64 = subject.shift_image(&c64, FRACTIONAL_STEP.0, FRACTIONAL_STEP.1, FRACTIONAL_H)?;
        c32 = subject.shift_image(&c32, FRACTIONAL_STEP.0, FRACTIONAL_STEP.1, FRACTIONAL_H)?;
        if logged(k) || k == count {
            let a = c64.inverse()?;
            let b = c32.inverse()?.mapv(|v| v.as_f64());
            out.push((k, max_abs_diff(a.view(), b.view()) / scale));
        }
    }
    Ok(out)
}

/// 1, 2, 5, 10, 20, 50, ...
fn logged(k: usize) -> bool {
    let mut p = 1;
    while p <= k {
        if [p, 2 * p, 5 * p].contains(&k) {
            return true;
        }
        p *= 10;
    }
    false
}

#[cfg(test)]
#[path = "chain_tests.rs"]
mod tests;
