//! Sizes: degenerate, prime and 2:1 shapes through the transform round trip, Haar shifts and
//! rotations, and the largest square the rotation's memory budget allows.

use ndarray::{Array2, ArrayView2, s};

use super::{Category, StabilityRecord, Subject, expect_refusal, max_abs_diff, measure, peak};
use crate::rotation_cycle::MemoryMeter;
use haarshift::BoundaryMode;
use haarshift::kernels::KernelOptions;
use haarshift::kernels::{Outside, ShiftMethod, shift_plane};
use haarshift::rotate::{DEFAULT_MEMORY_BUDGET, RotateOptions, rotate_plane};
use haarshift::shift::GridShift;
use haarshift::transform::{TransformSpec, pad_to_power_of_two};
use haarshift::{Error, Result};

/// The shapes checked: a single pixel, a row, a column, 2x2, two prime shapes, and 2:1.
pub const SHAPES: [(usize, usize); 7] = [
    (1, 1),
    (1, 17),
    (17, 1),
    (2, 2),
    (13, 17),
    (127, 131),
    (64, 128),
];

/// The rotation budget small enough to run the largest accepted square in the experiment.
pub const AFFORDABLE_BUDGET: u64 = 8 << 20;

/// The size checks on sub-blocks of `image` (8-bit values, at least 131 on each side), and
/// the budget checks; the kernel and the Haar shift from `subject`.
pub fn checks(
    image: ArrayView2<'_, f64>,
    meter: &dyn MemoryMeter,
    subject: &impl Subject,
) -> Vec<StabilityRecord> {
    let mut out = Vec::new();
    for (h, w) in SHAPES {
        let x = image.slice(s![..h.min(image.nrows()), ..w.min(image.ncols())]);
        let size = format!("{h}x{w}");
        out.extend(
            shape_checks(x, subject)
                .into_iter()
                .map(|r| r.with("size", size.as_str())),
        );
    }
    out.push(largest_affordable(meter));
    out.push(largest_within_default(meter));
    out
}

/// Round trip, a whole and a fractional Haar shift, and a rotation of a constant, for one
/// shape.
fn shape_checks(x: ArrayView2<'_, f64>, subject: &impl Subject) -> Vec<StabilityRecord> {
    let spec = TransformSpec::default();
    let peak_x = peak(x).max(1.0);
    let round_trip = measure(Category::Size, "round trip", 0.0, || {
        let back = spec.forward(x)?.inverse()?;
        Ok((
            max_abs_diff(back.view(), x),
            "max |inverse(forward(x)) - x|, 8-bit data: exact".into(),
        ))
    });
    let whole = measure(Category::Size, "haar shift (3, -2)", 0.0, || {
        haar_against_pixels(subject, x, (3.0, -2.0), 0)
            .map(|d| (d, "vs the periodic roll: exact".into()))
    });
    let fractional = measure(
        Category::Size,
        "haar shift (0.375, -1.25) h=3",
        1e-12 * peak_x,
        || {
            haar_against_pixels(subject, x, (0.375, -1.25), 3).map(|d| {
                (
                    d,
                    "vs periodic bilinear interpolation of the padded image".into(),
                )
            })
        },
    );
    let constant = measure(Category::Size, "rotate 30 deg, constant", 1e-12, || {
        let c = Array2::from_elem(x.dim(), 0.1);
        let opts = RotateOptions {
            outside: Outside::Boundary(BoundaryMode::Edge),
            ..Default::default()
        };
        let kernel = subject.kernel::<f64>(ShiftMethod::Keys, &KernelOptions::default())?;
        let r = rotate_plane(c.view(), 30.0, kernel.as_ref(), &opts)?;
        Ok((
            max_abs_diff(r.view(), c.view()) / 0.1,
            "keys, edge boundary: relative deviation from the constant 0.1".into(),
        ))
    });
    vec![round_trip, whole, fractional, constant]
}

/// The largest difference between the compact Haar shift of `x` (padded to powers of two by
/// the default transform) and the same shift made in the pixel domain ([`pixel_shift`]).
pub(crate) fn haar_against_pixels(
    subject: &impl Subject,
    x: ArrayView2<'_, f64>,
    (dx, dy): (f64, f64),
    h: u32,
) -> Result<f64> {
    let spec = TransformSpec::default();
    let got = subject
        .shift_image(&spec.forward(x)?, dx, dy, h)?
        .inverse()?;
    Ok(max_abs_diff(
        got.view(),
        pixel_shift(x, (dx, dy), h)?.view(),
    ))
}

/// What the compact Haar shift of `x` by `(dx, dy)` at precision `h` is by definition, in the
/// pixel domain: periodic bilinear interpolation (the linear kernel with wrapped rows) of `x`
/// padded to powers of two as the default transform pads it, at the shift rounded to
/// `1/2^h`, cropped back to `x`'s size.
pub(crate) fn pixel_shift(
    x: ArrayView2<'_, f64>,
    (dx, dy): (f64, f64),
    h: u32,
) -> Result<Array2<f64>> {
    let spec = TransformSpec::default();
    let padded = pad_to_power_of_two(x, spec.padding)?;
    let (rx, ry) = (
        GridShift::new(dx, h)?.amount(),
        GridShift::new(dy, h)?.amount(),
    );
    let linear = ShiftMethod::Linear.kernel::<f64>();
    let want = shift_plane(
        padded.view(),
        rx,
        ry,
        linear.as_ref(),
        Outside::Boundary(BoundaryMode::Wrap),
    )?;
    let (rows, cols) = x.dim();
    Ok(want.slice(s![..rows, ..cols]).to_owned())
}

/// The bytes [`rotate_plane`] needs for an `n x n` f64 plane at 30 degrees with the linear
/// kernel, as its budget check reports them. The plane is a broadcast view of one value, so
/// nothing of size `n^2` is allocated, and a 1-byte budget makes the check refuse every size.
///
/// ```
/// use haarshift_experiments::stability::size::{largest_square, rotation_bytes};
/// let n = largest_square(1 << 20).unwrap();
/// assert!(rotation_bytes(n).unwrap() <= 1 << 20 && rotation_bytes(n + 1).unwrap() > 1 << 20);
/// ```
pub fn rotation_bytes(n: usize) -> Result<u128> {
    let one = ndarray::arr0(1.0f64);
    let plane = one
        .broadcast((n, n))
        .ok_or_else(|| Error::shape(&[n, n], "cannot broadcast"))?;
    let opts = RotateOptions {
        memory_budget: 1,
        ..Default::default()
    };
    let kernel = ShiftMethod::Linear.kernel::<f64>();
    match rotate_plane(plane, 30.0, kernel.as_ref(), &opts) {
        Err(Error::MemoryBudget { needed, .. }) => Ok(needed),
        Err(e) => Err(e),
        Ok(_) => Err(Error::parameter("budget", "a 1-byte budget was accepted")),
    }
}

/// The largest square side whose rotation fits in `budget` bytes, from the library's own
/// budget figures ([`rotation_bytes`]): a quadratic estimate, then exact steps.
pub fn largest_square(budget: u64) -> Result<usize> {
    let probe = 256;
    let per_pixel = rotation_bytes(probe)? as f64 / (probe * probe) as f64;
    let mut n = ((budget as f64 / per_pixel).sqrt() as usize).max(1);
    while rotation_bytes(n + 1)? <= u128::from(budget) {
        n += 1;
    }
    while n > 1 && rotation_bytes(n)? > u128::from(budget) {
        n -= 1;
    }
    Ok(n)
}

/// Within [`AFFORDABLE_BUDGET`]: the largest square rotates, one pixel more is refused. The
/// figure is what the accepted rotation allocated, as `meter` measures it (its output
/// included, its input not), against the budget; with a meter that cannot tell, the library's own
/// figure for the rotation, which `largest_square` keeps within the budget by construction
/// (the detail says which).
fn largest_affordable(meter: &dyn MemoryMeter) -> StabilityRecord {
    let budget = AFFORDABLE_BUDGET;
    measure(
        Category::Size,
        "largest square within 8 MiB",
        budget as f64,
        || {
            let n = largest_square(budget)?;
            let needed = rotation_bytes(n)?;
            let opts = RotateOptions {
                memory_budget: budget,
                ..Default::default()
            };
            let kernel = ShiftMethod::Linear.kernel::<f64>();
            let ok = Array2::from_elem((n, n), 1.0);
            meter.reset_peak();
            rotate_plane(ok.view(), 30.0, kernel.as_ref(), &opts)?;
            let (figure, what) = match meter.peak_bytes() {
                Some(bytes) => (bytes as f64, "allocated"),
                None => (needed as f64, "needs, by the library's count"),
            };
            let big = Array2::from_elem((n + 1, n + 1), 1.0);
            match rotate_plane(big.view(), 30.0, kernel.as_ref(), &opts) {
                Err(Error::MemoryBudget { needed: over, .. }) => Ok((
                    figure,
                    format!(
                        "{n}x{n} rotated ({what} {figure} bytes; the library counts {needed}); \
                         {m}x{m} refused (needs {over})",
                        m = n + 1
                    ),
                )),
                other => Err(Error::parameter(
                    "budget",
                    format!(
                        "{}x{} was not refused: {:?}",
                        n + 1,
                        n + 1,
                        other.map(|_| ())
                    ),
                )),
            }
        },
    )
    .with("budget", budget)
}

/// Within the default 4 GiB budget: the largest square is computed from the library's
/// figures (not run: it would allocate about 4 GiB), one pixel more is refused without
/// allocating (the input is a broadcast view of one value).
fn largest_within_default(meter: &dyn MemoryMeter) -> StabilityRecord {
    let budget = DEFAULT_MEMORY_BUDGET;
    let largest = largest_square(budget).and_then(|n| Ok((n, rotation_bytes(n)?)));
    let (n, needed) = match largest {
        Ok(found) => found,
        Err(e) => {
            return measure(Category::Size, "largest square within 4 GiB", 0.0, || {
                Err(e)
            });
        }
    };
    let one = ndarray::arr0(1.0f64);
    let kernel = ShiftMethod::Linear.kernel::<f64>();
    let mut record = expect_refusal(
        Category::Size,
        "largest square within 4 GiB",
        meter,
        |e| matches!(e, Error::MemoryBudget { .. }),
        || {
            let over = one
                .broadcast((n + 1, n + 1))
                .ok_or_else(|| Error::shape(&[n + 1], "cannot broadcast"))?;
            rotate_plane(over, 30.0, kernel.as_ref(), &RotateOptions::default())
                .map(|r| format!("rotated {}x{}", r.nrows(), r.ncols()))
        },
    )
    .with("budget", budget);
    record.detail = format!(
        "{n}x{n} fits (needs {needed} bytes; computed, not run); {m}x{m}: {}",
        record.detail,
        m = n + 1
    );
    record
}

#[cfg(test)]
#[path = "size_tests.rs"]
mod tests;
