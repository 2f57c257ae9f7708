//! NumPy arrays in and out. Any array-like of numbers is accepted and
//! converted to float64 by NumPy; the libraries compute in f32, so every
//! value must be finite in f32 (checked here, with the value's place in
//! the message). Sample times are taken relative to the first in f64
//! first ([`times`]).

use std::borrow::Cow;

use numpy::ndarray::ArrayViewD;
use numpy::{
    AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use primo_skill::stamps::Stamps;

use crate::errors::invalid;

/// An array-like converted to float64, of any shape.
pub type Array<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// `v` as a finite f32; `what` and `at()` name it. The place is made
/// only on failure: formatting it for every value cost as much as a fit.
fn single(what: &str, at: impl FnOnce() -> String, v: f64) -> PyResult<f32> {
    let x = v as f32;
    if x.is_finite() {
        Ok(x)
    } else if v.is_finite() {
        Err(invalid(format!(
            "{what}{}: {v:e} is out of f32 range",
            at()
        )))
    } else {
        Err(invalid(format!(
            "{what}{}: {v} is not a finite number",
            at()
        )))
    }
}

/// Refuses an array that is not 1-D (nor a scalar when `scalar_ok`).
fn check_1d(what: &str, a: &Array<'_>, scalar_ok: bool) -> PyResult<()> {
    match a.ndim() {
        1 => Ok(()),
        0 if scalar_ok => Ok(()),
        n => Err(invalid(format!(
            "{what}: expected a 1-D array, got {n} dimensions (shape {:?})",
            a.shape()
        ))),
    }
}

/// A 1-D array (a scalar when `scalar_ok`) as finite f32 values.
pub fn vector(what: &str, a: &Array<'_>, scalar_ok: bool) -> PyResult<Vec<f32>> {
    check_1d(what, a, scalar_ok)?;
    let view = a.as_array();
    finite(what, &row_major(&view), |i| format!("[{i}]"))
}

/// A 1-D array as f64 values finite in f32: parameters kept in f64 (a
/// ProMP's weights), which a round trip through f32 would move, but whose
/// results come out in f32.
pub fn vector64(what: &str, a: &Array<'_>) -> PyResult<Vec<f64>> {
    check_1d(what, a, false)?;
    let view = a.as_array();
    let values = row_major(&view);
    for (i, v) in values.iter().enumerate() {
        single(what, || format!("[{i}]"), *v)?;
    }
    Ok(values.into_owned())
}

/// The array's values in row-major order: its memory when C-contiguous
/// (iterating a dynamic-dimension view costs 20 ns a value), else a copy
/// (a transpose, a slice).
fn row_major<'a>(view: &'a ArrayViewD<'_, f64>) -> Cow<'a, [f64]> {
    match view.as_slice() {
        Some(values) => Cow::Borrowed(values),
        None => Cow::Owned(view.iter().copied().collect()),
    }
}

/// Every value as a finite f32; `at(i)` names value `i`'s place.
fn finite(what: &str, values: &[f64], at: impl Fn(usize) -> String) -> PyResult<Vec<f32>> {
    values
        .iter()
        .enumerate()
        .map(|(i, v)| single(what, || at(i), *v))
        .collect()
}

/// A recording's sample times (1-D, s, strictly increasing, from any
/// origin: Unix time is fine) as f32 seconds since the first sample,
/// subtracted in f64 before rounding ([`primo_skill::stamps`]).
pub fn times(what: &str, a: &Array<'_>) -> PyResult<Vec<f32>> {
    check_1d(what, a, false)?;
    let view = a.as_array();
    let mut stamps = Stamps::new();
    row_major(&view)
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            if !t.is_finite() {
                return Err(invalid(format!("{what}[{i}]: {t} is not a finite number")));
            }
            stamps.push(t).map_err(|why| {
                let previous = format!("{what}[{}]", i.saturating_sub(1));
                invalid(format!("{what}[{i}] = {t} {}", why.why(&previous)))
            })
        })
        .collect()
}

/// A 2-D array as `(rows, columns, row-major finite f32 values)`.
pub fn matrix(what: &str, a: &Array<'_>) -> PyResult<(usize, usize, Vec<f32>)> {
    let shape = a.shape().to_vec();
    let [rows, cols] = shape[..] else {
        return Err(invalid(format!(
            "{what}: expected a 2-D array, got {} dimensions (shape {shape:?})",
            shape.len()
        )));
    };
    let view = a.as_array();
    let at = |i: usize| format!("[{}, {}]", i / cols.max(1), i % cols.max(1));
    Ok((rows, cols, finite(what, &row_major(&view), at)?))
}

/// f32 values as a float64 array.
pub fn out<'py>(py: Python<'py>, values: &[f32]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_iter(py, values.iter().map(|v| f64::from(*v)))
}

/// Row-major f32 values as a `rows × cols` float64 array.
pub fn out2<'py>(
    py: Python<'py>,
    values: &[f32],
    cols: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows = values.len().checked_div(cols).unwrap_or(0);
    PyArray1::from_iter(py, values.iter().map(|v| f64::from(*v))).reshape([rows, cols])
}

/// An optional finite number of seconds above 0 (`what` names it).
pub(crate) fn positive(what: &str, v: Option<f64>) -> PyResult<Option<f32>> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0 && (x as f32) > 0.0) => Err(invalid(format!(
            "{what}: {x} must be a positive, finite number"
        ))),
        v => Ok(v.map(|x| x as f32)),
    }
}

/// An optional array of one value per column (`what` names it).
pub(crate) fn per_column(
    what: &str,
    a: Option<Array<'_>>,
    names: &[String],
) -> PyResult<Option<Vec<f32>>> {
    let Some(a) = a else { return Ok(None) };
    let v = vector(what, &a, false)?;
    if v.len() != names.len() {
        return Err(invalid(format!(
            "{what}: {} values, expected one per column ({})",
            v.len(),
            names.join(",")
        )));
    }
    Ok(Some(v))
}
