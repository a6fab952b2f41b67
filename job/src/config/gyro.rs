//! `[gyro_a]`, `[gyro_b]` (each gyro's errors) and `[plant]` (what the two gyros share).

use serde::{Deserialize, Serialize};

use gyrofx_model::plant::{GyroErrors, Plant};

use super::check::{finite, non_negative, positive};
use crate::error::{Error, Result};

/// `[plant]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantConfig {
    /// What produces each gyro's samples: `rate` (the rate-level model of `[gyro_a]`,
    /// `[gyro_b]`) or `resonator` (`[resonator_a]`, `[resonator_b]` closed by `[loop]`).
    pub model: String,
    /// Shortest bias-instability correlation time, s.
    pub bi_tau_min_s: f64,
    /// Longest, s.
    pub bi_tau_max_s: f64,
}

impl PlantConfig {
    /// Checks `[gyro_a]`, then `[gyro_b]`, then this section, and returns the plant sampled at
    /// `fs_hz` (Hz, already checked by `[stimulus]`).
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field.
    pub fn validate(&self, fs_hz: f64, gyro_a: &GyroErrors, gyro_b: &GyroErrors) -> Result<Plant> {
        let plant = Plant {
            fs_hz,
            gyros: [gyro("gyro_a", gyro_a)?, gyro("gyro_b", gyro_b)?],
            bi_tau_min_s: self.bi_tau_min_s,
            bi_tau_max_s: self.bi_tau_max_s,
        };
        positive("plant.bi_tau_min_s", plant.bi_tau_min_s)?;
        if !(plant.bi_tau_max_s.is_finite() && plant.bi_tau_max_s > plant.bi_tau_min_s) {
            return Err(Error::config(
                "plant.bi_tau_max_s",
                plant.bi_tau_max_s,
                format!("a finite number > bi_tau_min_s = {}", plant.bi_tau_min_s),
            ));
        }
        Ok(plant)
    }
}

/// Checks one gyro's section, named `section` in errors.
fn gyro(section: &str, g: &GyroErrors) -> Result<GyroErrors> {
    let field = |name: &str| format!("{section}.{name}");
    for (name, value) in [
        ("sf_ppm", g.sf_ppm),
        ("sf_mode_mismatch_ppm", g.sf_mode_mismatch_ppm),
        ("bias_dps", g.bias_dps),
        ("bias_mode_mismatch_dps", g.bias_mode_mismatch_dps),
        ("rate_ramp_deg_per_h2", g.rate_ramp_deg_per_h2),
    ] {
        finite(&field(name), value)?;
    }
    for (name, value) in [
        ("arw_deg_per_sqrt_h", g.arw_deg_per_sqrt_h),
        ("bias_instability_deg_per_h", g.bias_instability_deg_per_h),
        ("rrw_deg_per_h_per_sqrt_h", g.rrw_deg_per_h_per_sqrt_h),
        ("settle_tau_s", g.settle_tau_s),
    ] {
        non_negative(&field(name), value)?;
    }
    Ok(*g)
}

#[cfg(test)]
mod tests {
    use crate::config::assert_refused;

    #[test]
    fn bad_gyro_and_plant_values_name_field_value_and_what_is_allowed() {
        assert_refused(&[
            (
                "[gyro_b]\narw_deg_per_sqrt_h = -1.0",
                "gyro_b.arw_deg_per_sqrt_h = -1",
                ">= 0",
            ),
            (
                "[gyro_a]\nbias_dps = nan",
                "gyro_a.bias_dps = NaN",
                "a finite number",
            ),
            (
                "[plant]\nbi_tau_max_s = 0.1",
                "plant.bi_tau_max_s = 0.1",
                "> bi_tau_min_s",
            ),
        ]);
    }
}
