//! Keyword arguments as the library's option types: names parsed as the command line parses
//! them, so that a Python caller and a command-line user meet the same words and messages.

use std::str::FromStr;

use haarshift::BoundaryMode;
use haarshift::kernels::{KernelOptions, Outside, ShiftMethod};
use haarshift::transform::Levels;

use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::errors::{OrRaise, bad_argument};

/// A name the library knows (`"bspline3"`, `"reflect"`, ...), or its `ValueError`.
pub fn parse<T: FromStr<Err: Into<haarshift_relight::Error>>>(value: &str) -> PyResult<T> {
    value.parse().or_raise()
}

/// `levels`: `"full"`, `None` (full) or a whole number.
pub fn levels(value: Option<&Bound<'_, PyAny>>) -> PyResult<Levels> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(Levels::Full);
    };
    if let Ok(text) = value.cast::<PyString>() {
        return parse(text.to_str()?);
    }
    match value.extract::<usize>() {
        Ok(k) => Ok(Levels::Count(k)),
        Err(_) => Err(bad_argument(
            "levels",
            format!("{} is neither \"full\" nor a whole number", value.repr()?),
        )),
    }
}

/// The kernel options of `method` from the keyword arguments, refusing one that `method` does
/// not take (as the command line refuses a misplaced flag).
pub fn kernel(
    method: &str,
    precision: Option<u32>,
    retain: bool,
    keys_a: Option<f64>,
) -> PyResult<(ShiftMethod, KernelOptions)> {
    let method: ShiftMethod = parse(method)?;
    let options = KernelOptions::for_method(method, precision, retain, keys_a).or_raise()?;
    Ok((method, options))
}

/// Where samples from outside the image come from: `fill` or `boundary` (not both); `None`
/// for both is a fill of 0.
pub fn outside(fill: Option<f64>, boundary: Option<&str>) -> PyResult<Outside> {
    match (fill, boundary) {
        (Some(_), Some(_)) => Err(bad_argument(
            "fill",
            "give fill or boundary, not both (boundary continues the image, fill is a constant)",
        )),
        (_, Some(mode)) => Ok(Outside::Boundary(parse::<BoundaryMode>(mode)?)),
        (fill, None) => Outside::Fill(fill.unwrap_or(0.0)).validate().or_raise(),
    }
}
