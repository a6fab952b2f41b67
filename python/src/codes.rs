//! Real values to codes and back, in any format, with the CLI's rounding and overflow names.

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use gyrofx_job::golden::check_code;
use gyrofx_model::fx::{from_f64, Format, Overflow, Rounding};

use crate::blocks::Codes;
use crate::refused;

/// Parses a format string (`s18.14`, `u12.12`) whose codes fit `int64`.
pub(crate) fn format(text: &str) -> PyResult<Format> {
    let format: Format = text.parse().map_err(|e| {
        refused(format!(
            "format {text:?}: {e} (expected s<width>.<fraction bits> or u<width>.<fraction bits>, e.g. s18.14)"
        ))
    })?;
    if !format.signed && format.width == 64 {
        return Err(refused(format!(
            "format {text}: u64 codes do not fit numpy.int64; use at most u63"
        )));
    }
    Ok(format)
}

/// `values` as a one-dimensional `float64` array: any real array-like numpy converts (a list,
/// ints, a `float32` array).
fn real_record<'py>(values: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray1<'py, f64>> {
    let numpy = values.py().import("numpy")?;
    let array = numpy.call_method1("asarray", (values, "float64"))?;
    let dimensions: usize = array.getattr("ndim")?.extract()?;
    if dimensions != 1 {
        return Err(refused(format!(
            "values: {dimensions} dimensions; allowed: a one-dimensional record of real values"
        )));
    }
    array.extract()
}

/// Quantizes real values to codes of `fmt`.
///
/// `rounding` is one of floor, ceil, zero, nearest, round, convergent and `overflow` one of
/// saturate, wrap (the config's names). NaN and ±inf are refused with their index.
#[pyfunction]
#[pyo3(signature = (values, fmt, rounding = "nearest", overflow = "saturate"))]
pub(crate) fn quantize<'py>(
    py: Python<'py>,
    values: Bound<'py, PyAny>,
    fmt: &str,
    rounding: &str,
    overflow: &str,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let format = format(fmt)?;
    let rounding: Rounding = rounding.parse().map_err(|_| {
        refused(format!(
            "rounding = {rounding:?}: expected one of floor, ceil, zero, nearest, round, convergent"
        ))
    })?;
    let overflow: Overflow = overflow.parse().map_err(|_| {
        refused(format!(
            "overflow = {overflow:?}: expected saturate or wrap"
        ))
    })?;
    let values = real_record(&values)?;
    let values = values.as_array();
    let mut codes = Vec::with_capacity(values.len());
    for (index, value) in values.iter().enumerate() {
        let quantized = from_f64(*value, format, rounding, overflow)
            .map_err(|e| refused(format!("values[{index}] = {value}: {e}")))?;
        codes.push(quantized.code as i64);
    }
    Ok(codes.into_pyarray(py))
}

/// The real values (`code · 2^-frac`) of codes of `fmt`; a code outside the format is refused
/// with its index.
#[pyfunction]
pub(crate) fn to_real<'py>(
    py: Python<'py>,
    codes: Codes<'py>,
    fmt: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let format = format(fmt)?;
    let codes = codes.resolve("codes")?;
    let mut values = Vec::with_capacity(codes.len());
    for (index, code) in codes.iter().enumerate() {
        check_code(*code, format, &format!("codes[{index}]")).map_err(refused)?;
        values.push(format.to_f64(i128::from(*code)));
    }
    Ok(values.into_pyarray(py))
}
