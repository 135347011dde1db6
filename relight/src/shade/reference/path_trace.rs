//! The second, independent truth of interreflected light: a Monte Carlo path tracer
//! (Kajiya 1986's rendering equation, estimated by paths of fixed depth), with nothing
//! discretised but the lighting (`relight reference --path-trace N`).
//!
//! For each vertex `v` (position `p_v`, vertex normal `n_v`, albedo `a_v`), `N` paths start
//! at the vertex. Each takes one cosine-weighted direction per bounce (pdf `cos / pi`, Malley's
//! method: a uniform point of the unit disc lifted onto the hemisphere), so a Lambertian
//! surface's `rho / pi x cos / pdf` leaves just `rho` and a path's value is
//!
//! `a_v x rho_1 x ... x rho_k x L(w_k)`
//!
//! when its ray from the `k`-th surface point escapes in direction `w_k` (`k <= B`, the depth,
//! `--bounces`), and 0 when its `(B + 1)`-th ray hits something too, or any ray meets a
//! surface on the far side of its shading normal (the gather's one-sided rule,
//! [`bounce`](crate::precompute::bounce)). `L` is the lighting map's texel containing
//! `w_k` (the same `N x 2N` downsampled environment as the reference's; no interpolation). At a
//! hit the path goes on from the hit point itself: its position, normal (the hit triangle's
//! vertex normals interpolated barycentrically, normalised) and albedo (likewise), nothing
//! interpolated over the mesh's stored radiance and no direction discretised, so its
//! difference from the gather measures those two errors. A path's first ray starts at the vertex's
//! origin ([`RayOrigins`], off creases and contact, as the reference's do); every later one
//! off its hit point along the interpolated normal by
//! [`ray_offset`](crate::precompute::visibility::ray_offset).
//!
//! **Repeatable.** The two uniform numbers of path `k`'s bounce `d` at vertex `v` are a
//! counter-based hash of `(seed, v, k, d)` (SplitMix64, as the visibility jitter's), so the
//! result does not depend on threads or order, and one seed gives the same bits every run.
//!
//! **Its error.** With `N >= 2` paths the standard error of each vertex's mean is
//! `sqrt(s^2 / N)`, `s^2` the unbiased sample variance of its paths, per channel
//! ([`PathTrace::standard_error`]); it falls as `1 / sqrt(N)`.

use std::f64::consts::{PI, TAU};
use std::time::Instant;

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

use super::ReferenceReport;
use super::interreflection::check_bounces;
use crate::material::brdf::tangents;
use crate::precompute::bounce::facing_normal;
use crate::precompute::cast::{f32x3, jitter};
use crate::precompute::origin::RayOrigins;
use crate::precompute::raycast::Hit;
use crate::scene::mesh::dot;
use crate::{Error, Result};
use crate::{Mesh, SceneBvh};
use haarshift::progress::Task;
use haarshift::sphere::LatLongMap;
use haarshift::sphere::latlong::angles;

/// How to trace; see the [module docs](self).
///
/// ```
/// use haarshift_relight::shade::reference::path_trace::PathTraceOptions;
/// let o = PathTraceOptions::new(256);
/// assert_eq!((o.paths, o.bounces, o.seed, o.progress), (256, 0, 0, false));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceOptions {
    /// Paths per vertex, at least 2 (for the standard error).
    pub paths: usize,
    /// The depth `B`: surfaces a path may bounce off before it must escape, 0 to
    /// [`MAX_BOUNCES`](super::interreflection::MAX_BOUNCES).
    pub bounces: usize,
    /// The seed of every path's random numbers.
    pub seed: u64,
    /// Report progress to the installed [reporter](haarshift::progress).
    pub progress: bool,
}

impl PathTraceOptions {
    /// `paths` paths of depth 0 (direct light), seed 0, no progress.
    pub fn new(paths: usize) -> Self {
        PathTraceOptions {
            paths,
            bounces: 0,
            seed: 0,
            progress: false,
        }
    }
}

/// What [`path_trace`] estimated.
#[derive(Clone, Debug, PartialEq)]
pub struct PathTrace {
    /// The mean of each vertex's paths, `(V, 3)`.
    pub radiance: Array2<f64>,
    /// The standard error of each mean, `(V, 3)`.
    pub standard_error: Array2<f64>,
    /// Rays cast and seconds taken.
    pub report: ReferenceReport,
}

impl PathTrace {
    /// The root mean square of the standard errors over every vertex and channel.
    ///
    /// ```
    /// use haarshift_relight::shade::reference::path_trace::{PathTrace, PathTraceOptions};
    /// use haarshift_relight::ReferenceReport;
    /// use ndarray::Array2;
    /// let t = PathTrace { radiance: Array2::zeros((2, 3)),
    ///                     standard_error: Array2::from_elem((2, 3), 0.5),
    ///                     report: ReferenceReport { rays: 0, seconds: 0.0 } };
    /// assert_eq!(t.rms_standard_error(), 0.5);
    /// ```
    pub fn rms_standard_error(&self) -> f64 {
        let e = &self.standard_error;
        (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt()
    }
}

/// A surface point a path stands on: where its next ray starts and the normal it samples
/// around.
#[derive(Clone, Copy)]
struct Surface {
    origin: [f32; 3],
    normal: [f64; 3],
}

/// The lighting's texel containing the unit direction `d` (RGB; gray spread).
fn lookup(lighting: &LatLongMap<f64>, d: [f64; 3]) -> [f64; 3] {
    let (h, w) = (lighting.height(), lighting.width());
    let (theta, phi) = angles(d);
    let i = ((theta / PI * h as f64) as usize).min(h - 1);
    let j = ((phi / TAU * w as f64) as usize).min(w - 1);
    let map = lighting.as_array();
    let ch = lighting.channels();
    std::array::from_fn(|c| map[[i, j, c.min(ch - 1)]])
}

/// A cosine-weighted direction about the unit `n` from two uniform numbers (Malley's method).
fn cosine_direction(n: [f64; 3], (a, b): (f64, f64)) -> [f64; 3] {
    let (t, s) = tangents(n);
    let r = a.sqrt();
    let (sin, cos) = (TAU * b).sin_cos();
    let (x, y, z) = (r * cos, r * sin, (1.0 - a).max(0.0).sqrt());
    std::array::from_fn(|k| x * t[k] + y * s[k] + z * n[k])
}

/// The surface a hit stands for, with its albedo; `None` on the far side of its shading
/// normal ([`facing_normal`]).
fn surface_at(
    mesh: &Mesh,
    albedo: ArrayView2<'_, f32>,
    hit: &Hit,
    d: [f64; 3],
    eps: f64,
) -> Option<(Surface, [f64; 3])> {
    let tri = mesh.triangles()[hit.triangle];
    let normal = facing_normal(mesh, hit, d)?;
    let p = mesh.positions();
    let w = hit.weights();
    let mix = |f: &dyn Fn(usize, usize) -> f64| -> [f64; 3] {
        std::array::from_fn(|c| (0..3).map(|k| w[k] * f(k, c)).sum())
    };
    let position = mix(&|k, c| p[[tri[k] as usize, c]]);
    let len = dot(normal, normal).sqrt();
    if len.is_nan() || len <= 0.0 {
        return None; // opposite normals cancelling: no hemisphere to sample
    }
    let normal = normal.map(|x| x / len);
    let rho = mix(&|k, c| f64::from(albedo[[tri[k] as usize, c]]));
    let origin = f32x3(std::array::from_fn(|k| position[k] + eps * normal[k]));
    Some((Surface { origin, normal }, rho))
}

/// Each vertex's outgoing radiance under `lighting` with up to `options.bounces` bounces,
/// estimated by `options.paths` paths (see the [module docs](self)); `albedo` `(V, 3)`,
/// `lighting` a lat-long map, gray or RGB, already rotated.
///
/// ```
/// use haarshift_relight::shade::reference::path_trace::{PathTraceOptions, path_trace};
/// use haarshift_relight::{Mesh, SceneBvh};
/// use haarshift::sphere::LatLongMap;
/// use ndarray::{Array2, array};
/// // One upward triangle under a sky of radiance 1: every path escapes with value albedo.
/// let m = Mesh::new(array![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]],
///                   vec![[0, 1, 2]], None).unwrap();
/// let sky = LatLongMap::<f64>::from_fn(8, 1, |_, o| o[0] = 1.0).unwrap();
/// let albedo = Array2::from_elem((3, 3), 0.5f32);
/// let t = path_trace(&m, &SceneBvh::new(&m), albedo.view(), &sky, &PathTraceOptions::new(16))
///     .unwrap();
/// assert!(t.radiance.iter().all(|&r| r == 0.5));
/// assert_eq!((t.rms_standard_error(), t.report.rays), (0.0, 3 * 16));
/// ```
pub fn path_trace(
    mesh: &Mesh,
    bvh: &SceneBvh,
    albedo: ArrayView2<'_, f32>,
    lighting: &LatLongMap<f64>,
    options: &PathTraceOptions,
) -> Result<PathTrace> {
    check_bounces(options.bounces)?;
    let vertices = mesh.vertex_count();
    if albedo.dim() != (vertices, 3) {
        return Err(Error::shape(
            albedo.shape(),
            format!("the albedo must be ({vertices}, 3), one RGB row per vertex"),
        ));
    }
    let ch = lighting.channels();
    if !(ch == 1 || ch == 3) {
        return Err(Error::parameter(
            "lighting",
            format!("{ch} channels: the path tracer takes gray or RGB lighting"),
        ));
    }
    let paths = options.paths;
    if !(2..=1 << 24).contains(&paths) {
        return Err(Error::parameter(
            "paths",
            format!(
                "{paths}: must be 2 to {} (a standard error needs two)",
                1 << 24
            ),
        ));
    }
    let start = Instant::now();
    let origins = RayOrigins::new(mesh);
    let eps = origins.eps();
    let bar = Task::begin(options.progress, "path tracing (vertices)", vertices);
    let per_vertex: Vec<([f64; 3], [f64; 3], u64)> = (0..vertices)
        .into_par_iter()
        .map(|v| {
            let (origin, normal) = origins.origin_and_normal(v);
            let start = Surface {
                origin: f32x3(origin),
                normal,
            };
            let a = [0, 1, 2].map(|c| f64::from(albedo[[v, c]]));
            let (mut sum, mut squares, mut rays) = ([0.0f64; 3], [0.0f64; 3], 0u64);
            let mut hit = [None];
            for k in 0..paths {
                let mut surface = start;
                let mut weight = a;
                let mut value = [0.0; 3];
                for depth in 0..=options.bounces {
                    let d = cosine_direction(surface.normal, jitter(options.seed, v, k, depth));
                    bvh.closest_hits_from(surface.origin, &[f32x3(d)], f32::INFINITY, &mut hit);
                    rays += 1;
                    let Some(h) = hit[0] else {
                        let l = lookup(lighting, d);
                        value = std::array::from_fn(|c| weight[c] * l[c]);
                        break;
                    };
                    if depth == options.bounces {
                        break;
                    }
                    let Some((next, rho)) = surface_at(mesh, albedo, &h, d, eps) else {
                        break;
                    };
                    (0..3).for_each(|c| weight[c] *= rho[c]);
                    surface = next;
                }
                for c in 0..3 {
                    sum[c] += value[c];
                    squares[c] += value[c] * value[c];
                }
            }
            let n = paths as f64;
            let mean = sum.map(|s| s / n);
            let se = std::array::from_fn(|c| {
                let variance = (squares[c] - n * mean[c] * mean[c]) / (n - 1.0);
                (variance.max(0.0) / n).sqrt()
            });
            bar.advance(1);
            (mean, se, rays)
        })
        .collect();
    let mut radiance = Array2::<f64>::zeros((vertices, 3));
    let mut error = Array2::<f64>::zeros((vertices, 3));
    let mut rays = 0;
    for (v, (mean, se, r)) in per_vertex.into_iter().enumerate() {
        for c in 0..3 {
            (radiance[[v, c]], error[[v, c]]) = (mean[c], se[c]);
        }
        rays += r;
    }
    Ok(PathTrace {
        radiance,
        standard_error: error,
        report: ReferenceReport {
            rays,
            seconds: start.elapsed().as_secs_f64(),
        },
    })
}

#[cfg(test)]
#[path = "path_trace_tests.rs"]
mod tests;
