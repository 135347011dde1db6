//! The `haarshift` binary's integration tests: one test binary (linked once) with one module
//! per command family; `common` runs the binary and checks its outputs and failures. The
//! hostile-input tests, which measure each child's peak memory, are a binary of their own
//! (`tests/hostile`): a child's `ru_maxrss` starts at its parent's resident size when it
//! forks, so they need a parent that stays small.

mod common;

mod bake;
mod bounces;
mod cache_hashes;
mod compute_precision;
mod deploy;
mod examples;
mod experiment;
mod experiment_relight;
mod flags;
mod ground_cells;
mod hdr;
mod ray_tracer;
mod readme;
mod reference_bounces;
mod refine;
mod relight;
mod relight_assets;
mod relight_error;
mod relight_scene;
mod relight_shard;
mod report_overwrite;
mod rotate_shift;
mod sphere;
mod sphere_integrate;
mod sphere_product;
mod transform;
mod viewer;
mod viewer_dynamic;
