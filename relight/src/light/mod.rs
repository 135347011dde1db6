//! The lighting: the environment map loaded ([`environment`]), downsampled by solid-angle-weighted
//! means ([`downsample`]) and rotated, and its kept Haar coefficients ([`lighting`]).

pub mod downsample;
pub mod environment;
pub mod lighting;
