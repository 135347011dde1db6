//! Splitting a precomputation across machines: shard `I` of `N` computes the vertices
//! `[I x V / N, (I + 1) x V / N)` (the floor of each bound), so that the `N` ranges cover every
//! vertex exactly once, are as even as whole vertices allow and can be computed in any order on
//! any machine. Every shard traces the whole scene and every random choice is keyed by the
//! global vertex index, texel and sample ([`vertex_major`](super::visibility::vertex_major)),
//! so a vertex's transport has the same bits whatever `N` is; `haarshift relight merge` puts
//! the shards back together ([`merge_shards`](crate::scene::cache_shard::merge_shards)).
//!
//! A split by vertex count, not by rays: a vertex's rays are the texels above its horizon,
//! about half of them for every vertex, so equal vertex counts are equal work up to the
//! occlusion's effect on the BVH traversal.
//!
//! **Where the index comes from** ([`ShardSpec::resolve`]): `--shard I/N` names it; `--shard
//! auto` reads it from the scheduler's environment, through a lookup function so that tests
//! need not change the process's environment:
//! * a Slurm array job (`SLURM_ARRAY_TASK_ID` set): `I = (ID - MIN) / STEP` and
//!   `N = SLURM_ARRAY_TASK_COUNT`, with `SLURM_ARRAY_TASK_MIN` and `SLURM_ARRAY_TASK_STEP`
//!   (1 when unset). An array with gaps (`--array=0,2,5`: its `MIN`, `MAX`, `STEP` describe
//!   more tasks than `COUNT`) is refused: some shards would never run;
//! * a Kubernetes Indexed Job (`JOB_COMPLETION_INDEX` set): `I` is the index and `N` comes
//!   from `--shards N` (the Job's `completions`), which Kubernetes does not export.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use crate::{Error, Result};

/// Shard `index` of `count`; see the [module docs](self).
///
/// ```
/// use haarshift_relight::precompute::shard::Shard;
/// let shards: Vec<_> = (0..3).map(|i| Shard::new(i, 3).unwrap().range(10)).collect();
/// assert_eq!(shards, [0..3, 3..6, 6..10]);
/// assert_eq!("2/3".parse::<Shard>().unwrap(), Shard::new(2, 3).unwrap());
/// assert!(Shard::new(3, 3).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    index: usize,
    count: usize,
}

impl Shard {
    /// Shard `index` of `count` (`index < count`).
    pub fn new(index: usize, count: usize) -> Result<Self> {
        if index >= count {
            return Err(Error::parameter(
                "shard",
                format!("{index}/{count}: the index must be below the count (0 to {count} - 1)"),
            ));
        }
        Ok(Shard { index, count })
    }

    /// The one shard that is the whole precomputation.
    ///
    /// ```
    /// use haarshift_relight::precompute::shard::Shard;
    /// assert_eq!(Shard::whole().range(7), 0..7);
    /// ```
    pub fn whole() -> Self {
        Shard { index: 0, count: 1 }
    }

    /// The index `I`.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The count `N`.
    pub fn count(&self) -> usize {
        self.count
    }

    /// This shard's share of `total` items (vertices, a scene's shapes, an experiment's
    /// settings): `[I x total / N, (I + 1) x total / N)`.
    ///
    /// ```
    /// use haarshift_relight::precompute::shard::Shard;
    /// assert_eq!(Shard::new(1, 4).unwrap().range(10), 2..5);
    /// assert_eq!(Shard::new(3, 4).unwrap().range(2), 1..2);
    /// ```
    pub fn range(&self, total: usize) -> Range<usize> {
        // In u128: I x V cannot overflow, and the quotient is at most V.
        let bound = |i: usize| (i as u128 * total as u128 / self.count as u128) as usize;
        bound(self.index)..bound(self.index + 1)
    }

    /// The shard a scheduler's environment names, `lookup` reading its variables (see the
    /// [module docs](self)); `shards` is `--shards N`, required by a Kubernetes Indexed Job
    /// and, when given to a Slurm array job, checked against its task count.
    ///
    /// ```
    /// use haarshift_relight::precompute::shard::Shard;
    /// let slurm = |name: &str| match name {
    ///     "SLURM_ARRAY_TASK_ID" => Some("7".to_string()),
    ///     "SLURM_ARRAY_TASK_MIN" => Some("1".to_string()),
    ///     "SLURM_ARRAY_TASK_STEP" => Some("2".to_string()),
    ///     "SLURM_ARRAY_TASK_MAX" => Some("9".to_string()),
    ///     "SLURM_ARRAY_TASK_COUNT" => Some("5".to_string()),
    ///     _ => None,
    /// };
    /// assert_eq!(Shard::from_env(slurm, None).unwrap(), Shard::new(3, 5).unwrap());
    /// let k8s = |name: &str| (name == "JOB_COMPLETION_INDEX").then(|| "4".to_string());
    /// assert_eq!(Shard::from_env(k8s, Some(8)).unwrap(), Shard::new(4, 8).unwrap());
    /// assert!(Shard::from_env(|_| None, Some(8)).is_err());
    /// ```
    pub fn from_env(
        lookup: impl Fn(&str) -> Option<String>,
        shards: Option<usize>,
    ) -> Result<Self> {
        let number = |name: &str| -> Result<Option<usize>> {
            lookup(name)
                .map(|value| {
                    value.trim().parse::<usize>().map_err(|_| {
                        Error::parameter(
                            "shard",
                            format!("auto: {name}={value:?} is not a whole number"),
                        )
                    })
                })
                .transpose()
        };
        if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
            let required = |name: &str| {
                number(name)?.ok_or_else(|| {
                    Error::parameter(
                        "shard",
                        format!("auto: SLURM_ARRAY_TASK_ID is set but {name} is not"),
                    )
                })
            };
            let count = required("SLURM_ARRAY_TASK_COUNT")?;
            let min = required("SLURM_ARRAY_TASK_MIN")?;
            let step = number("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1);
            let max = number("SLURM_ARRAY_TASK_MAX")?;
            // The tasks MIN, MIN + STEP, ..., MAX must be exactly COUNT: else the array has
            // gaps (or a MAX off the step) and the shards it lacks would never run.
            let spanned = max.and_then(|max| {
                let span = max.checked_sub(min)?;
                (step > 0 && span % step == 0).then(|| span / step + 1)
            });
            let offset = id.checked_sub(min).filter(|d| step > 0 && d % step == 0);
            let (Some(offset), true) = (offset, max.is_none() || spanned == Some(count)) else {
                return Err(Error::parameter(
                    "shard",
                    format!(
                        "auto: the Slurm array (task {id}, min {min}, max {}, step {step}, count \
                         {count}) has gaps: give --array=A-B or A-B:STEP",
                        max.map_or("unset".into(), |m| m.to_string())
                    ),
                ));
            };
            if let Some(n) = shards.filter(|&n| n != count) {
                return Err(Error::parameter(
                    "shard",
                    format!("auto: --shards {n} but the Slurm array has {count} tasks"),
                ));
            }
            return Shard::new(offset / step, count);
        }
        if let Some(index) = number("JOB_COMPLETION_INDEX")? {
            let count = shards.ok_or_else(|| {
                Error::parameter(
                    "shard",
                    "auto: JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job): give the \
                     Job's completions as --shards N",
                )
            })?;
            return Shard::new(index, count);
        }
        Err(Error::parameter(
            "shard",
            "auto: neither SLURM_ARRAY_TASK_ID (a Slurm array job) nor JOB_COMPLETION_INDEX \
             (a Kubernetes Indexed Job) is set: give --shard I/N",
        ))
    }
}

/// `I/N`.
impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// `I/N`, two whole numbers with `I < N`.
impl FromStr for Shard {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        let parsed = s
            .split_once('/')
            .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)));
        let Some((index, count)) = parsed else {
            return Err(Error::parameter(
                "shard",
                format!("{s:?}: expected I/N (shard I of N, counting from 0) or auto"),
            ));
        };
        Shard::new(index, count)
    }
}

/// `--shard`: a shard named, or `auto` (from the scheduler's environment).
///
/// ```
/// use haarshift_relight::precompute::shard::{Shard, ShardSpec};
/// assert_eq!("auto".parse::<ShardSpec>().unwrap(), ShardSpec::Auto);
/// let given: ShardSpec = "1/4".parse().unwrap();
/// assert_eq!(given.resolve(|_| None, None).unwrap(), Shard::new(1, 4).unwrap());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardSpec {
    /// `I/N`.
    Given(Shard),
    /// `auto`: [`Shard::from_env`].
    Auto,
}

impl ShardSpec {
    /// The shard: the one given, or [`Shard::from_env`] with `lookup` and `shards`
    /// (`--shards N`, which only `auto` takes).
    pub fn resolve(
        self,
        lookup: impl Fn(&str) -> Option<String>,
        shards: Option<usize>,
    ) -> Result<Shard> {
        match (self, shards) {
            (ShardSpec::Given(shard), None) => Ok(shard),
            (ShardSpec::Given(shard), Some(_)) => Err(Error::parameter(
                "shard",
                format!("{shard}: --shards goes with --shard auto only (I/N names the count)"),
            )),
            (ShardSpec::Auto, shards) => Shard::from_env(lookup, shards),
        }
    }
}

impl ShardSpec {
    /// The shard of `spec` (none without one), `auto` read from this process's environment
    /// ([`resolve`](Self::resolve)); `shards` without a `spec` is refused, as it names the
    /// count of `auto` only.
    ///
    /// ```
    /// use haarshift_relight::precompute::shard::{Shard, ShardSpec};
    /// let given = "1/4".parse::<ShardSpec>().ok();
    /// assert_eq!(ShardSpec::from_env(given, None).unwrap(), Some(Shard::new(1, 4).unwrap()));
    /// assert_eq!(ShardSpec::from_env(None, None).unwrap(), None);
    /// let err = ShardSpec::from_env(None, Some(4)).unwrap_err().to_string();
    /// assert_eq!(err, "invalid shards: goes with --shard auto");
    /// ```
    pub fn from_env(spec: Option<ShardSpec>, shards: Option<usize>) -> Result<Option<Shard>> {
        match (spec, shards) {
            (None, Some(_)) => Err(Error::parameter("shards", "goes with --shard auto")),
            (spec, shards) => spec
                .map(|s| s.resolve(|name| std::env::var(name).ok(), shards))
                .transpose(),
        }
    }
}

/// `auto` or `I/N`.
impl FromStr for ShardSpec {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "auto" => Ok(ShardSpec::Auto),
            _ => s.parse().map(ShardSpec::Given),
        }
    }
}

#[cfg(test)]
#[path = "shard_tests.rs"]
mod tests;
