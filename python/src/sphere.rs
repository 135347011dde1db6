//! `haarshift.sphere`: lat-long maps rotated, integrated and multiplied through their Haar
//! coefficients.

use haarshift::faces::ParamKind;
use haarshift::faces::integrate::{IntegralMethod, IntegrateOptions, integrate as integrate_maps};
use haarshift::faces::map_product::{ProductOptions, map_product};
use haarshift::product::Selection;
use haarshift::sphere::{LatLongMap, Method, SphereOptions, SphereRotation, rotate_map};
use haarshift::{Sample, round_to_code};
use ndarray::{Array3, ArrayD, Axis, Ix2, Ix3};
use numpy::{Element, IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PySequence;

use crate::arrays::{ArrayArg, Code};
use crate::errors::{OrRaise, bad_argument};
use crate::options::parse;

/// `data` ((H, W) or (H, W, C)) as a lat-long map.
fn lat_long<T: Sample>(data: ArrayD<T>) -> haarshift::Result<LatLongMap<T>> {
    let data: Array3<T> = match data.ndim() {
        2 => data
            .into_dimensionality::<Ix2>()
            .expect("two axes")
            .insert_axis(Axis(2)),
        _ => data.into_dimensionality::<Ix3>().expect("three axes"),
    };
    LatLongMap::new(data)
}

/// A map's array for Python: `(H, W)` when the input was 2D, else `(H, W, C)`.
fn map_out<'py, T: Element>(
    py: Python<'py>,
    data: Array3<T>,
    two_dimensional: bool,
) -> Bound<'py, PyAny> {
    if two_dimensional {
        data.index_axis_move(Axis(2), 0).into_pyarray(py).into_any()
    } else {
        data.into_pyarray(py).into_any()
    }
}

/// rotate(map, yaw=0.0, pitch=0.0, roll=0.0, *, method="haar", level=None, samples=8)
///
/// The lat-long map rotated, `g(p) = f(R p)`, as `haarshift sphere rotate` rotates it.
///
/// `map` is (H, 2H) or (H, 2H, C) with H a power of two: row i is the elevation from +Y (up),
/// column j the azimuth, pixel centres at theta = (i + 0.5) pi / H, phi = (j + 0.5) 2 pi / W,
/// and the direction (sin theta sin phi, cos theta, sin theta cos phi). Angles in degrees:
/// yaw about +Y, pitch about +X, roll about +Z, R = Rz(roll) Ry(yaw) Rx(pitch). `method`
/// "haar" (the chain rule on the Haar details), "haar-cubic", "bilinear", "bicubic" or
/// "reference" (solid-angle integration with `samples` x `samples` lookups a pixel). `level`
/// L computes detail levels 0..=L only (blocks of equal pixels above). A yaw by whole columns
/// is an exact shift. float32 and float64 are kept; uint8 and uint16 are computed in float32
/// and rounded back to codes.
///
/// >>> import numpy as np, haarshift
/// >>> m = np.zeros((4, 8)); m[:, 0] = 1.0
/// >>> haarshift.sphere.rotate(m, yaw=-45.0)[0]  # one column: exact
/// array([0., 1., 0., 0., 0., 0., 0., 0.])
#[pyfunction]
#[pyo3(signature = (map, yaw = 0.0, pitch = 0.0, roll = 0.0, *, method = "haar", level = None, samples = 8))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
fn rotate<'py>(
    py: Python<'py>,
    map: &Bound<'py, PyAny>,
    yaw: f64,
    pitch: f64,
    roll: f64,
    method: &str,
    level: Option<usize>,
    samples: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let rotation = SphereRotation::from_degrees(yaw, pitch, roll).or_raise()?;
    let options = SphereOptions {
        method: parse::<Method>(method)?,
        level,
        reference_samples: samples,
    };
    let map = ArrayArg::image(map, "map")?;
    let flat = map.shape().len() == 2;
    let (rotation, options) = (&rotation, &options);
    Ok(match &map {
        ArrayArg::F32(a) => map_out(
            py,
            rotated(py, a.as_array().to_owned(), rotation, options)?,
            flat,
        ),
        ArrayArg::F64(a) => map_out(
            py,
            rotated(py, a.as_array().to_owned(), rotation, options)?,
            flat,
        ),
        ArrayArg::U8(_) => {
            let floats = rotated::<f32>(py, map.to_float(), rotation, options)?;
            map_out(py, to_codes::<u8>(floats), flat)
        }
        ArrayArg::U16(_) => {
            let floats = rotated::<f32>(py, map.to_float(), rotation, options)?;
            map_out(py, to_codes::<u16>(floats), flat)
        }
    })
}

/// `data` as a lat-long map, rotated with the GIL released.
fn rotated<T: Sample>(
    py: Python<'_>,
    data: ArrayD<T>,
    rotation: &SphereRotation,
    options: &SphereOptions,
) -> PyResult<Array3<T>> {
    let result = py.detach(|| rotate_map(&lat_long(data)?, rotation, options));
    Ok(result.or_raise()?.map.into_array())
}

/// `f32` samples rounded to the nearest code and clamped.
fn to_codes<C: Code>(data: Array3<f32>) -> Array3<C> {
    data.mapv(|v| C::from_rounded(round_to_code(v, C::MAX)))
}

/// The maps of `integrate` and `product`, each as an array, and whether any is float64.
fn map_args<'py>(maps: &Bound<'py, PyAny>) -> PyResult<(Vec<ArrayArg<'py>>, bool)> {
    let sequence = maps
        .cast::<PySequence>()
        .map_err(|_| bad_argument("maps", "expected a sequence of lat-long arrays"))?;
    let mut out = Vec::new();
    for (i, item) in sequence.try_iter()?.enumerate() {
        out.push(ArrayArg::image(&item?, &format!("maps[{i}]"))?);
    }
    if out.len() < 2 {
        return Err(bad_argument(
            "maps",
            format!("the product of {} map(s): give two or more", out.len()),
        ));
    }
    let double = out.iter().any(|m| matches!(m, ArrayArg::F64(_)));
    Ok((out, double))
}

/// Every map as a lat-long map of `T`.
fn lat_longs<T: Sample>(maps: &[ArrayArg<'_>]) -> haarshift::Result<Vec<LatLongMap<T>>> {
    maps.iter().map(|m| lat_long(m.to_float())).collect()
}

/// The selections of `keep` (one count for every map or one per map), `threshold` or
/// `per_face`.
fn selections(
    keep: Option<&Bound<'_, PyAny>>,
    threshold: Option<f64>,
    per_face: bool,
) -> PyResult<Vec<Selection>> {
    let keep: Vec<usize> = match keep.filter(|k| !k.is_none()) {
        None => Vec::new(),
        Some(k) => match k.extract::<usize>() {
            Ok(one) => vec![one],
            Err(_) => k.extract::<Vec<usize>>().map_err(|_| {
                bad_argument(
                    "keep",
                    "expected a count or a sequence of counts, one per map",
                )
            })?,
        },
    };
    Selection::from_counts(&keep, threshold, per_face).or_raise()
}

/// integrate(maps, *, param="latlong", resolution=None, keep=None, threshold=None, per_face=False, depth=None, method="tree")
///
/// The integral over the sphere of the product of `maps`, computed on their Haar trees, as
/// `haarshift sphere integrate` computes it: the sum over texels of f_1 x f_2 x ... x the
/// texel's solid angle.
///
/// `maps` are two or more lat-long arrays of one size, (H, 2H) or (H, 2H, C); a one-channel
/// map multiplies every channel of the others. `keep` K (or one count per map) keeps each
/// map's K largest detail coefficients (orthonormal magnitudes), `threshold` T those above T,
/// `per_face` counts per face; `param` "latlong" or "cube" (six faces, converted by
/// solid-angle integration), `resolution` the working face side. `depth` D visits detail
/// levels 0..=D only (tree method). `method` "tree", "triple" (three maps), "pixel" or
/// "pairwise". Computed in float64 when any map is float64, else float32, summed in float64.
/// Returns a float when every map is 2D, else one float per channel (a float64 array).
///
/// >>> import numpy as np, haarshift
/// >>> one = np.ones((4, 8))
/// >>> round(haarshift.sphere.integrate([one, one]), 12) == round(4 * np.pi, 12)
/// True
#[pyfunction]
#[pyo3(signature = (maps, *, param = "latlong", resolution = None, keep = None, threshold = None, per_face = false, depth = None, method = "tree"))]
#[allow(clippy::too_many_arguments)] // the keyword arguments of one Python function
fn integrate<'py>(
    py: Python<'py>,
    maps: &Bound<'py, PyAny>,
    param: &str,
    resolution: Option<usize>,
    keep: Option<&Bound<'py, PyAny>>,
    threshold: Option<f64>,
    per_face: bool,
    depth: Option<usize>,
    method: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let options = IntegrateOptions {
        param: parse::<ParamKind>(param)?,
        resolution,
        selections: selections(keep, threshold, per_face)?,
        depth,
        method: parse::<IntegralMethod>(method)?,
    };
    let (maps, double) = map_args(maps)?;
    let flat = maps.iter().all(|m| m.shape().len() == 2);
    // The maps are copied with the GIL held (they borrow numpy's arrays), then integrated
    // without it.
    let result = if double {
        let maps = lat_longs::<f64>(&maps).or_raise()?;
        py.detach(|| integrate_maps(&maps, &options))
    } else {
        let maps = lat_longs::<f32>(&maps).or_raise()?;
        py.detach(|| integrate_maps(&maps, &options))
    };
    let value = result.or_raise()?.value;
    if flat {
        return Ok(value[0].into_pyobject(py)?.into_any());
    }
    Ok(PyArray1::from_vec(py, value).into_any())
}

/// product(maps, *, param="latlong", resolution=None, keep=None, threshold=None, per_face=False)
///
/// The product of `maps` through their Haar trees (not pixel by pixel), as `haarshift sphere
/// product` computes it: with everything kept it equals the pixelwise product to rounding;
/// with `keep`, `threshold` or `per_face` (as in `integrate`) it is the product of the pruned
/// maps. With param="latlong" the result is the (N, 2N) or (N, 2N, C) product map (N the
/// working resolution, default H); with param="cube" its six faces (6, S, S, C) in the order
/// +X, -X, +Y, -Y, +Z, -Z. float64 when any map is float64, else float32.
///
/// >>> import numpy as np, haarshift
/// >>> a = np.full((4, 8), 2.0); b = np.full((4, 8), 3.0)
/// >>> float(haarshift.sphere.product([a, b])[1, 5])
/// 6.0
#[pyfunction]
#[pyo3(signature = (maps, *, param = "latlong", resolution = None, keep = None, threshold = None, per_face = false))]
fn product<'py>(
    py: Python<'py>,
    maps: &Bound<'py, PyAny>,
    param: &str,
    resolution: Option<usize>,
    keep: Option<&Bound<'py, PyAny>>,
    threshold: Option<f64>,
    per_face: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let options = ProductOptions {
        param: parse::<ParamKind>(param)?,
        resolution,
        selections: selections(keep, threshold, per_face)?,
    };
    let (maps, double) = map_args(maps)?;
    let flat = maps.iter().all(|m| m.shape().len() == 2);
    let cube = options.param == ParamKind::Cube;
    if double {
        product_as::<f64>(py, &maps, &options, flat, cube)
    } else {
        product_as::<f32>(py, &maps, &options, flat, cube)
    }
}

fn product_as<'py, T: Sample + Element>(
    py: Python<'py>,
    maps: &[ArrayArg<'_>],
    options: &ProductOptions,
    flat: bool,
    cube: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let maps = lat_longs::<T>(maps).or_raise()?;
    let result = py.detach(|| map_product(&maps, options)).or_raise()?;
    if cube {
        return Ok(result.map.into_array().into_pyarray(py).into_any());
    }
    let map = result.map.to_lat_long().or_raise()?;
    Ok(map_out(py, map.into_array(), flat))
}

/// The `haarshift.sphere` submodule.
pub fn module<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyModule>> {
    let m = PyModule::new(py, "sphere")?;
    m.add_function(wrap_pyfunction!(rotate, &m)?)?;
    m.add_function(wrap_pyfunction!(integrate, &m)?)?;
    m.add_function(wrap_pyfunction!(product, &m)?)?;
    Ok(m)
}
