//! One way to run a precomputation: a [`PrecomputeRequest`] holds everything a run needs (the
//! input, every option of `haarshift relight precompute`, the output), refuses what cannot be
//! done in one [`check`](PrecomputeRequest::check) before any work, and
//! [`run`](PrecomputeRequest::run)s it: the scene loaded within the memory budget, the ground
//! plane added, then a whole cache (refined, with bounces), a shard (skipped when its output
//! is complete already) or a shard of one more bounce, written to the output. The command
//! line and Python fill in the same request, so their options, refusals and caches agree.
//!
//! The library prints nothing: what a run has to say (the mesh files' warnings, the tracer
//! that cast, the timings, the memory) comes back in the [`PrecomputeRun`] for the caller to
//! show.

use std::ops::Range;
use std::path::PathBuf;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;

use crate::light::environment::Environment;
use crate::precompute::refine::{Probe, RefineReport, Refinement, precompute_refined};
use crate::precompute::shard::{Shard, ShardSpec};
use crate::precompute::{
    DEFAULT_MAP_SIZE, Order, PrecomputeOptions, precompute, precompute_bounce_shard,
    precompute_shard, shard_is_done,
};
use crate::scene::validate::{DEFAULT_MEMORY_LIMIT, MemoryBudget};
use crate::{
    CacheShard, Error, PrecomputeReport, RayTracer, Result, Scene, SceneCache, VisibilityOptions,
};

/// The face side of a precomputation when none is given (`--resolution`).
pub const DEFAULT_RESOLUTION: usize = 32;

/// What a precomputation starts from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneInput {
    /// A mesh (`.obj`, `.ply`, `.gltf`, `.glb`) or a scene file (`.json`), read by
    /// [`Scene::load_within`] within the run's memory budget.
    File(PathBuf),
    /// A scene already loaded (its warnings are the run's).
    Loaded(Box<Scene>),
}

/// Everything a precomputation run needs, named as `haarshift relight precompute`'s flags are
/// (`--visibility-samples` is [`visibility_samples`](Self::visibility_samples), and so on).
/// [`new`](Self::new) gives the command line's defaults.
///
/// ```
/// use haarshift_relight::precompute::request::{Outcome, PrecomputeRequest, SceneInput};
/// use haarshift_relight::{Generator, Scene};
/// use haarshift::faces::ParamKind;
/// let ball = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
/// let mut request = PrecomputeRequest::new(SceneInput::Loaded(Box::new(ball)));
/// (request.param, request.resolution, request.ground_plane) = (ParamKind::Cube, 4, true);
/// let run = request.run().unwrap();
/// let Outcome::Whole { cache, file_bytes, .. } = &run.outcome else { panic!("a whole cache") };
/// assert_eq!((cache.mesh.vertex_count(), cache.params.ground_cells), (54 + 1089, Some(32)));
/// assert_eq!((file_bytes, run.warnings.len()), (&None, 0)); // no output asked for
/// request.refine = Some(3.0);
/// let err = request.check().unwrap_err().to_string();
/// assert!(err.contains("3: the tolerance is a fraction"), "{err}");
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PrecomputeRequest {
    /// The mesh or scene file, or a scene loaded.
    pub input: SceneInput,
    /// `--ground-plane`: add a ground plane under the scene, unless it has one.
    pub ground_plane: bool,
    /// `--ground-cells N`: the ground plane's cells per side (with
    /// [`ground_plane`](Self::ground_plane); default 32).
    pub ground_cells: Option<usize>,
    /// `--memory-limit`: the most bytes the scene and its transport may take.
    pub memory_limit: u64,
    /// `-o`: the cache (or shard) to write; a shard needs one, a whole cache may be kept in
    /// memory only.
    pub output: Option<PathBuf>,
    /// `--param`.
    pub param: ParamKind,
    /// `--resolution N`: the face side, a power of two.
    pub resolution: usize,
    /// `--keep-visibility K`: detail coefficients kept per vertex (`None`: all).
    pub keep_visibility: Option<usize>,
    /// `--visibility-samples S`: `S x S` stratified rays per texel.
    pub visibility_samples: usize,
    /// `--seed`: of the stratified jitter.
    pub seed: u64,
    /// `--order`.
    pub order: Order,
    /// `--ray-tracer` (`None`: [`RayTracer::best`]).
    pub ray_tracer: Option<RayTracer>,
    /// `--map-size M`: the shadow-buffer side of [`Order::Direction`].
    pub map_size: usize,
    /// `--sh-bands B`: also the spherical-harmonic transfer of `B` bands.
    pub sh_bands: Option<usize>,
    /// `--bounces B`: bounces of interreflected light.
    pub bounces: usize,
    /// `--bounce-from MERGED.hsr`: with a shard, add one bounce to this merged cache's.
    pub bounce_from: Option<PathBuf>,
    /// `--refine TOL`: refine the mesh where the transport differs by more than `TOL`.
    pub refine: Option<f64>,
    /// `--max-vertices N`: with [`refine`](Self::refine), the most vertices.
    pub max_vertices: Option<usize>,
    /// `--refine-light ENV`: with [`refine`](Self::refine), judge edges under this map.
    pub refine_light: Option<PathBuf>,
    /// `--shard I/N|auto`: one shard of the vertices only.
    pub shard: Option<ShardSpec>,
    /// `--shards N`: with `--shard auto` in a Kubernetes Indexed Job, the number of shards.
    pub shards: Option<usize>,
    /// `--force`: replace the output if it exists (a shard: even a complete one).
    pub force: bool,
    /// Progress bars on standard error while rays are cast (the command line's; off here).
    pub progress: bool,
}

impl PrecomputeRequest {
    /// A request for `input` with the command line's defaults: lat-long
    /// [`DEFAULT_RESOLUTION`], every coefficient, one ray per texel, the vertex order with the
    /// best tracer, no ground plane, bounces, refinement or shard, the default memory limit,
    /// no output.
    pub fn new(input: SceneInput) -> Self {
        PrecomputeRequest {
            input,
            ground_plane: false,
            ground_cells: None,
            memory_limit: DEFAULT_MEMORY_LIMIT,
            output: None,
            param: ParamKind::LatLong,
            resolution: DEFAULT_RESOLUTION,
            keep_visibility: None,
            visibility_samples: 1,
            seed: 0,
            order: Order::Vertex,
            ray_tracer: None,
            map_size: DEFAULT_MAP_SIZE,
            sh_bands: None,
            bounces: 0,
            bounce_from: None,
            refine: None,
            max_vertices: None,
            refine_light: None,
            shard: None,
            shards: None,
            force: false,
            progress: false,
        }
    }

    /// Refuses, before any file is read or any ray cast, everything the run would refuse for
    /// its options: options that go only with another ([`ground_cells`](Self::ground_cells)
    /// with [`ground_plane`](Self::ground_plane), [`max_vertices`](Self::max_vertices) and
    /// [`refine_light`](Self::refine_light) with [`refine`](Self::refine),
    /// [`bounce_from`](Self::bounce_from) and [`shards`](Self::shards) with
    /// `shard`), a shard without an output, an output that is an input or
    /// exists (unless [`force`](Self::force), or a shard, whose complete output is skipped),
    /// a bad resolution, a transport too large, a tracer not available, bounces, a shard or a
    /// refinement the other options rule out. `--shard auto` is resolved from the process's
    /// environment ([`Shard::from_env`]).
    pub fn check(&self) -> Result<()> {
        self.plan().map(drop)
    }

    /// The options, shard and refinement this request asks for, every refusal of
    /// [`check`](Self::check) made.
    fn plan(&self) -> Result<Plan> {
        let shard = ShardSpec::from_env(self.shard, self.shards)?;
        self.check_pairs(shard)?;
        self.check_output(shard)?;
        let param = Parameterization::new(self.param, self.resolution)?;
        let mut visibility = VisibilityOptions::new(param);
        visibility.samples = self.visibility_samples;
        visibility.seed = self.seed;
        visibility.sh_bands = self.sh_bands;
        visibility.progress = self.progress;
        visibility.keep = self
            .keep_visibility
            .map_or(Selection::All, Selection::Largest);
        let options = PrecomputeOptions {
            visibility,
            order: self.order,
            map_size: self.map_size,
            memory_limit: self.memory_limit,
            ray_tracer: self.ray_tracer.unwrap_or_else(RayTracer::best),
            bounces: self.bounces,
        };
        options.check()?;
        if shard.is_some() {
            options.check_shard(self.bounce_from.is_some())?;
        }
        // The probe is read by the run; its parameterisation is the transport's by making.
        let refinement = self.refine.map(|tolerance| Refinement {
            tolerance,
            max_vertices: self.max_vertices,
            probe: None,
        });
        if let Some(r) = &refinement {
            r.check_with(&options, shard)?;
        }
        Ok(Plan {
            options,
            shard,
            refinement,
        })
    }

    /// Refuses an option given without the one it goes with (the command line's `requires`).
    fn check_pairs(&self, shard: Option<Shard>) -> Result<()> {
        let needs = |given: bool, name: &'static str, reason: &str| match given {
            true => Err(Error::parameter(name, reason)),
            false => Ok(()),
        };
        needs(
            self.ground_cells.is_some() && !self.ground_plane,
            "ground cells",
            "the ground plane's cells go with --ground-plane",
        )?;
        if let Some(cells) = self.ground_cells {
            crate::scene::check_ground_cells(cells)?;
        }
        crate::scene::validate::check_memory_limit(self.memory_limit)?;
        needs(
            self.max_vertices.is_some() && self.refine.is_none(),
            "max vertices",
            "goes with --refine TOL",
        )?;
        needs(
            self.refine_light.is_some() && self.refine.is_none(),
            "refine light",
            "goes with --refine TOL",
        )?;
        needs(
            self.bounce_from.is_some() && shard.is_none(),
            "bounce from",
            "goes with --shard: an unsharded --bounces run gathers every bounce itself",
        )?;
        needs(
            shard.is_some() && self.output.is_none(),
            "output",
            "a shard is written to a file: give --output",
        )
    }

    /// Refuses an output that is one of the inputs, or that exists (unless replaced by
    /// `--force`, or a shard's, which the run looks at once the scene is read).
    fn check_output(&self, shard: Option<Shard>) -> Result<()> {
        let Some(output) = &self.output else {
            return Ok(());
        };
        let file = match &self.input {
            SceneInput::File(path) => Some(path.as_path()),
            SceneInput::Loaded(_) => None,
        };
        let inputs = [
            file,
            self.bounce_from.as_deref(),
            self.refine_light.as_deref(),
        ];
        for input in inputs.into_iter().flatten() {
            haarshift::io::ensure_distinct_paths(input, output)?;
        }
        if !self.force && shard.is_none() && output.exists() {
            return Err(haarshift::Error::OutputExists {
                path: output.clone(),
            }
            .into());
        }
        Ok(())
    }

    /// Runs the precomputation: [`check`](Self::check)s, reads the refinement's probe
    /// lighting, loads the scene within the options' [memory budget](PrecomputeOptions::budget)
    /// (with the ground plane when asked), then computes, writes the output (if any) and
    /// reports. A shard whose output holds it complete is skipped
    /// ([`shard_is_done`]) unless [`force`](Self::force).
    pub fn run(&self) -> Result<PrecomputeRun> {
        let Plan {
            options,
            shard,
            mut refinement,
        } = self.plan()?;
        if let (Some(r), Some(path)) = (&mut refinement, &self.refine_light) {
            let env = Environment::load(path)?;
            let name = path
                .file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into());
            r.probe = Some(
                Probe::new(name, &env, options.visibility.param).map_err(|e| e.in_file(path))?,
            );
        }
        let (scene, warnings) = self.load(options.budget(shard))?;
        let outcome = match shard {
            None => self.whole(scene, &options, refinement.as_ref())?,
            Some(shard) => self.shard(scene, &options, shard)?,
        };
        Ok(PrecomputeRun {
            warnings,
            param: options.visibility.param,
            order: options.order,
            outcome,
        })
    }

    /// The scene, with the ground plane when asked, and its warnings (a file's named).
    fn load(&self, budget: MemoryBudget) -> Result<(Scene, Vec<String>)> {
        let (mut scene, path) = match &self.input {
            SceneInput::File(path) => (Scene::load_within(path, &budget)?, Some(path)),
            SceneInput::Loaded(scene) => (scene.as_ref().clone(), None),
        };
        let warnings = (scene.warnings.iter())
            .map(|w| match path {
                Some(p) => format!("{}: {w}", p.display()),
                None => w.clone(),
            })
            .collect();
        let added = match (self.ground_plane, self.ground_cells) {
            (false, _) => Ok(()),
            (true, None) => scene.add_ground_plane(),
            (true, Some(cells)) => scene.add_ground_plane_of(cells),
        };
        match path {
            Some(p) => added.map_err(|e| e.in_file(p))?,
            None => added?,
        }
        Ok((scene, warnings))
    }

    /// Every vertex's transport (refined when asked), the cache written to the output if any.
    fn whole(
        &self,
        scene: Scene,
        options: &PrecomputeOptions,
        refinement: Option<&Refinement>,
    ) -> Result<Outcome> {
        let (cache, report, refined) = match refinement {
            Some(r) => {
                let (cache, report, refined) = precompute_refined(scene, options, r)?;
                (cache, report, Some(refined))
            }
            None => {
                let (cache, report) = precompute(scene, options)?;
                (cache, report, None)
            }
        };
        let file_bytes = (self.output.as_deref())
            .map(|path| cache.write(path, self.force))
            .transpose()?;
        Ok(Outcome::Whole {
            cache: Box::new(cache),
            report,
            refined,
            file_bytes,
        })
    }

    /// One shard (of one more bounce with [`bounce_from`](Self::bounce_from)), written to the
    /// output; skipped when the output holds it complete.
    fn shard(&self, scene: Scene, options: &PrecomputeOptions, shard: Shard) -> Result<Outcome> {
        let output = (self.output.as_deref())
            .ok_or_else(|| Error::parameter("output", "a shard is written to a file"))?;
        let vertices = shard.range(scene.mesh.vertex_count());
        if !self.force && shard_is_done(output, &scene, options, shard)? {
            return Ok(Outcome::Skipped { shard, vertices });
        }
        let (part, report) = match &self.bounce_from {
            Some(merged) => {
                let merged_cache = SceneCache::read(merged)?;
                precompute_bounce_shard(scene, options, shard, &merged_cache)
                    .map_err(|e| e.in_file(merged))?
            }
            None => precompute_shard(scene, options, shard)?,
        };
        let file_bytes = part.write(output, self.force)?;
        Ok(Outcome::Shard {
            shard,
            vertices,
            part: Box::new(part),
            report,
            file_bytes,
        })
    }
}

/// What [`PrecomputeRequest::plan`] found: the run's options, its shard and refinement.
struct Plan {
    options: PrecomputeOptions,
    shard: Option<Shard>,
    refinement: Option<Refinement>,
}

/// What a [`PrecomputeRequest`] did, for its caller to show.
#[derive(Clone, Debug, PartialEq)]
pub struct PrecomputeRun {
    /// What the mesh files approximated (a glossy glTF material taken as its base colour),
    /// one line each, a file's named (`bunny.glb: ...`): beside the work, not a refusal.
    pub warnings: Vec<String>,
    /// The directions of the transport.
    pub param: Parameterization,
    /// The loop order.
    pub order: Order,
    /// The cache or shard made, or the shard skipped.
    pub outcome: Outcome,
}

/// The result of a run.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Every vertex's transport.
    Whole {
        /// The cache (what was written, when there was an output).
        cache: Box<SceneCache>,
        /// Rays, tracer, seconds and working memory.
        report: PrecomputeReport,
        /// What the refinement did, when asked for.
        refined: Option<RefineReport>,
        /// Bytes written to the output (`None`: none given).
        file_bytes: Option<u64>,
    },
    /// One shard, written to the output.
    Shard {
        /// The shard.
        shard: Shard,
        /// Its vertices.
        vertices: Range<usize>,
        /// What was written.
        part: Box<CacheShard>,
        /// Rays, tracer, seconds and working memory.
        report: PrecomputeReport,
        /// Bytes written.
        file_bytes: u64,
    },
    /// A shard whose output held it complete already: nothing computed.
    Skipped {
        /// The shard.
        shard: Shard,
        /// Its vertices.
        vertices: Range<usize>,
    },
}

#[cfg(test)]
#[path = "request_tests.rs"]
mod tests;
