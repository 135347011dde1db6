//! The speed/accuracy trade-off: every kernel at every parameter (Haar precision `h`,
//! supersampling `s`, kernel size) through the rotation cycle, summarised per configuration
//! over the images, with the Pareto frontiers of error against time and against memory.
//!
//! * [`TradeoffGrid`] expands methods into their configurations: compact Haar at
//!   `h = 0..=max_precision`, retained Haar at `h = 1..=max_retained_precision`, and every
//!   configuration except retained Haar at `s = 0..=max_supersample`. Retained Haar runs at
//!   `s = 0` only, because it already works on a `2^h`-finer grid: at `s > 0` it would be
//!   retained Haar at `h + s`. Kernel sizes are the kernels themselves (`bspline3`/`bspline5`,
//!   `lanczos3`/`lanczos4`, `keys`).
//! * [`summarize`] aggregates the per-image [`CycleRecord`]s into one [`TradeoffPoint`] per
//!   configuration (mean RMS, total and median seconds, largest peak memory) and flags the
//!   points on each frontier ([`frontier`]).
//!
//! ```
//! use haarshift_experiments::kernel_cycle::{KernelCycle, run_rotation_cycle, synthetic_images};
//! use haarshift_experiments::rotation_cycle::NoMeter;
//! use haarshift_experiments::tradeoff::{TradeoffGrid, summarize};
//! use haarshift::kernels::{KernelOptions, ShiftMethod};
//! let grid = TradeoffGrid { max_precision: 1, max_retained_precision: 1, max_supersample: 0 };
//! let haar = KernelCycle::every_kernel(KernelOptions::default(), 0)
//!     .into_iter()
//!     .filter(|m| m.method == ShiftMethod::Haar)
//!     .collect::<Vec<_>>();
//! let configs = grid.expand(&haar); // compact h = 0, 1 and retained h = 1
//! assert_eq!(configs.len(), 3);
//! let image = synthetic_images().unwrap()[0].centre_crop(24).unwrap();
//! let runs = run_rotation_cycle(&[image], &configs, 6, &NoMeter, |_| {}).unwrap();
//! let points = summarize(&runs);
//! assert_eq!(points.len(), 3);
//! assert!(points.iter().any(|p| p.time_frontier));
//! ```

use serde::{Deserialize, Serialize};

use super::kernel_cycle::KernelCycle;
use super::pareto::frontier;
use super::rotation_cycle::{CycleRecord, MethodSpec};
use haarshift::kernels::{HaarShift, KernelOptions, ShiftMethod};
use haarshift::rotate::MAX_SUPERSAMPLE;
use haarshift::{Error, Result};

/// The parameter ranges the trade-off sweeps.
///
/// ```
/// use haarshift_experiments::tradeoff::TradeoffGrid;
/// let grid = TradeoffGrid::default();
/// assert_eq!((grid.max_precision, grid.max_retained_precision, grid.max_supersample), (3, 2, 2));
/// // 7 pixel kernels + fft, and compact Haar h = 0..=3, at s = 0, 1, 2; retained h = 1, 2.
/// assert_eq!(grid.every_configuration().len(), (8 + 4) * 3 + 2);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TradeoffGrid {
    /// Compact Haar runs at `h = 0..=max_precision`.
    pub max_precision: u32,
    /// Retained Haar runs at `h = 1..=max_retained_precision` (none when 0).
    pub max_retained_precision: u32,
    /// Every configuration but retained Haar runs at `s = 0..=max_supersample`.
    pub max_supersample: u32,
}

impl Default for TradeoffGrid {
    /// Compact `h <= 3`, retained `h <= 2`, `s <= 2` (so that retained Haar at `h = 2` meets
    /// every kernel on the same 4x finer grid): a few minutes on 128x128 crops.
    fn default() -> Self {
        TradeoffGrid {
            max_precision: 3,
            max_retained_precision: 2,
            max_supersample: 2,
        }
    }
}

impl TradeoffGrid {
    /// Every configuration of every method in `methods` (their precision and supersampling
    /// are replaced by the grid's; the Haar retain flag and other options are kept), each
    /// method's sweep in turn, without repeats.
    ///
    /// ```
    /// use haarshift_experiments::kernel_cycle::KernelCycle;
    /// use haarshift_experiments::tradeoff::TradeoffGrid;
    /// use haarshift::kernels::{KernelOptions, ShiftMethod};
    /// let grid = TradeoffGrid { max_precision: 3, max_retained_precision: 2, max_supersample: 1 };
    /// let fft = KernelCycle::new(ShiftMethod::Fft, KernelOptions::default(), 0);
    /// let sweep = grid.expand(&[fft, fft]);
    /// assert_eq!(sweep.iter().map(|m| m.supersample).collect::<Vec<_>>(), vec![0, 1]);
    /// ```
    pub fn expand(&self, methods: &[KernelCycle]) -> Vec<KernelCycle> {
        let mut configs: Vec<KernelCycle> = Vec::new();
        for base in methods {
            let retained = base.method == ShiftMethod::Haar && base.options.retain;
            let precisions = match (base.method, retained) {
                (ShiftMethod::Haar, true) => 1..=self.max_retained_precision,
                (ShiftMethod::Haar, false) => 0..=self.max_precision,
                _ => base.options.precision..=base.options.precision,
            };
            let supersamples = if retained {
                0..=0
            } else {
                0..=self.max_supersample
            };
            for precision in precisions {
                for supersample in supersamples.clone() {
                    let options = KernelOptions {
                        precision,
                        ..base.options
                    };
                    let config = KernelCycle::new(base.method, options, supersample);
                    if !configs.contains(&config) {
                        configs.push(config);
                    }
                }
            }
        }
        configs
    }

    /// Refuses ranges a kernel or the rotation would refuse, before any run starts rather
    /// than midway through the sweep.
    ///
    /// ```
    /// use haarshift_experiments::tradeoff::TradeoffGrid;
    /// assert!(TradeoffGrid::default().validate().is_ok());
    /// let grid = TradeoffGrid { max_supersample: 99, ..Default::default() };
    /// let err = grid.validate();
    /// assert!(matches!(err, Err(haarshift::Error::InvalidParameter { name: "supersample", .. })));
    /// ```
    pub fn validate(&self) -> Result<()> {
        if self.max_supersample > MAX_SUPERSAMPLE {
            return Err(Error::parameter(
                "supersample",
                format!(
                    "{} is above the maximum of {MAX_SUPERSAMPLE}",
                    self.max_supersample
                ),
            ));
        }
        HaarShift::new(self.max_precision.max(self.max_retained_precision), false).map(|_| ())
    }

    /// [`expand`](Self::expand) applied to every kernel, Haar in both modes.
    pub fn every_configuration(&self) -> Vec<KernelCycle> {
        self.expand(&KernelCycle::every_kernel(KernelOptions::default(), 0))
    }

    /// The parameter line printed with the results.
    ///
    /// ```
    /// use haarshift_experiments::tradeoff::TradeoffGrid;
    /// assert_eq!(
    ///     TradeoffGrid::default().describe(),
    ///     "compact haar h = 0..=3, retained haar h = 1..=2 (at s = 0), supersample s = 0..=2"
    /// );
    /// ```
    pub fn describe(&self) -> String {
        format!(
            "compact haar h = 0..={}, retained haar h = 1..={} (at s = 0), supersample s = 0..={}",
            self.max_precision, self.max_retained_precision, self.max_supersample
        )
    }
}

/// One configuration summarised over the images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TradeoffPoint {
    /// The method and its parameters.
    #[serde(flatten)]
    pub method: MethodSpec,
    /// Rotations in the cycle.
    pub steps: usize,
    /// Number of images.
    pub images: usize,
    /// Mean over the images of the RMS error.
    pub mean_rms: f64,
    /// Largest error over all images.
    pub max_error: f64,
    /// Wall time of all the images' rotations.
    pub total_seconds: f64,
    /// Median wall time per image.
    pub median_seconds: f64,
    /// Largest peak heap of one image's rotations (the runs are one at a time), when measured.
    pub peak_bytes: Option<u64>,
    /// On the Pareto frontier of (total seconds, mean RMS).
    pub time_frontier: bool,
    /// On the Pareto frontier of (peak bytes, mean RMS); false when memory was not measured.
    pub memory_frontier: bool,
}

/// One [`TradeoffPoint`] per configuration (method, parameters and steps) in order of first
/// appearance in `runs`, with the frontier flags set.
///
/// ```
/// use haarshift_experiments::rotation_cycle::{CycleRecord, MethodSpec};
/// use haarshift_experiments::tradeoff::summarize;
/// let run = |method: &str, rms, seconds| CycleRecord {
///     image: "a".into(), method: MethodSpec { method: method.into(), ..Default::default() },
///     steps: 16, crop: 64, rms, psnr: 30.0, max_error: 2.0 * rms, seconds, peak_bytes: Some(100),
/// };
/// let points = summarize(&[run("linear", 16.0, 0.1), run("fft", 2.0, 0.5), run("keys", 9.0, 0.6)]);
/// let flags: Vec<_> = points.iter().map(|p| (p.time_frontier, p.memory_frontier)).collect();
/// // keys is slower and worse than fft; at equal memory only fft's error counts.
/// assert_eq!(flags, vec![(true, false), (true, true), (false, false)]);
/// ```
pub fn summarize(runs: &[CycleRecord]) -> Vec<TradeoffPoint> {
    let mut groups: Vec<(&MethodSpec, usize, Vec<&CycleRecord>)> = Vec::new();
    for run in runs {
        match groups
            .iter_mut()
            .find(|(m, steps, _)| **m == run.method && *steps == run.steps)
        {
            Some((_, _, members)) => members.push(run),
            None => groups.push((&run.method, run.steps, vec![run])),
        }
    }
    let mut points: Vec<TradeoffPoint> = groups
        .into_iter()
        .map(|(method, steps, members)| {
            let n = members.len() as f64;
            let mut seconds: Vec<f64> = members.iter().map(|r| r.seconds).collect();
            seconds.sort_by(f64::total_cmp);
            let peak_bytes = members
                .iter()
                .map(|r| r.peak_bytes)
                .collect::<Option<Vec<u64>>>()
                .and_then(|b| b.into_iter().max());
            TradeoffPoint {
                method: method.clone(),
                steps,
                images: members.len(),
                mean_rms: members.iter().map(|r| r.rms).sum::<f64>() / n,
                max_error: members.iter().map(|r| r.max_error).fold(0.0, f64::max),
                total_seconds: seconds.iter().sum(),
                median_seconds: median(&seconds),
                peak_bytes,
                time_frontier: false,
                memory_frontier: false,
            }
        })
        .collect();
    let by_time: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.total_seconds, p.mean_rms))
        .collect();
    let by_memory: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.peak_bytes.map_or(f64::NAN, |b| b as f64), p.mean_rms))
        .collect();
    for i in frontier(&by_time) {
        points[i].time_frontier = true;
    }
    for i in frontier(&by_memory) {
        points[i].memory_frontier = true;
    }
    points
}

/// The median of sorted, non-empty `values` (the mean of the middle two for an even count).
fn median(sorted: &[f64]) -> f64 {
    let mid = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[mid]
    } else {
        (sorted[mid - 1] + sorted[mid]) / 2.0
    }
}

#[cfg(test)]
#[path = "tradeoff_tests.rs"]
mod tests;
