//! # haarshift
//!
//! Signal processing directly in the Haar wavelet domain: images shifted and rotated on their
//! Haar coefficients, lat-long maps rotated through theirs, and products of functions on the
//! sphere integrated on sparse Haar trees, each method measured against an oracle. The
//! all-frequency relighting built on it is the crate `haarshift-relight`; the experiments that
//! measure every method, `haarshift-experiments`.
//!
//! ## Start here
//!
//! **Rotate an image** by three shears, each a shift of the rows' Haar coefficients
//! ([`rotate`], [`kernels`]; the program `examples/rotate_image.rs`):
//!
//! ```
//! use haarshift::kernels::ShiftMethod;
//! use haarshift::rotate::{Canvas, RotateOptions, rotate_image};
//! let image = haarshift::io::read_image::<f32>(concat!(env!("CARGO_MANIFEST_DIR"), "/testdata/coins.png"))?;
//! let options = RotateOptions { canvas: Canvas::Expand, ..Default::default() };
//! let turned = rotate_image(&image, 30.0, ShiftMethod::Haar.kernel::<f32>().as_ref(), &options)?;
//! assert!(turned.width() > image.width());
//! # Ok::<(), haarshift::Error>(())
//! ```
//!
//! **Shift an image** by a quarter pixel without leaving the transform ([`shift`],
//! [`transform`]):
//!
//! ```
//! use haarshift::shift::shift_image;
//! use haarshift::transform::TransformSpec;
//! let image = ndarray::array![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]];
//! let coefficients = TransformSpec::default().forward(image.view())?;
//! // 0.25 columns right, on the 1/4-pixel grid (precision 2).
//! let moved = shift_image(&coefficients, 0.25, 0.0, 2)?.inverse()?;
//! assert_eq!(moved.sum(), image.sum()); // periodic: nothing leaves the image
//! # Ok::<(), haarshift::Error>(())
//! ```
//!
//! **Rotate a lat-long map** on its Haar coefficients by the chain rule ([`sphere`]; the
//! program `examples/rotate_envmap.rs`):
//!
//! ```
//! use haarshift::sphere::{LatLongMap, SphereOptions, SphereRotation, rotate_map};
//! let sky = LatLongMap::<f64>::from_fn(32, 3, |d, rgb| rgb.fill(1.0 + d[1]))?; // bright above
//! let turned = rotate_map(&sky, &SphereRotation::from_degrees(0.0, 90.0, 0.0)?, &SphereOptions::default())?;
//! assert_eq!(turned.map.height(), 32);
//! # Ok::<(), haarshift::Error>(())
//! ```
//!
//! **Precompute a mesh's transport** and **shade it under a new lighting**: the front door of
//! `haarshift-relight` (its crate docs, and `relight/examples/relight_mesh.rs`).
//!
//! ## Modules
//!
//! | module | what |
//! |---|---|
//! | [`transform`] | 1D, 2D pyramid and separable Haar transforms, `average` or `orthonormal`, f32 or f64, any size (padded with a [`BoundaryMode`]) |
//! | [`shift`] | whole and fractional shifts on the coefficients: 1D, 2D, N-D separable, dense in O(n) or one coefficient in O(1) |
//! | [`kernels`] | the nine 1D shift kernels of the rotations (Haar, nearest, linear, Keys, B-spline, Lanczos, FFT, ...), behind [`kernels::ShearKernel`] |
//! | [`rotate`] | image rotation by three shears with any kernel |
//! | [`sphere`] | lat-long maps ([`sphere::LatLongMap`]), rotated in pixels or on Haar coefficients; spherical harmonics; the rotation error measures ([`sphere::map_error`]) |
//! | [`faces`] | functions on the sphere as square faces (lat-long and cube map), their conversion, integrals and products |
//! | [`product`] | n-function product integrals and products on sparse Haar quadtrees, the triple product, nonlinear approximation |
//! | [`io`] | PNG, JPEG, TIFF, OpenEXR, Radiance HDR and `.npy` in and out of [`PlanarImage`], atomic writes, coefficient files |
//! | [`metrics`] | error measures (RMS, PSNR, masked statistics) |
//! | [`patterns`] | synthetic test patterns (zone plate, Siemens star), fixed chains of shifts |
//! | [`progress`] | where long computations report progress (the library draws nothing) |
//! | [`memory`] | the process's peak resident memory, for reports |
//!
//! Errors: one type, [`Error`]. Items marked `#[doc(hidden)]` are public only because the
//! sibling crates (`haarshift-relight`, `haarshift-experiments`) call them; they are not part
//! of this crate's API and may change.
//!
//! ## Conventions
//!
//! Arrays are row-major `(row, column)`; row 0 is the top of an image; a 2x2 block
//! `[[p, q], [r, s]]` has average `A = (p+q+r+s)/4` and details `a = (p-q+r-s)/4` (horizontal),
//! `b = (p+q-r-s)/4` (vertical), `c = (p-q-r+s)/4` (diagonal) in the `average` normalisation.
//! Directions on the sphere: world Y up, right-handed, [`sphere::latlong`]'s angles; a rotation
//! `R` acts as `g(p) = f(R p)`.
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
