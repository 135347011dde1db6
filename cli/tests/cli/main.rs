//! The `haarshift` binary's integration tests: one test binary (linked once) with one module
//! per command family; `common` runs the binary and checks its outputs and failures.

mod common;

mod compute_precision;
mod deploy;
mod experiment;
mod experiment_relight;
mod flags;
mod hdr;
mod hostile;
mod readme;
mod relight;
mod relight_error;
mod relight_scene;
mod relight_shard;
mod report_overwrite;
mod rotate_shift;
mod sphere;
mod sphere_integrate;
mod sphere_product;
mod transform;
