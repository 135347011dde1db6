//! The dynamic-scene experiment (`haarshift experiment dynamic`): occlusion fields and
//! just-in-time radiance transfer against the ray-cast ground truth, over the map resolution,
//! the field's sample density, the kept-coefficient budget (and whether looked-up maps are
//! truncated before or after the blend), the traversal depth, and the time of each kind of
//! change.
//!
//! **Protocol.** A scenario is a scene file, the object that moves and where it goes. For a
//! setting, the scene is built (fields and own transport), just-in-time transfer is formed
//! for the moving object at its file placement, the object is moved to its target, and the
//! frame is shaded (`<T, O_moving>` per vertex). The ground truth is
//! [`DynamicScene::reference`] of the moved scene over the environment at
//! `reference_resolution` (ray casting against every object; no field, no transform). Errors
//! are per-vertex radiance differences, RMS and maximum over all vertices and channels,
//! relative to the RMS of the ground truth. The budget and depth axes re-truncate one build
//! ([`DynamicScene::truncated`], [`DynamicScene::set_shading`]), so their times are of the
//! shading only; the build times are those of the resolution and density axes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::journal::Journal;
use crate::{Error, Result};
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::metrics::RelativeError;
use haarshift::product::Selection;
use haarshift::sphere::SphereRotation;
use haarshift_relight::dynamic::fields::{FieldOptions, Truncation};
use haarshift_relight::dynamic::{
    Change, DynamicOptions, DynamicScene, JustInTimeTransfer, Placement,
};
use haarshift_relight::light::environment::Environment;
use haarshift_relight::shade::{FrameSpec, ShaderSpec, ShadingInput};
use haarshift_relight::{
    Lighting, SceneBvh, SceneFile, Transform, VisibilityOptions, vertex_major,
};

/// A kept-coefficient budget: lighting, each vertex's own transport, each occlusion map
/// (`None`: all).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Budget {
    /// Lighting details kept.
    pub light: Option<usize>,
    /// Own-transport details kept per vertex.
    pub visibility: Option<usize>,
    /// Details kept per occlusion map.
    pub field: Option<usize>,
}

impl Budget {
    const ALL: Budget = Budget {
        light: None,
        visibility: None,
        field: None,
    };

    const fn of(light: usize, visibility: usize, field: usize) -> Budget {
        Budget {
            light: Some(light),
            visibility: Some(visibility),
            field: Some(field),
        }
    }
}

fn selection(k: Option<usize>) -> Selection {
    k.map_or(Selection::All, Selection::Largest)
}

/// What to run: each axis a list; see the [module docs](self).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DynamicProtocol {
    /// Lat-long heights `N` of the maps (the resolution axis).
    pub resolutions: Vec<usize>,
    /// Sample densities relative to Sun 2006's fields (the density axis): circles, points
    /// per circle and shells scale by it, the shell grid by its square root.
    pub densities: Vec<f64>,
    /// The resolution of the budget, depth and timing axes.
    pub base_resolution: usize,
    /// Budgets (the budget axis), each with truncation before and after the blend.
    pub budgets: Vec<Budget>,
    /// The budget of the depth and timing axes.
    pub base_budget: Budget,
    /// The lat-long height of the ground truth's lighting.
    pub reference_resolution: usize,
}

impl DynamicProtocol {
    /// The default run: minutes on two cores.
    pub fn quick() -> Self {
        DynamicProtocol {
            resolutions: vec![16, 32],
            densities: vec![0.25, 0.5, 1.0],
            base_resolution: 32,
            budgets: vec![
                Budget::ALL,
                Budget::of(300, 120, 120),
                Budget::of(200, 70, 70),
                Budget::of(100, 30, 30),
                Budget::of(40, 10, 10),
            ],
            base_budget: Budget::of(200, 70, 70),
            reference_resolution: 64,
        }
    }

    /// The full run: the 64 x 128 maps and twice 001's density too.
    pub fn full() -> Self {
        DynamicProtocol {
            resolutions: vec![16, 32, 64],
            densities: vec![0.25, 0.5, 1.0, 2.0],
            reference_resolution: 128,
            ..Self::quick()
        }
    }
}

/// A scene, the object that moves in it and where it goes.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Its name in the records.
    pub name: String,
    /// The scene file's content.
    pub file: SceneFile,
    /// The directory its relative paths start from.
    pub dir: PathBuf,
    /// The moving object's name.
    pub moving: String,
    /// Where it goes.
    pub to: Transform,
}

impl Scenario {
    /// A scenario from a scene file.
    pub fn load(path: &Path, moving: &str, to: Transform) -> Result<Self> {
        let (file, dir) = SceneFile::read(path)?;
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into(),
        );
        Ok(Scenario {
            name,
            file,
            dir: dir.to_path_buf(),
            moving: moving.to_owned(),
            to,
        })
    }
}

/// One measured setting. The `static` axis is the floor under the others: the moved scene
/// precomputed as a static scene (its "re-form" is that precomputation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DynamicRecord {
    /// Scenario name.
    pub scene: String,
    /// The axis: `resolution`, `density`, `budget`, `depth`, `change` or `static`.
    pub axis: String,
    /// Vertices.
    pub vertices: usize,
    /// Objects.
    pub objects: usize,
    /// Lat-long height `N` of every map.
    pub resolution: usize,
    /// Sample points per shape's fields.
    pub field_samples: usize,
    /// Lighting details kept (empty: all).
    pub keep_light: Option<usize>,
    /// Own-transport details kept (empty: all).
    pub keep_visibility: Option<usize>,
    /// Occlusion-map details kept (empty: all).
    pub keep_field: Option<usize>,
    /// `before` or `after` the blend.
    pub truncation: String,
    /// Traversal depth (detail levels `0..depth`).
    pub depth: usize,
    /// What varies (`object` or `lighting`).
    pub change: String,
    /// RMS error over vertices and channels, relative to the ground truth's RMS.
    pub rms_relative: f64,
    /// Largest error, relative to the ground truth's RMS.
    pub max_relative: f64,
    /// RMS error in radiance units.
    pub rms: f64,
    /// Seconds building the fields (all shapes).
    pub field_seconds: f64,
    /// Bytes of the stored field maps.
    pub field_bytes: usize,
    /// Seconds re-forming the transfer.
    pub reform_seconds: f64,
    /// Seconds of one frame (encoding the varying factor and the dot products).
    pub frame_seconds: f64,
    /// Fixed-product coefficients per vertex.
    pub product_coefficients: f64,
}

/// Runs `protocol` on `scenario` under `env` (rotated by `angles`, degrees); `progress` is
/// called with each record as it is made. Each setup (a resolution or a density, with the
/// budget, depth, change and static rows measured on its build) is one unit of `journal`
/// ([`Journal::in_memory`] for none), keyed by the scenario's name: a resumed journal's
/// setups are taken from it, and a run whose setups are all journaled builds nothing.
///
/// ```no_run
/// use haarshift_experiments::moving_objects::{DynamicProtocol, Scenario, run};
/// use haarshift_experiments::journal::Journal;
/// use haarshift_relight::Transform;
/// use haarshift_relight::light::environment::Environment;
/// let to = Transform { translate: [1.5, 1.2, 4.5], ..Transform::default() };
/// let scenario = Scenario::load("../testdata/scenes/bunny_and_ball.json".as_ref(), "ball", to).unwrap();
/// let env = Environment::load("../testdata/envmaps/rooitou_park_32x16.hdr".as_ref()).unwrap();
/// let mut journal = Journal::create("dynamic.journal".as_ref(), "quick", false).unwrap();
/// let records = run(&scenario, &env, [0.0; 3], &DynamicProtocol::quick(), &mut journal, |_| {}).unwrap();
/// journal.finish().unwrap();
/// assert!(records.iter().any(|r| r.axis == "static"));
/// ```
pub fn run(
    scenario: &Scenario,
    env: &Environment,
    angles: [f64; 3],
    protocol: &DynamicProtocol,
    journal: &mut Journal,
    mut progress: impl FnMut(&DynamicRecord),
) -> Result<Vec<DynamicRecord>> {
    let rotation = SphereRotation::from_degrees(angles[0], angles[1], angles[2])?;
    let mut setups: Vec<(&str, usize, f64)> = protocol
        .resolutions
        .iter()
        .map(|&n| ("resolution", n, 1.0))
        .collect();
    setups.extend(
        protocol
            .densities
            .iter()
            .filter(|&&d| d != 1.0)
            .map(|&d| ("density", protocol.base_resolution, d)),
    );
    let Some(&(_, first_n, first_density)) = setups.first() else {
        return Err(Error::parameter(
            "protocol",
            "no resolution and no density: nothing to measure",
        ));
    };
    // The ground truth ray-casts the moved scene (no field) as the first setup places it (a
    // turn is whole columns of its resolution); journaled before any setup, so that a resumed
    // run compares against the same one without building that setup again.
    let mut first: Option<Built> = None;
    let rows: Vec<[f64; 3]> = journal.unit(&format!("{} truth", scenario.name), || {
        let built = Built::new(scenario, first_n, first_density)?;
        let truth = built.truth(env, &rotation, protocol.reference_resolution)?;
        first = Some(built);
        Ok(truth
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect())
    })?;
    let truth =
        Array2::from_shape_vec((rows.len(), 3), rows.into_flattened()).expect("three values a row");
    let run = Run {
        scenario,
        env,
        rotation,
        protocol,
        truth: &truth,
    };
    let mut out = Vec::new();
    for (k, &(axis, n, density)) in setups.iter().enumerate() {
        let key = format!("{} {axis} {n} {density}", scenario.name);
        let records = journal.unit(&key, || {
            let built = match first.take() {
                Some(built) if k == 0 => built,
                _ => Built::new(scenario, n, density)?,
            };
            run.setup(&built, axis, n)
        })?;
        records.iter().for_each(&mut progress);
        out.extend(records);
    }
    Ok(out)
}

/// What every setup of one [`run`] shares.
struct Run<'a> {
    scenario: &'a Scenario,
    env: &'a Environment,
    rotation: SphereRotation,
    protocol: &'a DynamicProtocol,
    truth: &'a Array2<f64>,
}

impl Run<'_> {
    /// The records of one setup, built at resolution `n`: its own row and, at the base
    /// resolution, the budget, depth, change and static rows on the same build.
    fn setup(&self, built: &Built, axis: &str, n: usize) -> Result<Vec<DynamicRecord>> {
        let (scenario, env, rotation, protocol, truth) = (
            self.scenario,
            self.env,
            &self.rotation,
            self.protocol,
            self.truth,
        );
        let mut out = vec![built.measure(scenario, env, rotation, truth, axis, Budget::ALL)?];
        if axis != "resolution" || n != protocol.base_resolution {
            return Ok(out);
        }
        for budget in &protocol.budgets {
            for truncation in [
                Truncation::Before,
                Truncation::After(selection(budget.field)),
            ] {
                if truncation != Truncation::Before && budget.field.is_none() {
                    continue;
                }
                let b = built.with_budget(budget, truncation)?;
                out.push(b.measure(scenario, env, rotation, truth, "budget", *budget)?);
            }
        }
        let base = built.with_budget(&protocol.base_budget, Truncation::Before)?;
        let levels = n.trailing_zeros() as usize;
        for depth in 1..=levels {
            let mut b = base.clone();
            b.scene
                .set_shading(Truncation::Before, Selection::All, Some(depth))?;
            out.push(b.measure(
                scenario,
                env,
                rotation,
                truth,
                "depth",
                protocol.base_budget,
            )?);
        }
        out.push(base.measure_lighting(env, rotation, truth, protocol.base_budget, scenario)?);
        out.push(built.measure_static(env, rotation, truth, scenario)?);
        Ok(out)
    }
}

#[derive(Clone)]
struct Built {
    scene: DynamicScene,
    moving: usize,
    target: Placement,
}

impl Built {
    fn new(scenario: &Scenario, n: usize, density: f64) -> Result<Self> {
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let base = FieldOptions::new(param);
        let scale = |x: usize, by: f64| ((x as f64 * by).round() as usize).max(2);
        let field = FieldOptions {
            circles: scale(base.circles, density),
            circle_points: scale(base.circle_points, density).max(3),
            shells: scale(base.shells, density),
            shell_grid: scale(base.shell_grid, density.sqrt()),
            ..base
        };
        let options = DynamicOptions {
            field,
            ..DynamicOptions::new(param)
        };
        let scene = DynamicScene::build(&scenario.file, &scenario.dir, &options)?;
        let moving = scene.object_index(&scenario.moving).ok_or_else(|| {
            Error::parameter(
                "moving object",
                format!(
                    "{}: no object of {} has that name",
                    scenario.moving, scenario.name
                ),
            )
        })?;
        let target = Placement::from_transform(&scenario.to, param)?;
        Ok(Built {
            scene,
            moving,
            target,
        })
    }

    fn with_budget(&self, budget: &Budget, truncation: Truncation) -> Result<Self> {
        let mut scene = self
            .scene
            .truncated(selection(budget.visibility), selection(budget.field))?;
        scene.set_shading(truncation, Selection::All, None)?;
        Ok(Built {
            scene,
            moving: self.moving,
            target: self.target,
        })
    }

    /// The ground truth of the moved scene.
    fn truth(&self, env: &Environment, rotation: &SphereRotation, n: usize) -> Result<Array2<f64>> {
        let mut moved = self.scene.clone();
        moved.place(self.moving, self.target)?;
        moved.reference(&env.lat_long(n, rotation)?)
    }

    fn lighting(
        &self,
        env: &Environment,
        rotation: &SphereRotation,
        budget: Budget,
    ) -> Result<Lighting> {
        Lighting::new(env, self.scene.param(), rotation, selection(budget.light))
    }

    fn record(
        &self,
        scenario: &Scenario,
        axis: &str,
        budget: Budget,
        truth: &Array2<f64>,
        got: &Array2<f32>,
    ) -> Result<DynamicRecord> {
        let o = self.scene.options();
        let error = RelativeError::between(got.mapv(f64::from).view(), truth.view())?;
        Ok(DynamicRecord {
            scene: scenario.name.clone(),
            axis: axis.into(),
            vertices: self.scene.vertex_count(),
            objects: self.scene.object_count(),
            resolution: self.scene.param().face_size(),
            field_samples: o.field.samples(),
            keep_light: budget.light,
            keep_visibility: budget.visibility,
            keep_field: budget.field,
            truncation: match o.truncation {
                Truncation::Before => "before".into(),
                Truncation::After(_) => "after".into(),
            },
            depth: o
                .depth
                .unwrap_or(self.scene.param().face_size().trailing_zeros() as usize),
            change: "object".into(),
            rms_relative: error.rms_relative,
            max_relative: error.max_relative,
            rms: error.rms,
            field_seconds: self.scene.report().field_seconds,
            field_bytes: self.scene.report().field_bytes,
            reform_seconds: 0.0,
            frame_seconds: 0.0,
            product_coefficients: 0.0,
        })
    }

    /// Forms the transfer for the moving object, moves it, shades the frame.
    fn measure(
        &self,
        scenario: &Scenario,
        env: &Environment,
        rotation: &SphereRotation,
        truth: &Array2<f64>,
        axis: &str,
        budget: Budget,
    ) -> Result<DynamicRecord> {
        let lighting = self.lighting(env, rotation, budget)?;
        let mut scene = self.scene.clone();
        let start = Instant::now();
        let jrt = JustInTimeTransfer::<f32>::form(&scene, &lighting, Change::Object(self.moving))?;
        let reform = start.elapsed().as_secs_f64();
        scene.place(self.moving, self.target)?;
        let start = Instant::now();
        let got = jrt.frame_moved(&scene)?;
        let frame = start.elapsed().as_secs_f64();
        let mut r = self.record(scenario, axis, budget, truth, &got)?;
        r.reform_seconds = reform;
        r.frame_seconds = frame;
        r.product_coefficients = jrt.report().coefficients as f64 / scene.vertex_count() as f64;
        Ok(r)
    }

    /// The floor under every field figure: the moved scene precomputed as a static scene
    /// (own transport ray-cast against every object, issue 8's path), all coefficients kept.
    fn measure_static(
        &self,
        env: &Environment,
        rotation: &SphereRotation,
        truth: &Array2<f64>,
        scenario: &Scenario,
    ) -> Result<DynamicRecord> {
        let mut scene = self.scene.clone();
        scene.place(self.moving, self.target)?;
        let mesh = scene.mesh();
        let param = scene.param();
        let start = Instant::now();
        let (set, _) = vertex_major(&mesh, &SceneBvh::new(&mesh), &VisibilityOptions::new(param))?;
        let reform = start.elapsed().as_secs_f64();
        // The default spec: Lambertian Haar in f32, every coefficient.
        let albedo = scene.albedo();
        let input = ShadingInput::new(&mesh, albedo.view(), Some(&set), mesh.vertex_count());
        let frame = FrameSpec {
            environment: env,
            rotation: *rotation,
            eye: None,
        };
        let shading = ShaderSpec::default().build(&input)?.shade(&frame)?;
        let got = shading.radiance.to_f32();
        let frame = shading.timing.total_seconds();
        let mut r = Built {
            scene,
            moving: self.moving,
            target: self.target,
        }
        .record(scenario, "static", Budget::ALL, truth, &got)?;
        r.change = "none".into();
        (r.field_seconds, r.field_bytes) = (0.0, 0);
        r.reform_seconds = reform;
        r.frame_seconds = frame;
        r.product_coefficients = set.coefficient_count() as f64 / r.vertices as f64;
        Ok(r)
    }

    /// The moved scene with the transfer formed for a change of lighting.
    fn measure_lighting(
        &self,
        env: &Environment,
        rotation: &SphereRotation,
        truth: &Array2<f64>,
        budget: Budget,
        scenario: &Scenario,
    ) -> Result<DynamicRecord> {
        let mut scene = self.scene.clone();
        scene.place(self.moving, self.target)?;
        let lighting = self.lighting(env, rotation, budget)?;
        let start = Instant::now();
        let jrt = JustInTimeTransfer::<f32>::form(&scene, &lighting, Change::Lighting)?;
        let reform = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let lighting = self.lighting(env, rotation, budget)?;
        let got = jrt.frame_lit(&scene, &lighting)?;
        let frame = start.elapsed().as_secs_f64();
        let mut r = Built {
            scene,
            moving: self.moving,
            target: self.target,
        }
        .record(scenario, "change", budget, truth, &got)?;
        r.change = "lighting".into();
        r.reform_seconds = reform;
        r.frame_seconds = frame;
        r.product_coefficients = jrt.report().coefficients as f64 / r.vertices as f64;
        Ok(r)
    }
}

#[cfg(test)]
#[path = "moving_objects_tests.rs"]
mod tests;
