//! `gyrofx` for Python: the bit-accurate model and its float twins, called sample by sample or
//! on whole numpy records from a cocotb test, a notebook or a scoreboard.
//!
//! Nothing here computes: every class wraps the Rust model the CLI and the vectors use, so a
//! Python result is the vectors' result bit for bit. Codes are `int` / `numpy.int64` exactly as
//! the RTL ports carry them (two's complement values, flags 0/1, mode 1 normal / 0 reverse);
//! real values are °/s.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod blocks;
mod codes;
mod format;
mod loops;
mod plan;
mod population;

create_exception!(
    gyrofx,
    GyrofxError,
    PyValueError,
    "A refused config, format or argument; the message is the CLI's."
);

/// The exception for `error`, with its message.
pub(crate) fn refused(error: impl std::fmt::Display) -> PyErr {
    GyrofxError::new_err(error.to_string())
}

/// The compiled part of the `gyrofx` package (`import gyrofx` re-exports it).
#[pymodule]
fn _gyrofx(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("GyrofxError", module.py().get_type::<GyrofxError>())?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    module.add_class::<plan::Plan>()?;
    module.add_class::<blocks::Kf>()?;
    module.add_class::<blocks::KfFloat>()?;
    module.add_class::<blocks::Sequencer>()?;
    module.add_class::<blocks::Estimator>()?;
    module.add_class::<blocks::EstimatorFloat>()?;
    module.add_class::<blocks::MeanFilter>()?;
    module.add_class::<blocks::MeanFilterFloat>()?;
    module.add_class::<blocks::Chain>()?;
    module.add_class::<blocks::ChainFloat>()?;
    module.add_class::<loops::GyroLoop>()?;
    module.add_class::<loops::GyroLoopFloat>()?;
    module.add_class::<loops::System>()?;
    module.add_class::<loops::SystemFloat>()?;
    module.add_class::<loops::Resonator>()?;
    module.add_class::<format::Format>()?;
    module.add_class::<format::Rounding>()?;
    module.add_class::<format::Overflow>()?;
    module.add_function(wrap_pyfunction!(format::quantize, module)?)?;
    module.add_function(wrap_pyfunction!(format::to_real, module)?)?;
    module.add_function(wrap_pyfunction!(population::_population_describe, module)?)?;
    module.add_function(wrap_pyfunction!(population::_population_members, module)?)?;
    module.add_function(wrap_pyfunction!(population::_population_summary, module)?)?;
    Ok(())
}
