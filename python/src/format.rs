//! `Format`, `Rounding` and `Overflow` for Python: a format as an object (width, fraction, code
//! range, LSB, to and from real values) and the quantizer's modes as enums. Everywhere a
//! format, a rounding or an overflow mode is taken, the config's strings (`"s24.14"`,
//! `"nearest"`, `"saturate"`) are accepted too. `gyrofx.quantize` and `gyrofx.to_real` live
//! here, on the kernels of `codes`.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyString;

use gyrofx_model::fx::{self, Format as ModelFormat};

use crate::blocks::Codes;
use crate::codes;
use crate::refused;

/// A fixed-point format: `Format("s24.14")` (signed, 24-bit word, 14 fraction bits), or
/// `Format(width=24, fraction=14, signed=True)`. A code's real value is `code · lsb`. It equals
/// its config string: `Format("s24.14") == "s24.14"`.
#[pyclass(module = "gyrofx", name = "Format", frozen, from_py_object)]
#[derive(Clone)]
pub(crate) struct Format {
    pub(crate) inner: ModelFormat,
}

#[pymethods]
impl Format {
    #[new]
    #[pyo3(signature = (text = None, *, width = None, fraction = None, signed = true))]
    fn new(
        text: Option<&str>,
        width: Option<u32>,
        fraction: Option<i32>,
        signed: bool,
    ) -> PyResult<Format> {
        let inner = match (text, width, fraction) {
            (Some(text), None, None) => codes::format(text)?,
            (None, Some(width), Some(fraction)) => {
                let inner = ModelFormat::new(signed, width, fraction).map_err(|e| {
                    refused(format!(
                        "Format(width={width}, fraction={fraction}, signed={signed}): {e}"
                    ))
                })?;
                codes::format(&inner.to_string())?
            }
            _ => return Err(refused(
                "Format: give a string such as \"s24.14\", or width= and fraction= (and signed=)",
            )),
        };
        Ok(Format { inner })
    }

    /// Word length, bits.
    #[getter]
    fn width(&self) -> u32 {
        self.inner.width
    }

    /// Fraction bits: the LSB weighs `2^-fraction`.
    #[getter]
    fn fraction(&self) -> i32 {
        self.inner.frac
    }

    /// Two's complement when true, unsigned otherwise.
    #[getter]
    fn signed(&self) -> bool {
        self.inner.signed
    }

    /// The smallest code.
    #[getter]
    fn min_code(&self) -> i64 {
        self.inner.min_code() as i64
    }

    /// The largest code.
    #[getter]
    fn max_code(&self) -> i64 {
        self.inner.max_code() as i64
    }

    /// The real value of one code step, `2^-fraction`.
    #[getter]
    fn lsb(&self) -> f64 {
        self.inner.lsb()
    }

    /// Real values of `codes` (`gyrofx.to_real`).
    fn to_real<'py>(
        &self,
        py: Python<'py>,
        codes: Codes<'py>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        codes::codes_to_real(py, codes, self.inner)
    }

    /// Codes of real `values` (`gyrofx.quantize`).
    #[pyo3(signature = (values, rounding = RoundingArg::Text("nearest".into()), overflow = OverflowArg::Text("saturate".into())),
           text_signature = "($self, values, rounding='nearest', overflow='saturate')")]
    fn quantize<'py>(
        &self,
        py: Python<'py>,
        values: Bound<'py, PyAny>,
        rounding: RoundingArg,
        overflow: OverflowArg,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let (codes, _) =
            codes::quantize_values(py, &values, self.inner, rounding.mode()?, overflow.mode()?)?;
        Ok(codes)
    }

    fn __str__(&self) -> String {
        self.inner.to_string()
    }

    fn __repr__(&self) -> String {
        format!("Format('{}')", self.inner)
    }

    /// Equal to a `Format` of the same width, fraction and signedness, and to its string.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        match other.extract::<FormatArg>() {
            Ok(FormatArg::Object(format)) => format.inner == self.inner,
            Ok(FormatArg::Text(text)) => text == self.inner.to_string(),
            Err(_) => false,
        }
    }

    /// Its string's hash: equal objects hash alike.
    fn __hash__(&self, py: Python<'_>) -> PyResult<isize> {
        PyString::new(py, &self.inner.to_string()).hash()
    }
}

/// Quantizes real values to codes of `fmt` (a `Format` or its string).
///
/// `rounding` is a `Rounding` or one of floor, ceil, zero, nearest, round, convergent, and
/// `overflow` an `Overflow` or saturate, wrap (the config's names). NaN and ±inf are refused
/// with their index. With `counts=True` it returns `(codes, overflowed)`: how many values did
/// not fit the format (saturated or wrapped).
#[pyfunction]
#[pyo3(signature = (values, fmt, rounding = RoundingArg::Text("nearest".into()), overflow = OverflowArg::Text("saturate".into()), *, counts = false),
       text_signature = "(values, fmt, rounding='nearest', overflow='saturate', *, counts=False)")]
pub(crate) fn quantize<'py>(
    py: Python<'py>,
    values: Bound<'py, PyAny>,
    fmt: FormatArg,
    rounding: RoundingArg,
    overflow: OverflowArg,
    counts: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (codes, overflowed) = codes::quantize_values(
        py,
        &values,
        fmt.format()?,
        rounding.mode()?,
        overflow.mode()?,
    )?;
    if counts {
        Ok((codes, overflowed).into_pyobject(py)?.into_any())
    } else {
        Ok(codes.into_any())
    }
}

/// The real values (`code · 2^-frac`) of codes of `fmt` (a `Format` or its string); a code
/// outside the format is refused with its index.
#[pyfunction]
pub(crate) fn to_real<'py>(
    py: Python<'py>,
    codes: Codes<'py>,
    fmt: FormatArg,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    codes::codes_to_real(py, codes, fmt.format()?)
}

/// A format as an argument: a `Format` or its string.
#[derive(FromPyObject)]
pub(crate) enum FormatArg {
    Object(Format),
    Text(String),
}

impl FormatArg {
    pub(crate) fn format(&self) -> PyResult<ModelFormat> {
        match self {
            FormatArg::Object(format) => Ok(format.inner),
            FormatArg::Text(text) => codes::format(text),
        }
    }
}

/// Rounding of the bits a quantization drops (the config's `rounding` names).
#[pyclass(module = "gyrofx", eq, eq_int, frozen, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Rounding {
    /// Toward −∞ (two's-complement truncation).
    #[pyo3(name = "FLOOR")]
    Floor,
    /// Toward +∞.
    #[pyo3(name = "CEIL")]
    Ceil,
    /// Toward zero.
    #[pyo3(name = "ZERO")]
    Zero,
    /// Nearest, ties toward +∞ (add half an LSB, then floor).
    #[pyo3(name = "NEAREST")]
    Nearest,
    /// Nearest, ties away from zero.
    #[pyo3(name = "ROUND")]
    Round,
    /// Nearest, ties to even.
    #[pyo3(name = "CONVERGENT")]
    Convergent,
}

impl Rounding {
    fn mode(self) -> fx::Rounding {
        match self {
            Rounding::Floor => fx::Rounding::Floor,
            Rounding::Ceil => fx::Rounding::Ceil,
            Rounding::Zero => fx::Rounding::Zero,
            Rounding::Nearest => fx::Rounding::Nearest,
            Rounding::Round => fx::Rounding::Round,
            Rounding::Convergent => fx::Rounding::Convergent,
        }
    }
}

#[pymethods]
impl Rounding {
    /// The config's name (`"nearest"`).
    #[getter]
    fn config_name(&self) -> &'static str {
        self.mode().name()
    }
}

/// What a value outside the format becomes (the config's `overflow` names).
#[pyclass(module = "gyrofx", eq, eq_int, frozen, hash, from_py_object)]
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) enum Overflow {
    /// Clamped to the nearest code.
    #[pyo3(name = "SATURATE")]
    Saturate,
    /// The low `width` bits kept (two's-complement wrap-around).
    #[pyo3(name = "WRAP")]
    Wrap,
}

impl Overflow {
    fn mode(self) -> fx::Overflow {
        match self {
            Overflow::Saturate => fx::Overflow::Saturate,
            Overflow::Wrap => fx::Overflow::Wrap,
        }
    }
}

#[pymethods]
impl Overflow {
    /// The config's name (`"saturate"`).
    #[getter]
    fn config_name(&self) -> &'static str {
        self.mode().name()
    }
}

/// A rounding as an argument: a `Rounding` or its config name.
#[derive(FromPyObject)]
pub(crate) enum RoundingArg {
    Enum(Rounding),
    Text(String),
}

impl RoundingArg {
    pub(crate) fn mode(&self) -> PyResult<fx::Rounding> {
        match self {
            RoundingArg::Enum(rounding) => Ok(rounding.mode()),
            RoundingArg::Text(text) => text.parse().map_err(|_| {
                refused(format!(
                    "rounding = {text:?}: expected one of floor, ceil, zero, nearest, round, convergent (or a gyrofx.Rounding)"
                ))
            }),
        }
    }
}

/// An overflow mode as an argument: an `Overflow` or its config name.
#[derive(FromPyObject)]
pub(crate) enum OverflowArg {
    Enum(Overflow),
    Text(String),
}

impl OverflowArg {
    pub(crate) fn mode(&self) -> PyResult<fx::Overflow> {
        match self {
            OverflowArg::Enum(overflow) => Ok(overflow.mode()),
            OverflowArg::Text(text) => text.parse().map_err(|_| {
                refused(format!(
                    "overflow = {text:?}: expected saturate or wrap (or a gyrofx.Overflow)"
                ))
            }),
        }
    }
}
