//! The axes of the relighting experiment, one file each; every axis is a method of
//! [`SceneUnderTest`](super::scene::SceneUnderTest) that relights one condition many ways and
//! returns its records.

mod coefficients;
mod depth;
mod harmonics;
mod resolution;
mod rotation;
