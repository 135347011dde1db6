//! Experiments that measure what each method costs and how much error it accumulates.
//!
//! * [`table`]: Markdown result tables.
//! * [`pareto`]: the cost/error Pareto frontier.
//! * [`rotation_cycle`]: Alnasser 2008's Table 2.2 protocol: rotate back to the start, measure.
//! * [`kernel_cycle`]: the library's kernels in the rotation cycle; the default image set.
//! * [`shift_chain`]: one shift against a chain of small ones (Alnasser 2008's Table 3.1).
//! * [`stability`]: the numerical extremes, each check with its figure, tolerance and verdict.
//! * [`tradeoff`]: every kernel and parameter through the rotation cycle; Pareto frontiers.
//! * [`relight`]: every relighting method against the ray-cast truth over the sources' axes;
//!   picture grids.
//! * [`moving_objects`]: occlusion fields and just-in-time radiance transfer against the ray-cast truth.
//! * [`output`]: CSV, JSON and PNG files side by side, written atomically.
//! * [`journal`]: measurements written as they are made, so that a killed run resumes.
//! * [`plot`]: the PNG plots the experiment commands write next to their CSV and JSON.
//! * [`gallery`]: the committed diffuse renders: Haar, SH and the reference under several maps.
//!
//! Errors are the relighting's ([`haarshift_relight::Error`]), which wraps the core's.
#![warn(missing_docs)]

#[cfg(test)]
#[macro_use]
mod test_support;

pub use haarshift_relight::{Error, Result};

pub mod gallery;
pub mod journal;
pub mod kernel_cycle;
pub mod moving_objects;
pub mod output;
pub mod pareto;
pub mod plot;
pub mod relight;
pub mod rotation_cycle;
pub mod shift_chain;
pub mod stability;
pub mod table;
pub mod tradeoff;
