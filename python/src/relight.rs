//! `haarshift.relight`: a dynamic scene file relit per vertex, as `haarshift relight scene`
//! relights it.

use std::path::PathBuf;

use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift::relight::Lighting;
use haarshift::relight::dynamic::{DynamicOptions, DynamicScene};
use haarshift::relight::light::environment::Environment;
use haarshift::sphere::{LatLongMap, SphereRotation};
use numpy::IntoPyArray;
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
/// Each object gets seed 001's occlusion fields (`circles` x `circle_points` points on its
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
    let reference = match method {
        "haar" => false,
        "reference" => true,
        other => {
            return Err(bad_argument(
                "method",
                format!("unknown value {other:?} (expected one of: haar, reference)"),
            ));
        }
    };
    let param = Parameterization::new(parse::<ParamKind>(param)?, resolution).or_raise()?;
    let largest = |k: Option<usize>| k.map_or(Selection::All, Selection::Largest);
    let mut options = DynamicOptions::new(param);
    options.keep_visibility = largest(keep_visibility);
    options.field.keep = largest(keep_field);
    options.field.circles = circles;
    options.field.circle_points = circle_points;
    options.field.shells = shells;
    options.field.shell_grid = shell_grid;
    let given = env.map(environment).transpose()?;
    let radiance = py.detach(|| -> haarshift::Result<_> {
        let built = DynamicScene::load(&scene, &options)?;
        let file = built.environment.as_ref();
        let env = match (given, file) {
            (Some(env), _) => env,
            (None, Some(spec)) => Environment::load(&spec.path)?,
            (None, None) => {
                return Err(haarshift::Error::InvalidParameter {
                    name: "env",
                    reason: "give env= (the scene names no environment)".into(),
                });
            }
        };
        let in_file = file.map_or([0.0; 3], |s| [s.yaw, s.pitch, s.roll]);
        let turn = SphereRotation::from_degrees(
            yaw.unwrap_or(in_file[0]),
            pitch.unwrap_or(in_file[1]),
            roll.unwrap_or(in_file[2]),
        )?;
        Ok(if reference {
            Radiance::Truth(built.reference(&env.lat_long(param.face_size(), &turn)?)?)
        } else {
            let lighting = Lighting::new(&env, param, &turn, largest(keep_light))?;
            Radiance::Haar(built.shade::<f32>(&lighting)?)
        })
    });
    Ok(match radiance.or_raise()? {
        Radiance::Haar(haar) => haar.into_pyarray(py).into_any(),
        Radiance::Truth(truth) => truth.into_pyarray(py).into_any(),
    })
}

/// Per-vertex radiance by either method, in its own precision.
enum Radiance {
    Haar(ndarray::Array2<f32>),
    Truth(ndarray::Array2<f64>),
}

/// The `haarshift.relight` submodule.
pub fn module<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyModule>> {
    let m = PyModule::new(py, "relight")?;
    m.add_function(wrap_pyfunction!(scene, &m)?)?;
    Ok(m)
}
