//! Real values to codes and back, in any format: the kernels behind `gyrofx.quantize`,
//! `gyrofx.to_real` and `Format` (the Python-facing functions are in `format`).

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

/// `values` quantized to `format`, and how many did not fit it.
pub(crate) fn quantize_values<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    format: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> PyResult<(Bound<'py, PyArray1<i64>>, u64)> {
    let values = real_record(values)?;
    let values = values.as_array();
    let mut codes = Vec::with_capacity(values.len());
    let mut overflowed = 0u64;
    for (index, value) in values.iter().enumerate() {
        let quantized = from_f64(*value, format, rounding, overflow)
            .map_err(|e| refused(format!("values[{index}] = {value}: {e}")))?;
        overflowed += u64::from(quantized.overflowed);
        codes.push(quantized.code as i64);
    }
    Ok((codes.into_pyarray(py), overflowed))
}

/// The real values of `codes` in `format` (`gyrofx.to_real`); a code outside the format is
/// refused with its index.
pub(crate) fn codes_to_real<'py>(
    py: Python<'py>,
    codes: Codes<'py>,
    format: Format,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let codes = codes.resolve("codes")?;
    let mut values = Vec::with_capacity(codes.len());
    for (index, code) in codes.iter().enumerate() {
        check_code(*code, format, &format!("codes[{index}]")).map_err(refused)?;
        values.push(format.to_f64(i128::from(*code)));
    }
    Ok(values.into_pyarray(py))
}
