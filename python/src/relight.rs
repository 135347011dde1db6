//! `haarshift.relight`: scenes precomputed into caches and shaded per vertex as
//! `haarshift relight precompute` and `relight render` do it, and dynamic scene files relit as
//! `relight scene` relights them. Every shading goes through the library's one `Shader`.

use std::collections::HashMap;
use std::path::PathBuf;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift::sphere::{LatLongMap, SphereRotation};
use haarshift_relight::dynamic::{DynamicBudgets, DynamicOptions, DynamicScene};
use haarshift_relight::light::environment::Environment;
use haarshift_relight::precompute::request::{
    DEFAULT_RESOLUTION, Outcome, PrecomputeRequest, SceneInput,
};
use haarshift_relight::precompute::shard::{Shard, ShardSpec};
use haarshift_relight::precompute::{DEFAULT_MAP_SIZE, Order};
use haarshift_relight::render::view::ViewSpec;
use haarshift_relight::scene::validate::{DEFAULT_MEMORY_LIMIT, parse_memory_limit};
use haarshift_relight::shade::dynamic_scene::{DynamicMethod, DynamicShader};
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::{
    FrameSpec, LightSpec, Method, ShadeOptions, Shader as LibraryShader, ShaderSpec, ShadingInput,
};
use haarshift_relight::{Brdf, EnvironmentSpec, RayTracer, SceneCache, merge_shards};
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;

use crate::arrays::ArrayArg;
use crate::errors::{OrRaise, bad_argument};
use crate::options::parse;

/// The lighting: a file, or a lat-long array.
fn environment(env: &Bound<'_, PyAny>) -> PyResult<Environment> {
    if let Ok(path) = env.extract::<PathBuf>() {
        return Environment::load(&path).or_raise();
    }
    let map = ArrayArg::image(env, "env")?.to_float::<f64>();
    let map = match map.ndim() {
        2 => map.insert_axis(ndarray::Axis(2)),
        _ => map,
    };
    let map = map.into_dimensionality().expect("three axes");
    Ok(Environment::new(LatLongMap::new(map).or_raise()?))
}

/// Every vertex's outgoing radiance, a (V, 3) array, of the dynamic scene file `scene` (JSON:
/// meshes, materials, transforms, the environment, the camera) with its objects where the file
/// places them: what `haarshift relight scene SCENE --vertices OUT.npy` writes for one frame.
///
/// Each object gets Sun 2006's occlusion fields (`circles` x `circle_points` points on its
/// ground plane, `shells` shells of 6 x `shell_grid` x `shell_grid` points, one ray per texel
/// of a `param` map of side `resolution`), and a vertex reflects the n-function product
/// integral of its own transport, the lighting and each other object's looked-up occlusion
/// (float32). `keep_light`, `keep_visibility` and `keep_field` keep that many detail
/// coefficients of each factor (None: all). method="reference" ray-casts visibility against
/// every object instead (the ground truth, float64). `env` is a lat-long file or array,
/// default the scene file's; `yaw`, `pitch`, `roll` (degrees) turn it, default the file's.
///
/// >>> import json, os, tempfile, numpy as np, haarshift
/// >>> d = tempfile.mkdtemp(); path = os.path.join(d, "balls.json")
/// >>> ball = {"generator": {"sphere": {"cells": 4}}}
/// >>> with open(path, "w") as f:
/// ...     json.dump({"objects": [dict(ball, name="a"), dict(ball, name="b",
/// ...         transform={"translate": [2.5, 0, 0]})], "ground_plane": True}, f)
/// >>> sky = np.ones((16, 32))
/// >>> fields = dict(resolution=8, circles=20, circle_points=40, shells=6, shell_grid=5)
/// >>> v = haarshift.relight.scene(path, env=sky, **fields)
/// >>> v.shape, v.dtype
/// ((1389, 3), dtype('float32'))
/// >>> truth = haarshift.relight.scene(path, env=sky, method="reference", resolution=8)
/// >>> bool(np.sqrt(((v - truth) ** 2).mean() / (truth ** 2).mean()) < 0.02)  # 0.013
/// True
#[pyfunction]
#[pyo3(signature = (scene, *, env = None, yaw = None, pitch = None, roll = None, method = "haar", param = "latlong", resolution = 32, keep_light = None, keep_visibility = None, keep_field = None, circles = 100, circle_points = 200, shells = 20, shell_grid = 9))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
fn scene<'py>(
    py: Python<'py>,
    scene: PathBuf,
    env: Option<&Bound<'py, PyAny>>,
    yaw: Option<f64>,
    pitch: Option<f64>,
    roll: Option<f64>,
    method: &str,
    param: &str,
    resolution: usize,
    keep_light: Option<usize>,
    keep_visibility: Option<usize>,
    keep_field: Option<usize>,
    circles: usize,
    circle_points: usize,
    shells: usize,
    shell_grid: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let method = parse::<DynamicMethod>(method)?;
    let param = Parameterization::new(parse::<ParamKind>(param)?, resolution).or_raise()?;
    let options = DynamicOptions::from_budgets(&DynamicBudgets {
        keep_visibility,
        keep_field,
        circles,
        circle_points,
        shells,
        shell_grid,
        ..DynamicBudgets::new(param)
    });
    let given = env.map(environment).transpose()?;
    let light = LightSpec {
        env: None,
        yaw,
        pitch,
        roll,
    };
    let keep_light = keep_light.map_or(Selection::All, Selection::Largest);
    let shading = py.detach(|| -> haarshift_relight::Result<_> {
        let built = DynamicScene::load(&scene, &options)?;
        let (env, angles) = lighting(&light, given, built.environment.as_ref())?;
        DynamicShader::new(&built, method, keep_light).shade(&FrameSpec {
            environment: &env,
            rotation: SphereRotation::from_degrees(angles[0], angles[1], angles[2])?,
            eye: None,
        })
    });
    Ok(radiance_array(py, shading.or_raise()?.radiance))
}

/// The lighting of a frame: `given` (an array or a file read), else the scene file's, with the
/// angles of `light` resolved against the file's.
fn lighting(
    light: &LightSpec,
    given: Option<Environment>,
    file: Option<&EnvironmentSpec>,
) -> haarshift_relight::Result<(Environment, [f64; 3])> {
    match given {
        Some(env) => Ok((env, light.angles(file))),
        None if file.is_none() => Err(haarshift_relight::Error::parameter(
            "env",
            "give env= (the scene names no environment)",
        )),
        None => light.load(file),
    }
}

/// Radiance as numpy, in the precision it was computed in.
fn radiance_array(
    py: Python<'_>,
    radiance: haarshift_relight::shade::Radiance,
) -> Bound<'_, PyAny> {
    use haarshift_relight::shade::Radiance;
    match radiance {
        Radiance::F32(r) => r.into_pyarray(py).into_any(),
        Radiance::F64(r) => r.into_pyarray(py).into_any(),
    }
}

/// A precomputed scene: its mesh, albedo and every vertex's transport, as the `.hsr` file
/// `haarshift relight precompute` writes holds it.
///
/// >>> import json, os, tempfile, numpy as np, haarshift
/// >>> d = tempfile.mkdtemp(); path = os.path.join(d, "ball.json")
/// >>> with open(path, "w") as f:
/// ...     json.dump({"objects": [{"generator": {"sphere": {"cells": 2}}}]}, f)
/// >>> cache = haarshift.relight.precompute(path, resolution=8, output=os.path.join(d, "ball.hsr"))
/// >>> cache.vertex_count, cache.positions.shape, cache.triangles.dtype
/// (54, (54, 3), dtype('uint32'))
/// >>> again = haarshift.relight.Cache.read(os.path.join(d, "ball.hsr"))
/// >>> bool(np.array_equal(again.albedo, cache.albedo))
/// True
#[pyclass(module = "haarshift.relight", frozen)]
pub struct Cache {
    cache: SceneCache,
    path: Option<PathBuf>,
}

#[pymethods]
impl Cache {
    /// Reads a cache file (`.hsr`), refusing a damaged one or another format version. The
    /// file is memory-mapped and its transport read in place, not copied.
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let cache = py.detach(|| SceneCache::read(&path)).or_raise()?;
        Ok(Cache {
            cache,
            path: Some(path),
        })
    }

    /// Writes the cache to `path` (atomically; an existing file only with `force=True`);
    /// returns the bytes written.
    #[pyo3(signature = (path, *, force = false))]
    fn write(&self, py: Python<'_>, path: PathBuf, force: bool) -> PyResult<u64> {
        py.detach(|| self.cache.write(&path, force)).or_raise()
    }

    /// The bounces of interreflected light the cache holds beside its direct transport (0:
    /// direct light alone).
    ///
    /// >>> import json, os, tempfile, haarshift
    /// >>> d = tempfile.mkdtemp(); path = os.path.join(d, "box.json")
    /// >>> with open(path, "w") as f:
    /// ...     json.dump({"objects": [{"generator": {"box": {"cells": 1}}}]}, f)
    /// >>> haarshift.relight.precompute(path, resolution=4, bounces=2).bounces
    /// 2
    #[getter]
    fn bounces(&self) -> usize {
        self.cache.params.bounces
    }

    /// The number of vertices, the ground plane's (if any) last.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.cache.mesh.vertex_count()
    }

    /// The vertices of the objects (those before the ground plane's).
    #[getter]
    fn object_vertices(&self) -> usize {
        self.cache.object_vertices()
    }

    /// Vertex positions, (V, 3) float64.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.cache.mesh.positions().to_owned().into_pyarray(py)
    }

    /// Unit vertex normals, (V, 3) float64.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.cache.mesh.normals().to_owned().into_pyarray(py)
    }

    /// Triangles as vertex indices, (T, 3) uint32.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        let t = self.cache.mesh.triangles();
        ndarray::Array2::from_shape_fn((t.len(), 3), |(i, k)| t[i][k]).into_pyarray(py)
    }

    /// RGB albedo per vertex, (V, 3) float32.
    #[getter]
    fn albedo<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        self.cache.albedo.clone().into_pyarray(py)
    }

    /// The parameterisation (`"latlong"` or `"cube"`) and its face size.
    #[getter]
    fn param(&self) -> (String, usize) {
        let p = self.cache.transport.param();
        (p.kind().to_string(), p.face_size())
    }

    /// The ray tracer that cast the visibility (`"embree"` or `"packets"`; None for the
    /// direction order's shadow buffers).
    #[getter]
    fn ray_tracer(&self) -> Option<String> {
        self.cache.params.ray_tracer.clone()
    }

    /// Spherical-harmonic bands stored beside the Haar transport (None: none).
    #[getter]
    fn sh_bands(&self) -> Option<usize> {
        self.cache.transport.sh().map(|t| t.bands())
    }

    fn __repr__(&self) -> String {
        let (kind, n) = self.param();
        format!(
            "Cache({} vertices, {kind} {n}{})",
            self.vertex_count(),
            self.path
                .as_ref()
                .map_or(String::new(), |p| format!(", {}", p.display()))
        )
    }
}

/// Precomputes `scene` (a mesh .obj/.ply/.gltf/.glb or a scene file .json) as `haarshift
/// relight precompute` does, through the same library request: every keyword is the command
/// line's flag of the same name (`--visibility-samples` is `visibility_samples`, `-o` is
/// `output`), with its default, its checks and its messages, all made before any work. Every
/// vertex's visibility x cosine over a `param` map of side `resolution`, Haar-transformed and
/// truncated to `keep_visibility` detail coefficients (None: all), with `sh_bands` bands of
/// spherical harmonics beside it when asked. With `output` the cache is also written there
/// (an existing file only with `force=True`). What the mesh files approximated (a glossy glTF
/// material taken as its base colour) is a `UserWarning`, one a line, as the command line
/// prints it.
///
/// `memory_limit` is bytes (an int) or a size as the command line writes it (`"8GiB"`,
/// `"512 MiB"`; None: 4 GiB): a scene or transport that would need more is refused
/// (`MemoryError`) before it is built.
///
/// With `shard="i/n"` (or `(i, n)`) only shard `i` of `n` is computed (the vertices `[i V / n,
/// (i + 1) V / n)`, traced against the whole scene, the bits an unsharded run gives them),
/// written to `output` (required), and `output` is returned as a string, so that a task on a
/// Dask or Ray worker returns a path; an `output` that already holds this shard complete is
/// not computed again (`force=True` recomputes it). `shard="auto"` reads it from a Slurm
/// array job or a Kubernetes Indexed Job (with `shards=N`, the Job's completions). `merge`
/// joins the shards. `bounces` with a shard adds one bounce to the merged cache `bounce_from`.
///
/// `ground_cells` (with `ground_plane=True`, default 32) is the ground plane's cells per side.
///
/// `ray_tracer` is `"embree"` (Intel Embree 3, the default where the system's
/// libembree3.so.3 loads at run time; refused with what to install where it does not) or
/// `"packets"` (haarshift's own, always available); the two answer alike except on rays
/// through a triangle's edge. The cache records the one that cast (`Cache.ray_tracer`).
/// `order="direction"` casts with shadow buffers of side `map_size` instead.
///
/// `bounces` (0 to 8) also gathers that many bounces of interreflected light over the same
/// rays and stores their sum beside the transport (`Cache.bounces`).
///
/// `refine=TOL` splits the edges whose ends' transports differ by more than TOL (in (0, 2]),
/// up to `max_vertices`, judged under the lighting `refine_light` (a file) when given.
///
/// >>> import json, os, tempfile, haarshift
/// >>> d = tempfile.mkdtemp(); path = os.path.join(d, "ball.json")
/// >>> with open(path, "w") as f:
/// ...     json.dump({"objects": [{"generator": {"sphere": {"cells": 2}}}]}, f)
/// >>> parts = [haarshift.relight.precompute(path, resolution=8, shard=f"{i}/2",
/// ...          output=os.path.join(d, f"part-{i}.hsr")) for i in range(2)]
/// >>> merged = haarshift.relight.merge(parts, output=os.path.join(d, "ball.hsr"))
/// >>> whole = haarshift.relight.precompute(path, resolution=8, output=os.path.join(d, "whole.hsr"))
/// >>> open(os.path.join(d, "ball.hsr"), "rb").read() == open(os.path.join(d, "whole.hsr"), "rb").read()
/// True
/// >>> haarshift.relight.precompute(path, resolution=8, refine=0.3, max_vertices=80).vertex_count
/// 80
/// >>> try:
/// ...     haarshift.relight.precompute(path, resolution=8, refine=3.0)
/// ... except ValueError as e:
/// ...     print(e)
/// invalid refine: 3: the tolerance is a fraction of an unoccluded vertex's transport, in (0, 2]
#[pyfunction]
#[pyo3(signature = (scene, *, output = None, param = "latlong", resolution = DEFAULT_RESOLUTION, keep_visibility = None, visibility_samples = 1, seed = 0, order = "vertex", ray_tracer = None, map_size = DEFAULT_MAP_SIZE, sh_bands = None, bounces = 0, bounce_from = None, refine = None, max_vertices = None, refine_light = None, shard = None, shards = None, force = false, ground_plane = false, ground_cells = None, memory_limit = None))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
fn precompute(
    py: Python<'_>,
    scene: PathBuf,
    output: Option<PathBuf>,
    param: &str,
    resolution: usize,
    keep_visibility: Option<usize>,
    visibility_samples: usize,
    seed: u64,
    order: &str,
    ray_tracer: Option<&str>,
    map_size: usize,
    sh_bands: Option<usize>,
    bounces: usize,
    bounce_from: Option<PathBuf>,
    refine: Option<f64>,
    max_vertices: Option<usize>,
    refine_light: Option<PathBuf>,
    shard: Option<&Bound<'_, PyAny>>,
    shards: Option<usize>,
    force: bool,
    ground_plane: bool,
    ground_cells: Option<usize>,
    memory_limit: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let request = PrecomputeRequest {
        output,
        param: parse::<ParamKind>(param)?,
        resolution,
        keep_visibility,
        visibility_samples,
        seed,
        order: parse::<Order>(order)?,
        ray_tracer: ray_tracer.map(parse::<RayTracer>).transpose()?,
        map_size,
        sh_bands,
        bounces,
        bounce_from,
        refine,
        max_vertices,
        refine_light,
        shard: shard.map(shard_spec).transpose()?,
        shards,
        force,
        ground_plane,
        ground_cells,
        memory_limit: match memory_limit {
            Some(limit) => memory_size(limit)?,
            None => DEFAULT_MEMORY_LIMIT,
        },
        ..PrecomputeRequest::new(SceneInput::File(scene))
    };
    // Checked in full before the scene is read.
    let run = py.detach(|| request.run()).or_raise()?;
    let warning = py.get_type::<PyUserWarning>();
    for text in &run.warnings {
        let text = std::ffi::CString::new(text.replace('\0', " "))?;
        PyErr::warn(py, &warning, &text, 1)?;
    }
    match run.outcome {
        Outcome::Whole { cache, .. } => {
            let cache = Cache {
                cache: *cache,
                path: request.output,
            };
            Ok(Py::new(py, cache)?.into_any())
        }
        Outcome::Shard { .. } | Outcome::Skipped { .. } => {
            let path = request.output.unwrap_or_default();
            Ok(path.into_pyobject(py)?.str()?.into_any().unbind())
        }
    }
}

/// `shard`: `"I/N"` or `"auto"` as the command line's `--shard` takes it, or a pair `(i, n)`.
fn shard_spec(value: &Bound<'_, PyAny>) -> PyResult<ShardSpec> {
    if let Ok(text) = value.extract::<String>() {
        return parse(&text);
    }
    match value.extract::<(usize, usize)>() {
        Ok((index, count)) => Ok(ShardSpec::Given(Shard::new(index, count).or_raise()?)),
        Err(_) => Err(bad_argument(
            "shard",
            format!(
                "{} is neither \"I/N\", \"auto\" nor a pair (i, n)",
                value.repr()?
            ),
        )),
    }
}

/// `memory_limit`: bytes, or a size such as `"8GiB"` read as `--memory-limit` reads it.
fn memory_size(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    if let Ok(text) = value.extract::<String>() {
        return parse_memory_limit(&text).or_raise();
    }
    match value.extract::<u64>() {
        Ok(bytes) => Ok(bytes),
        Err(_) => Err(bad_argument(
            "memory_limit",
            format!(
                "{} is neither bytes nor a size such as \"8GiB\"",
                value.repr()?
            ),
        )),
    }
}

/// Merges the shard files `shards` (any order) into the cache an unsharded `precompute`
/// makes, as `haarshift relight merge` does: refused, naming the file, unless they come from
/// the same scene and options and cover every vertex exactly once. With `output` the cache is
/// written there too (an existing file only with `force=True`), byte for byte the file an
/// unsharded run writes.
///
/// >>> import json, os, tempfile, haarshift
/// >>> d = tempfile.mkdtemp(); path = os.path.join(d, "ball.json")
/// >>> with open(path, "w") as f:
/// ...     json.dump({"objects": [{"generator": {"sphere": {"cells": 2}}}]}, f)
/// >>> parts = [haarshift.relight.precompute(path, resolution=8, shard=(i, 3),
/// ...          output=os.path.join(d, f"part-{i}.hsr")) for i in range(3)]
/// >>> haarshift.relight.merge(parts).vertex_count
/// 54
/// >>> try:
/// ...     haarshift.relight.merge(parts[:2])
/// ... except OSError as e:
/// ...     print(str(e).split(": ", 1)[1])
/// the shards do not cover every vertex exactly once: vertices 36..54 are in no shard (after shard 1/3)
#[pyfunction]
#[pyo3(signature = (shards, *, output = None, force = false))]
fn merge(
    py: Python<'_>,
    shards: Vec<PathBuf>,
    output: Option<PathBuf>,
    force: bool,
) -> PyResult<Cache> {
    let cache = py
        .detach(|| -> haarshift_relight::Result<_> {
            if let Some(path) = &output {
                for shard in &shards {
                    haarshift::io::ensure_distinct_paths(shard, path)?;
                }
                if !force && path.exists() {
                    return Err(haarshift::Error::OutputExists { path: path.clone() }.into());
                }
            }
            let cache = merge_shards(&shards)?;
            if let Some(path) = &output {
                cache.write(path, force)?;
            }
            Ok(cache)
        })
        .or_raise()?;
    Ok(Cache {
        cache,
        path: output,
    })
}

/// A way of shading a cache's vertices, built once from the same options as `haarshift
/// relight render` takes and asked for frame after frame (a glossy shader keeps its rotation
/// cache between frames).
///
/// `basis`: "haar", "sh" (the stored spherical-harmonic transfer), "reference" (direct
/// quadrature with ray casting at the cache's resolution) or "ambient" (ambient occlusion).
/// `brdf`: "lambert", "phong:EXP", "blinn:EXP" or "merl:FILE". The other keywords are the
/// command line's flags of the same names.
#[pyclass(module = "haarshift.relight")]
pub struct Shader {
    /// Locked only to be shared with Python's threads: each call has it to itself.
    shader: std::sync::Mutex<Box<dyn LibraryShader>>,
    mesh: haarshift_relight::Mesh,
    environment: Option<EnvironmentSpec>,
    camera: Option<haarshift_relight::CameraSpec>,
}

/// A shading's radiance (a numpy array) and its timing report.
type ShadeResult<'py> = (Bound<'py, PyAny>, HashMap<String, Py<PyAny>>);

#[pymethods]
impl Shader {
    #[new]
    #[pyo3(signature = (cache, *, basis = "haar", brdf = "lambert", albedo = None, keep_light = None, keep_visibility = None, depth = None, brdf_rotation = "haar", level = None, keep_brdf = None, brdf_levels = None, rotation_cache = None, elevations = haarshift_relight::material::brdf::DEFAULT_ELEVATIONS, fill_cache = false, light_rotation = "source"))]
    #[allow(clippy::too_many_arguments)] // the keyword arguments of one Python class
    fn new(
        py: Python<'_>,
        cache: &Cache,
        basis: &str,
        brdf: &str,
        albedo: Option<[f64; 3]>,
        keep_light: Option<usize>,
        keep_visibility: Option<usize>,
        depth: Option<usize>,
        brdf_rotation: &str,
        level: Option<usize>,
        keep_brdf: Option<usize>,
        brdf_levels: Option<usize>,
        rotation_cache: Option<usize>,
        elevations: usize,
        fill_cache: bool,
        light_rotation: &str,
    ) -> PyResult<Self> {
        let spec = ShaderSpec {
            method: parse::<Method>(basis)?,
            material: GlossyOptions {
                brdf: parse::<Brdf>(brdf)?,
                rotation: parse(brdf_rotation)?,
                level,
                keep_brdf,
                brdf_levels,
                cache_bins: rotation_cache,
                elevations,
            },
            fill_cache,
            shade: ShadeOptions {
                keep_visibility: keep_visibility.map(Selection::Largest),
                depth,
            },
            keep_light: keep_light.map_or(Selection::All, Selection::Largest),
            light_rotation: parse(light_rotation)?,
            ..ShaderSpec::default()
        };
        let source = &cache.cache;
        let painted = match albedo {
            Some(a) if a.iter().any(|x| !(0.0..=1.0).contains(x)) => {
                return Err(bad_argument(
                    "albedo",
                    format!("{a:?}: every channel must be from 0 to 1"),
                ));
            }
            Some(a) => Some(ndarray::Array2::from_shape_fn(
                (source.mesh.vertex_count(), 3),
                |(_, c)| a[c] as f32,
            )),
            None => None,
        };
        let shader = py
            .detach(|| {
                let mut input = ShadingInput::cache(source);
                if let Some(a) = &painted {
                    input.albedo = a.view();
                }
                if let Some(path) = &cache.path {
                    input = input.from_file(path);
                }
                spec.build(&input)
            })
            .or_raise()?;
        Ok(Shader {
            shader: std::sync::Mutex::new(shader),
            mesh: source.mesh.clone(),
            environment: source.environment.clone(),
            camera: source.camera.clone(),
        })
    }

    /// Every vertex's outgoing radiance (V, 3) under `env` (a lat-long file or array; default
    /// the scene file's) turned by `yaw`, `pitch`, `roll` degrees (default the scene file's),
    /// seen from `eye` (default the scene file's camera, else the one that frames the scene,
    /// as `relight render` places it), and the timing report: a dict of `encode_seconds`,
    /// `rotate_seconds`, `shade_seconds` and `description`.
    #[pyo3(signature = (env = None, *, yaw = None, pitch = None, roll = None, eye = None))]
    fn shade<'py>(
        &mut self,
        py: Python<'py>,
        env: Option<&Bound<'py, PyAny>>,
        yaw: Option<f64>,
        pitch: Option<f64>,
        roll: Option<f64>,
        eye: Option<[f64; 3]>,
    ) -> PyResult<ShadeResult<'py>> {
        if let Some(e) = eye
            && !e.iter().all(|x| x.is_finite())
        {
            return Err(bad_argument(
                "eye",
                format!("{e:?} is not a finite position"),
            ));
        }
        let given = env.map(environment).transpose()?;
        let light = LightSpec {
            env: None,
            yaw,
            pitch,
            roll,
        };
        let shader = self
            .shader
            .get_mut()
            .map_err(|_| bad_argument("shader", "a previous call panicked"))?;
        let (mesh, file, camera) = (&self.mesh, self.environment.as_ref(), self.camera.as_ref());
        let shading = py
            .detach(|| -> haarshift_relight::Result<_> {
                let (env, angles) = lighting(&light, given, file)?;
                let eye = match eye {
                    Some(e) => e,
                    None => ViewSpec::default().camera(camera, mesh)?.position(),
                };
                shader.shade(&FrameSpec {
                    environment: &env,
                    rotation: SphereRotation::from_degrees(angles[0], angles[1], angles[2])?,
                    eye: Some(eye),
                })
            })
            .or_raise()?;
        let mut report: HashMap<String, Py<PyAny>> = HashMap::new();
        let t = shading.timing;
        for (key, seconds) in [
            ("encode_seconds", t.encode_seconds),
            ("rotate_seconds", t.rotate_seconds),
            ("shade_seconds", t.shade_seconds),
        ] {
            report.insert(key.into(), seconds.into_pyobject(py)?.into_any().unbind());
        }
        report.insert(
            "description".into(),
            shading.description.into_pyobject(py)?.into_any().unbind(),
        );
        Ok((radiance_array(py, shading.radiance), report))
    }
}

/// The `haarshift.relight` submodule.
pub fn module<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyModule>> {
    let m = PyModule::new(py, "relight")?;
    m.add_function(wrap_pyfunction!(scene, &m)?)?;
    m.add_function(wrap_pyfunction!(precompute, &m)?)?;
    m.add_function(wrap_pyfunction!(merge, &m)?)?;
    m.add_class::<Cache>()?;
    m.add_class::<Shader>()?;
    Ok(m)
}
