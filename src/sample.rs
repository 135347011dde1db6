//! The floating-point types haarshift computes in.

use std::fmt::{Debug, Display};
use std::iter::Sum;
use std::ops::{AddAssign, DivAssign, MulAssign, SubAssign};

use ndarray::{ArrayBase, Data, Dimension, ScalarOperand};

use crate::{Error, Result};

/// A floating-point sample type: `f32` or `f64`.
///
/// Everything numeric in haarshift is generic over `Sample`; f64 is the reference precision
/// (oracle tests hold to about 1e-12), f32 the fast one.
///
/// ```
/// use haarshift::Sample;
/// fn mean<T: Sample>(v: &[T]) -> f64 {
///     v.iter().map(|x| x.as_f64()).sum::<f64>() / v.len() as f64
/// }
/// assert_eq!(mean(&[1.0f32, 2.0, 3.0]), 2.0);
/// ```
pub trait Sample:
    num_traits::Float
    + ScalarOperand
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + Sum
    + Default
    + Debug
    + Display
    + Send
    + Sync
    + lanes::Lanes
    + 'static
{
    /// `"f32"` or `"f64"`.
    const NAME: &'static str;

    /// Converts from f64, rounding to nearest for f32.
    fn from_f64(x: f64) -> Self;

    /// Converts to f64 exactly.
    fn as_f64(self) -> f64;
}

/// Four samples in one SIMD register where the platform has one, sealed inside the crate.
#[doc(hidden)]
pub mod lanes {
    use std::ops::{Add, AddAssign, Mul};

    /// Four lanes of a sample type: [`Quad4f32`] (one SSE register on x86-64) for f32,
    /// [`Quad4f64`] for f64. What the shading's sparse dot products gather an RGB row (and a
    /// zero) as, so that one coefficient is one load and one multiply-add of four lanes; arrays
    /// of four would do the same arithmetic, but the compiler drops the unused fourth lane and
    /// splits the load.
    pub trait Lanes: Copy {
        /// The four lanes.
        type Quad: Copy
            + Default
            + Add<Output = Self::Quad>
            + AddAssign
            + Mul<Self, Output = Self::Quad>
            + Send
            + Sync;

        /// `[r, g, b, 0]` as lanes.
        fn rgb(rgb: [Self; 3]) -> Self::Quad;

        /// The first three lanes.
        fn first_three(quad: Self::Quad) -> [Self; 3];
    }

    /// Four f32 lanes, lane-wise IEEE arithmetic: an SSE register on x86-64 (every x86-64
    /// has SSE2), a 16-byte aligned array elsewhere.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub struct Quad4f32(Inner32);

    #[cfg(target_arch = "x86_64")]
    type Inner32 = std::arch::x86_64::__m128;
    #[cfg(not(target_arch = "x86_64"))]
    type Inner32 = Aligned4f32;

    /// Four f32 on a 16-byte boundary, where no SSE register holds them.
    #[cfg(not(target_arch = "x86_64"))]
    #[derive(Clone, Copy, Debug)]
    #[repr(C, align(16))]
    pub struct Aligned4f32([f32; 4]);

    #[cfg(target_arch = "x86_64")]
    mod sse {
        use std::arch::x86_64::{_mm_add_ps, _mm_mul_ps, _mm_set1_ps, _mm_setr_ps, _mm_storeu_ps};

        use super::Quad4f32;

        // SAFETY (every function): SSE is part of the x86-64 baseline, so these intrinsics are
        // always available; they read and write only their arguments and `out`.
        #[inline(always)]
        pub(super) fn new(x: [f32; 4]) -> Quad4f32 {
            Quad4f32(unsafe { _mm_setr_ps(x[0], x[1], x[2], x[3]) })
        }
        #[inline(always)]
        pub(super) fn add(a: Quad4f32, b: Quad4f32) -> Quad4f32 {
            Quad4f32(unsafe { _mm_add_ps(a.0, b.0) })
        }
        #[inline(always)]
        pub(super) fn scale(a: Quad4f32, s: f32) -> Quad4f32 {
            Quad4f32(unsafe { _mm_mul_ps(a.0, _mm_set1_ps(s)) })
        }
        #[inline(always)]
        pub(super) fn array(a: Quad4f32) -> [f32; 4] {
            let mut out = [0.0f32; 4];
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), a.0) };
            out
        }
    }

    #[cfg(not(target_arch = "x86_64"))]
    mod sse {
        use super::{Aligned4f32, Quad4f32};

        #[inline(always)]
        pub(super) fn new(x: [f32; 4]) -> Quad4f32 {
            Quad4f32(Aligned4f32(x))
        }
        #[inline(always)]
        pub(super) fn add(a: Quad4f32, b: Quad4f32) -> Quad4f32 {
            new(std::array::from_fn(|k| a.0.0[k] + b.0.0[k]))
        }
        #[inline(always)]
        pub(super) fn scale(a: Quad4f32, s: f32) -> Quad4f32 {
            new(a.0.0.map(|x| x * s))
        }
        #[inline(always)]
        pub(super) fn array(a: Quad4f32) -> [f32; 4] {
            a.0.0
        }
    }

    impl Default for Quad4f32 {
        #[inline(always)]
        fn default() -> Self {
            sse::new([0.0; 4])
        }
    }

    impl Add for Quad4f32 {
        type Output = Self;
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            sse::add(self, other)
        }
    }

    impl AddAssign for Quad4f32 {
        #[inline(always)]
        fn add_assign(&mut self, other: Self) {
            *self = sse::add(*self, other);
        }
    }

    impl Mul<f32> for Quad4f32 {
        type Output = Self;
        #[inline(always)]
        fn mul(self, s: f32) -> Self {
            sse::scale(self, s)
        }
    }

    // SAFETY: four f32 in a register or an array; no pointer, nothing shared.
    unsafe impl Send for Quad4f32 {}
    unsafe impl Sync for Quad4f32 {}

    /// Four f64 lanes, lane-wise IEEE arithmetic (as four scalars: a 256-bit register is not
    /// in the x86-64 baseline).
    #[derive(Clone, Copy, Debug, Default)]
    #[repr(C, align(32))]
    pub struct Quad4f64([f64; 4]);

    impl Add for Quad4f64 {
        type Output = Self;
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            let [a, b, c, d] = self.0;
            Quad4f64([a + o.0[0], b + o.0[1], c + o.0[2], d + o.0[3]])
        }
    }

    impl AddAssign for Quad4f64 {
        #[inline(always)]
        fn add_assign(&mut self, other: Self) {
            *self = *self + other;
        }
    }

    impl Mul<f64> for Quad4f64 {
        type Output = Self;
        #[inline(always)]
        fn mul(self, s: f64) -> Self {
            let [a, b, c, d] = self.0;
            Quad4f64([a * s, b * s, c * s, d * s])
        }
    }

    impl Lanes for f32 {
        type Quad = Quad4f32;
        #[inline(always)]
        fn rgb([r, g, b]: [f32; 3]) -> Quad4f32 {
            sse::new([r, g, b, 0.0])
        }
        #[inline(always)]
        fn first_three(quad: Quad4f32) -> [f32; 3] {
            let [r, g, b, _] = sse::array(quad);
            [r, g, b]
        }
    }

    impl Lanes for f64 {
        type Quad = Quad4f64;
        #[inline(always)]
        fn rgb([r, g, b]: [f64; 3]) -> Quad4f64 {
            Quad4f64([r, g, b, 0.0])
        }
        #[inline(always)]
        fn first_three(quad: Quad4f64) -> [f64; 3] {
            let [r, g, b, _] = quad.0;
            [r, g, b]
        }
    }

    #[cfg(test)]
    mod tests {
        use super::Lanes;

        /// Lane-wise IEEE arithmetic, bit for bit as scalars give it.
        #[test]
        fn lanes_add_and_scale_as_scalars_do() {
            let (a, b, s) = (
                [0.1f32, -3.5, 7.25e-8],
                [1e30f32, 2.0, -7.25e-8],
                1.0f32 / 3.0,
            );
            let mut q = f32::rgb(a) * s;
            q += f32::rgb(b);
            let expect: [f32; 3] = std::array::from_fn(|k| a[k] * s + b[k]);
            assert_eq!(
                f32::first_three(q).map(f32::to_bits),
                expect.map(f32::to_bits)
            );
            let (a, b, s) = (
                [0.1f64, -3.5, 7.25e-8],
                [1e300f64, 2.0, -7.25e-8],
                1.0f64 / 3.0,
            );
            let q = f64::rgb(a) * s + f64::rgb(b);
            let expect: [f64; 3] = std::array::from_fn(|k| a[k] * s + b[k]);
            assert_eq!(
                f64::first_three(q).map(f64::to_bits),
                expect.map(f64::to_bits)
            );
        }
    }
}

impl Sample for f32 {
    const NAME: &'static str = "f32";
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self as f64
    }
}

impl Sample for f64 {
    const NAME: &'static str = "f64";
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self
    }
}

/// `x` rounded to the nearest integer (ties away from zero) and clamped to `0..=max`, for an
/// integer code range (`max` below 2^32): exactly `x.round().clamp(0, max)`, without the libm
/// call `round` is on baseline x86-64, which dominated writing 8- and 16-bit images. This is
/// how a float result becomes an 8- or 16-bit sample everywhere in haarshift.
///
/// ```
/// use haarshift::round_to_code;
/// assert_eq!(round_to_code(2.5f32, 255.0), 3.0);
/// assert_eq!(round_to_code(-0.7f64, 255.0), 0.0);
/// assert_eq!(round_to_code(300.2f64, 255.0), 255.0);
/// ```
#[inline]
pub fn round_to_code<T: Sample>(x: T, max: f64) -> T {
    let x = x.as_f64().clamp(0.0, max);
    // Truncation is exact here and so is the fraction `x - whole` (both below 2^32).
    let whole = x as u32 as f64;
    T::from_f64(if x - whole >= 0.5 { whole + 1.0 } else { whole })
}

/// Whether every value is finite: in chunks without an early exit inside, so that each
/// vectorises.
#[inline]
pub(crate) fn all_finite<T: Sample>(values: &[T]) -> bool {
    values
        .chunks(256)
        .all(|c| c.iter().fold(true, |ok, v| ok & v.is_finite()))
}

/// Returns an error naming the first NaN or infinity in `array`, if any.
///
/// ```
/// use ndarray::array;
/// assert!(haarshift::ensure_finite(&array![1.0, 2.0]).is_ok());
/// let err = haarshift::ensure_finite(&array![[1.0, f64::NAN]]).unwrap_err();
/// assert_eq!(err.to_string(), "non-finite value NaN at index [0, 1]");
/// ```
pub fn ensure_finite<T: Sample, S: Data<Elem = T>, D: Dimension>(
    array: &ArrayBase<S, D>,
) -> Result<()> {
    // The common case, all finite, in one fast pass; the index only when something is not.
    let finite = match array.as_slice_memory_order() {
        Some(values) => all_finite(values),
        None => array.iter().all(|v| v.is_finite()),
    };
    if finite {
        return Ok(());
    }
    match array.indexed_iter().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((index, value)) => Err(Error::NonFinite {
            value: value.as_f64(),
            index: index.into_pattern_vec(),
        }),
    }
}

/// Turns an ndarray index pattern into a plain vector, for error messages.
trait IntoPatternVec {
    fn into_pattern_vec(self) -> Vec<usize>;
}

impl<P: ndarray::IntoDimension> IntoPatternVec for P {
    fn into_pattern_vec(self) -> Vec<usize> {
        self.into_dimension().slice().to_vec()
    }
}

#[cfg(test)]
#[path = "sample_tests.rs"]
mod tests;
