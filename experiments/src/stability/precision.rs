//! The Haar precision `h`: compact shifts for every `h` up to [`MAX_PRECISION`] against their
//! pixel-domain equivalent, the first `h` beyond it refused; retained shifts up to what the
//! experiment can afford against the compact shift they project to, and the first `h` beyond
//! the memory budget refused without allocating.

use ndarray::ArrayView2;

use super::size::haar_against_pixels;
use super::{
    Category, StabilityRecord, Subject, expect_error, expect_refusal, max_abs_diff, measure,
};
use crate::rotation_cycle::MemoryMeter;
use haarshift::shift::{DEFAULT_MEMORY_BUDGET, MAX_PRECISION, RetainedImage};
use haarshift::transform::TransformSpec;
use haarshift::{Error, Result};

/// The shift of the precision checks: irrational-looking amounts, rounded differently at
/// every `h`.
const SHIFT: (f64, f64) = (5.317, -2.709);

/// The compact precisions checked.
pub const COMPACT: [u32; 9] = [0, 1, 2, 3, 5, 8, 12, 16, MAX_PRECISION];

/// The retained precisions run (the largest needs 64 MiB on a 16x16 image).
pub const RETAINED: [u32; 5] = [0, 1, 2, 4, 7];

/// The precision checks: compact on `image`, retained on its top-left 16x16 block.
/// The compact shift comes from `subject`.
pub fn checks(
    image: ArrayView2<'_, f64>,
    meter: &dyn MemoryMeter,
    subject: &impl Subject,
) -> Vec<StabilityRecord> {
    let mut out: Vec<StabilityRecord> = COMPACT
        .iter()
        .map(|&h| {
            measure(
                Category::Precision,
                format!("compact h={h}"),
                1e-12 * 255.0,
                || {
                    haar_against_pixels(subject, image, SHIFT, h).map(|d| {
                        (
                            d,
                            "vs periodic bilinear interpolation at the rounded shift".into(),
                        )
                    })
                },
            )
            .with("precision", h)
        })
        .collect();
    let c = TransformSpec::default().forward(image);
    out.push(
        expect_error(
            Category::Precision,
            format!("compact h={}", MAX_PRECISION + 1),
            |e| matches!(e, Error::InvalidParameter { .. }),
            || {
                let c = c
                    .as_ref()
                    .map_err(|e| Error::parameter("image", e.to_string()))?;
                subject
                    .shift_image(c, SHIFT.0, SHIFT.1, MAX_PRECISION + 1)
                    .map(|_| "shifted".into())
            },
        )
        .with("precision", MAX_PRECISION + 1),
    );
    let small = image.slice(ndarray::s![..16, ..16]);
    for h in RETAINED {
        out.push(
            measure(
                Category::Precision,
                format!("retained h={h}"),
                1e-12 * 255.0,
                || {
                    retained_against_compact(subject, small, h).map(|d| {
                        (
                            d,
                            format!(
                                "projection vs the compact shift ({} bytes retained)",
                                retained_bytes(16, h)
                            ),
                        )
                    })
                },
            )
            .with("precision", h),
        );
    }
    out.push(retained_budget(small, meter));
    out
}

/// Bytes a retained `side x side` f64 image takes at precision `h`: the retained transform and
/// its double buffer, `2 x 4^h` times the coefficients, as [`RetainedImage`] documents.
///
/// ```
/// assert_eq!(haarshift_experiments::stability::precision::retained_bytes(16, 9), 1 << 30);
/// ```
pub fn retained_bytes(side: usize, h: u32) -> u128 {
    2 * (side * side) as u128 * 4u128.pow(h) * 8
}

fn retained_against_compact(subject: &impl Subject, x: ArrayView2<'_, f64>, h: u32) -> Result<f64> {
    let c = TransformSpec::default().forward(x)?;
    let mut r = RetainedImage::new(&c, h)?;
    r.shift(SHIFT.0, SHIFT.1)?;
    let compact = subject.shift_image(&c, SHIFT.0, SHIFT.1, h)?;
    Ok(max_abs_diff(r.project().as_array(), compact.as_array()))
}

/// The largest `h` within the default budget is computed from the documented cost (not run
/// beyond the experiment's allowance); the next is refused with the documented byte count.
fn retained_budget(x: ArrayView2<'_, f64>, meter: &dyn MemoryMeter) -> StabilityRecord {
    let side = x.nrows();
    let budget = u128::from(DEFAULT_MEMORY_BUDGET);
    let h_max = (0..=MAX_PRECISION)
        .take_while(|&h| retained_bytes(side, h) <= budget)
        .last()
        .unwrap_or(0);
    let over = h_max + 1;
    let want = retained_bytes(side, over);
    let c = TransformSpec::default().forward(x);
    let mut record = expect_refusal(
        Category::Precision,
        format!("retained h={over}"),
        meter,
        |e| matches!(e, Error::MemoryBudget { needed, .. } if *needed == want),
        || {
            let c = c
                .as_ref()
                .map_err(|e| Error::parameter("image", e.to_string()))?;
            RetainedImage::new(c, over).map(|_| "retained".into())
        },
    )
    .with("precision", over);
    record.detail = format!(
        "h={h_max} is the largest within {budget} bytes (needs {} bytes; computed, not run); \
         h={over} must be refused needing {want}: {}",
        retained_bytes(side, h_max),
        record.detail
    );
    record
}

#[cfg(test)]
#[path = "precision_tests.rs"]
mod tests;
