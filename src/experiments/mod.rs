//! Experiments that measure what each method costs and how much error it accumulates.
//!
//! * [`plot`]: the PNG plots the experiment commands write next to their CSV and JSON.
pub mod plot;
