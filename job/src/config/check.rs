//! Field validators shared by every config section: each returns [`Error::Config`] naming the
//! field (its dotted path, e.g. `kf.state_format`), the value and what is allowed.

use gyrofx_model::fx::{CoefficientFormat, Format};

use crate::error::{Error, Result};

/// A coefficient width of 1..=64 bits, as an automatic coefficient format.
pub(crate) fn width(field: &str, width: u32) -> Result<CoefficientFormat> {
    if (1..=64).contains(&width) {
        Ok(CoefficientFormat::Auto { width })
    } else {
        Err(Error::config(field, width, "1..=64 bits"))
    }
}

/// A fixed-point format such as `s18.16`.
pub(crate) fn parse_format(field: &str, text: &str) -> Result<Format> {
    text.parse::<Format>()
        .map_err(|e| Error::config(field, format!("{text:?}"), e.to_string()))
}

/// Any finite number.
pub(crate) fn finite(field: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number"))
    }
}

/// A finite number > 0.
pub(crate) fn positive(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number > 0"))
    }
}

/// A finite number >= 0.
pub(crate) fn non_negative(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::config(field, value, "a finite number >= 0"))
    }
}
