//! Synthetic test patterns that stress resampling: a zone plate (every frequency up to
//! Nyquist) and a Siemens star (edges at every orientation, frequency rising toward the
//! centre). Values are in 0..=255 like an 8-bit image. And [`whole_shifts`], a fixed
//! pseudo-random chain of whole shifts.

use ndarray::Array2;

use crate::{Error, Result};

/// Checks a pattern size.
fn check(h: usize, w: usize) -> Result<()> {
    if h == 0 || w == 0 {
        return Err(Error::shape(&[h, w], "pattern is empty"));
    }
    Ok(())
}

/// A circular zone plate `127.5 (1 + cos(pi r^2 / (2 R)))`, `r` the distance of a pixel centre
/// from the array centre and `R` half the shorter side: the local frequency `r / (2R)` cycles
/// per pixel rises linearly from 0 at the centre to Nyquist (0.5) at distance `R`.
///
/// ```
/// let z = haarshift::patterns::zone_plate(64, 64).unwrap();
/// assert!(z.iter().all(|&v| (0.0..=255.0).contains(&v)));
/// ```
pub fn zone_plate(h: usize, w: usize) -> Result<Array2<f64>> {
    check(h, w)?;
    let (ci, cj) = ((h as f64 - 1.0) / 2.0, (w as f64 - 1.0) / 2.0);
    let radius = h.min(w) as f64 / 2.0;
    Ok(Array2::from_shape_fn((h, w), |(i, j)| {
        let r2 = (i as f64 - ci).powi(2) + (j as f64 - cj).powi(2);
        127.5 * (1.0 + (std::f64::consts::PI * r2 / (2.0 * radius)).cos())
    }))
}

/// A Siemens star with `spokes` black and `spokes` white sectors (0 and 255), each pixel the
/// average of 4x4 point samples so that edges are anti-aliased rather than jagged.
///
/// ```
/// let s = haarshift::patterns::siemens_star(65, 65, 16).unwrap();
/// // Opposite points on the star: with an even spoke count the star is symmetric under a
/// // half turn about the centre.
/// assert_eq!(s[[10, 20]], s[[54, 44]]);
/// ```
pub fn siemens_star(h: usize, w: usize, spokes: usize) -> Result<Array2<f64>> {
    check(h, w)?;
    if spokes == 0 {
        return Err(Error::parameter("spokes", "must be at least 1"));
    }
    const SUB: usize = 4;
    let (ci, cj) = ((h as f64 - 1.0) / 2.0, (w as f64 - 1.0) / 2.0);
    Ok(Array2::from_shape_fn((h, w), |(i, j)| {
        let mut white = 0usize;
        for si in 0..SUB {
            for sj in 0..SUB {
                let y = i as f64 - ci + (si as f64 + 0.5) / SUB as f64 - 0.5;
                let x = j as f64 - cj + (sj as f64 + 0.5) / SUB as f64 - 0.5;
                if (spokes as f64 * y.atan2(x)).sin() >= 0.0 {
                    white += 1;
                }
            }
        }
        255.0 * white as f64 / (SUB * SUB) as f64
    }))
}

/// Deterministic pseudo-random whole shifts `(dx, dy)` in `[-span, span)` times `unit`
/// (xorshift64, fixed seed), so that every run checks the same chain.
///
/// ```
/// let s = haarshift::patterns::whole_shifts(3, 10, 4);
/// assert!(s.iter().all(|&(dx, dy)| dx % 4 == 0 && dy.abs() <= 40));
/// ```
pub fn whole_shifts(count: usize, span: i64, unit: i64) -> Vec<(i64, i64)> {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % (2 * span as u64)) as i64 - span
    };
    (0..count).map(|_| (next() * unit, next() * unit)).collect()
}

#[cfg(test)]
#[path = "patterns_tests.rs"]
mod tests;
