//! The lighting: the environment map loaded, downsampled by solid-angle-weighted means and
//! rotated ([`environment`]), and its kept Haar coefficients ([`lighting`]).

pub mod environment;
pub mod lighting;
