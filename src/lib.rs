//! # haarshift
//!
//! Signal processing directly in the Haar wavelet domain.
//!
//! * [`transform`]: 1D, 2D non-separable ("standard pyramid") and separable Haar transforms, in
//!   the `average` or `orthonormal` normalisation, f32 or f64, any size (padded to powers of two
//!   with a chosen [`BoundaryMode`] and cropped back on the way out).
//! * [`shift`]: whole and fractional shifts computed directly on the coefficients, 1D, 2D
//!   non-separable and N-D separable, densely in O(n) or one coefficient at a time in O(1).
//! * [`sphere`]: rotation of lat-long environment maps in pixels and directly in the 2D Haar
//!   domain (the chain rule on detail coefficients), with a ground-truth reference and
//!   bilinear/bicubic resampling to compare against.
//! * [`product`]: integrals and products of several functions on sparse Haar quadtrees over
//!   sets of square faces (the n-function product integral, the product, nonlinear
//!   approximation, the weighting contract).
//! * [`relight`]: meshes and scenes lit by environment maps: ray casting, per-vertex visibility
//!   precomputed into sparse Haar transport, the scene cache, the lighting, the rasteriser and
//!   animations.
//! * [`progress`]: where long computations report their progress (the library draws nothing).
//! * [`experiments`], [`metrics`], [`patterns`]: error-accumulation experiments, the error
//!   measures they report, and the synthetic test patterns they use.
//! * [`io`]: PNG, JPEG, TIFF, OpenEXR, Radiance HDR and `.npy` in and out of [`PlanarImage`]
//!   (planar float channels in their stored units, 0..255 for 8-bit), written atomically and
//!   never over an existing file unless asked; coefficient files (`.npy` plus a JSON sidecar)
//!   that restore an image exactly.
//!
//! Conventions used throughout: arrays are row-major `(row, column)`; row 0 is the top of an
//! image; a 2x2 block `[[p, q], [r, s]]` has average `A = (p+q+r+s)/4` and details
//! `a = (p-q+r-s)/4` (horizontal), `b = (p+q-r-s)/4` (vertical), `c = (p-q-r+s)/4` (diagonal)
//! in the `average` normalisation.
#![warn(missing_docs)]

#[cfg(test)]
#[macro_use]
mod test_support;

mod boundary;
mod error;
pub mod faces;
pub mod io;
pub mod kernels;
pub mod memory;
pub mod metrics;
mod named;
pub mod patterns;
mod planar_image;
pub mod product;
pub mod progress;
pub mod rotate;
mod sample;
pub mod shift;
pub mod sphere;
pub mod transform;

pub use boundary::BoundaryMode;
pub use error::{Error, Result};
pub use planar_image::{Channels, PlanarImage, SampleDepth};
pub use sample::{Sample, ensure_finite, round_to_code};

/// The README's Rust examples, compiled and run as doctests so that they stay true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
