//! # haarshift
//!
//! Signal processing directly in the Haar wavelet domain.
//!
//! * [`transform`]: 1D, 2D non-separable ("standard pyramid") and separable Haar transforms, in
//!   the `average` or `orthonormal` normalisation, f32 or f64, any size (padded to powers of two
//!   with a chosen [`BoundaryMode`] and cropped back on the way out).
//!
//! * [`PlanarImage`]: images as planar float channels in their stored units (0..255 for 8-bit).
//!
//! Conventions used throughout: arrays are row-major `(row, column)`; row 0 is the top of an
//! image; a 2x2 block `[[p, q], [r, s]]` has average `A = (p+q+r+s)/4` and details
//! `a = (p-q+r-s)/4` (horizontal), `b = (p+q-r-s)/4` (vertical), `c = (p-q-r+s)/4` (diagonal)
//! in the `average` normalisation.
#![warn(missing_docs)]

mod boundary;
mod error;
pub mod kernels;
mod named;
mod planar_image;
pub mod rotate;
mod sample;
pub mod transform;

pub use boundary::BoundaryMode;
pub use error::{Error, Result};
pub use planar_image::{Channels, PlanarImage, SampleDepth};
pub use sample::{Sample, ensure_finite};
