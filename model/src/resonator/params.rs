//! The structure of one vibratory gyro (SPEC §1.6): its config section and the stiffness and
//! damping matrices derived from it.
//!
//! Principal stiffnesses and dampings from the two modes' frequencies and quality factors:
//!
//! ```text
//! k_i = m (2π f_i)²          (N/m)
//! d_i = m (2π f_i) / Q_i     (N·s/m)
//! ```
//!
//! rotated into the pick-off frame (x = drive axis in normal mode, y = sense axis):
//!
//! ```text
//! K = R(ε) diag(k1, k2) R(ε)ᵀ,  D = R(θ) diag(d1, d2) R(θ)ᵀ,  R(a) = [[cos a, −sin a], [sin a, cos a]]
//! kxx = (k1+k2)/2 + (k1−k2)/2 cos 2ε,  kyy = (k1+k2)/2 − (k1−k2)/2 cos 2ε,  kxy = kyx = (k1−k2)/2 sin 2ε
//! ```
//!
//! and the same pattern for `D` with `θ`. Trigonometry goes through the pure-Rust `libm`.

use std::f64::consts::PI;

/// One gyro's resonator (also the `[resonator_a]` / `[resonator_b]` config sections; the
/// field names are the config keys).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResonatorParams {
    /// Modal mass `m`, kg.
    pub mass_kg: f64,
    /// `f1`: natural frequency of the first principal stiffness axis (the drive mode), Hz.
    pub drive_frequency_hz: f64,
    /// `f2`: natural frequency of the second principal stiffness axis (the sense mode), Hz.
    pub sense_frequency_hz: f64,
    /// `Q1`: quality factor of the first principal damping axis (dimensionless).
    pub q_drive: f64,
    /// `Q2`: quality factor of the second principal damping axis (dimensionless).
    pub q_sense: f64,
    /// `ε`: angle of the principal stiffness axes from the pick-off axes, degrees.
    pub stiffness_angle_deg: f64,
    /// `θ`: angle of the principal damping axes from the pick-off axes, degrees.
    pub damping_angle_deg: f64,
    /// `q0`: drive amplitude the drive loop holds, m.
    pub drive_amplitude_m: f64,
    /// `φ`: net phase error of the sense channel in normal mode, degrees: the demodulation
    /// reference lags the Coriolis component of the sense signal by `φ`.
    pub phase_error_deg: f64,
    /// `φ′`: the same in reverse mode, degrees.
    pub phase_error_reverse_deg: f64,
}

/// A resonator parameter outside its range: names the field, its value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// A parameter outside its range.
    #[error("{field} = {value} is not allowed: {allowed}")]
    Range {
        /// The config key.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
}

/// The matrices of the equation of motion in the pick-off frame, and the principal values
/// they come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrices {
    /// Principal stiffnesses `[k1, k2]`, N/m.
    pub k_principal: [f64; 2],
    /// Principal dampings `[d1, d2]`, N·s/m.
    pub d_principal: [f64; 2],
    /// `K = [[kxx, kxy], [kxy, kyy]]`, N/m.
    pub k: [[f64; 2]; 2],
    /// `D = [[dxx, dxy], [dxy, dyy]]`, N·s/m.
    pub d: [[f64; 2]; 2],
}

/// `R(a) diag(p1, p2) R(a)ᵀ` for `a` in radians, written as SPEC §1.6 writes it.
pub fn rotated(principal: [f64; 2], angle_rad: f64) -> [[f64; 2]; 2] {
    let [p1, p2] = principal;
    let mean = (p1 + p2) / 2.0;
    let half_split = (p1 - p2) / 2.0;
    let c = libm::cos(2.0 * angle_rad);
    let s = libm::sin(2.0 * angle_rad);
    let xx = mean + half_split * c;
    let yy = mean - half_split * c;
    let xy = half_split * s;
    [[xx, xy], [xy, yy]]
}

impl ResonatorParams {
    /// Paper 004's Table 1 (f1 = 8195 Hz, f2 = 8142 Hz, Q 184 / 195, m = 5.4e-7 kg) with
    /// SPEC §1.6's defaults for what the table does not give: q0 = 2 µm, ε = 0.5°, θ = 2°,
    /// φ = φ′ = 1°.
    pub fn paper_004() -> Self {
        ResonatorParams {
            mass_kg: 5.4e-7,
            drive_frequency_hz: 8195.0,
            sense_frequency_hz: 8142.0,
            q_drive: 184.0,
            q_sense: 195.0,
            stiffness_angle_deg: 0.5,
            damping_angle_deg: 2.0,
            drive_amplitude_m: 2e-6,
            phase_error_deg: 1.0,
            phase_error_reverse_deg: 1.0,
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`ParamError::Range`] for the first field that is not finite or outside its range:
    /// mass, frequencies and drive amplitude must be positive; each Q above 0.5 (an
    /// underdamped mode); ε and θ within ±45° (beyond, x and y swap roles); φ and φ′ strictly
    /// within ±90° (at ±90° the Coriolis signal leaves the in-phase channel).
    pub fn validate(&self) -> Result<(), ParamError> {
        let check = |field: &'static str, value: f64, ok: bool, allowed: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(ParamError::Range {
                    field,
                    value,
                    allowed,
                })
            }
        };
        let positive = "a finite value above 0";
        check("mass_kg", self.mass_kg, self.mass_kg > 0.0, positive)?;
        check(
            "drive_frequency_hz",
            self.drive_frequency_hz,
            self.drive_frequency_hz > 0.0,
            positive,
        )?;
        check(
            "sense_frequency_hz",
            self.sense_frequency_hz,
            self.sense_frequency_hz > 0.0,
            positive,
        )?;
        let underdamped = "a finite quality factor above 0.5 (an underdamped mode)";
        check("q_drive", self.q_drive, self.q_drive > 0.5, underdamped)?;
        check("q_sense", self.q_sense, self.q_sense > 0.5, underdamped)?;
        let angle = "an angle within -45..=45 degrees";
        check(
            "stiffness_angle_deg",
            self.stiffness_angle_deg,
            self.stiffness_angle_deg.abs() <= 45.0,
            angle,
        )?;
        check(
            "damping_angle_deg",
            self.damping_angle_deg,
            self.damping_angle_deg.abs() <= 45.0,
            angle,
        )?;
        check(
            "drive_amplitude_m",
            self.drive_amplitude_m,
            self.drive_amplitude_m > 0.0,
            positive,
        )?;
        let phase = "a phase strictly within -90..90 degrees";
        check(
            "phase_error_deg",
            self.phase_error_deg,
            self.phase_error_deg.abs() < 90.0,
            phase,
        )?;
        check(
            "phase_error_reverse_deg",
            self.phase_error_reverse_deg,
            self.phase_error_reverse_deg.abs() < 90.0,
            phase,
        )
    }

    /// Principal stiffnesses `[k1, k2]`, N/m: `k_i = m (2π f_i)²`.
    pub fn principal_stiffness(&self) -> [f64; 2] {
        let k = |f: f64| self.mass_kg * (2.0 * PI * f) * (2.0 * PI * f);
        [k(self.drive_frequency_hz), k(self.sense_frequency_hz)]
    }

    /// Principal dampings `[d1, d2]`, N·s/m: `d_i = m (2π f_i) / Q_i`.
    pub fn principal_damping(&self) -> [f64; 2] {
        [
            self.mass_kg * 2.0 * PI * self.drive_frequency_hz / self.q_drive,
            self.mass_kg * 2.0 * PI * self.sense_frequency_hz / self.q_sense,
        ]
    }

    /// `K` and `D` in the pick-off frame.
    pub fn matrices(&self) -> Matrices {
        let k_principal = self.principal_stiffness();
        let d_principal = self.principal_damping();
        Matrices {
            k_principal,
            d_principal,
            k: rotated(k_principal, self.stiffness_angle_deg.to_radians()),
            d: rotated(d_principal, self.damping_angle_deg.to_radians()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_r_diag_r_transpose() {
        // Against the explicit product R diag Rᵀ, at an angle where every entry is non-zero.
        let a = 0.3_f64;
        let (c, s) = (libm::cos(a), libm::sin(a));
        let r = [[c, -s], [s, c]];
        let p = [5.0, 2.0];
        let got = rotated(p, a);
        for i in 0..2 {
            for j in 0..2 {
                let want = r[i][0] * p[0] * r[j][0] + r[i][1] * p[1] * r[j][1];
                assert!((got[i][j] - want).abs() < 1e-14, "({i},{j})");
            }
        }
    }

    #[test]
    fn paper_004_is_valid_and_derives_table_1() {
        let p = ResonatorParams::paper_004();
        p.validate().unwrap();
        let m = p.matrices();
        // k1 = 5.4e-7 (2π 8195)² = 1431.70 N/m; d1 = 5.4e-7 · 2π 8195 / 184 = 1.5111e-4 N·s/m.
        assert!(
            (m.k_principal[0] - 1431.70).abs() < 0.01,
            "{}",
            m.k_principal[0]
        );
        assert!(
            (m.d_principal[0] - 1.511_13e-4).abs() < 1e-8,
            "{}",
            m.d_principal[0]
        );
        // Trace and determinant survive the rotation.
        assert!((m.k[0][0] + m.k[1][1] - m.k_principal.iter().sum::<f64>()).abs() < 1e-9);
        let det = m.d[0][0] * m.d[1][1] - m.d[0][1] * m.d[1][0];
        assert!((det / (m.d_principal[0] * m.d_principal[1]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn validation_names_the_field_value_and_range() {
        let mut p = ResonatorParams::paper_004();
        p.q_sense = 0.2;
        let message = p.validate().unwrap_err().to_string();
        assert!(
            message.contains("q_sense = 0.2") && message.contains("above 0.5"),
            "{message}"
        );
        let mut p = ResonatorParams::paper_004();
        p.phase_error_reverse_deg = 90.0;
        assert!(matches!(
            p.validate(),
            Err(ParamError::Range {
                field: "phase_error_reverse_deg",
                ..
            })
        ));
        let mut p = ResonatorParams::paper_004();
        p.mass_kg = f64::NAN;
        assert!(p
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("mass_kg = NaN"));
    }

    #[test]
    fn config_keys_are_exactly_the_fields() {
        let text = r#"{"mass_kg":5.4e-7,"drive_frequency_hz":8195,"sense_frequency_hz":8142,
            "q_drive":184,"q_sense":195,"stiffness_angle_deg":0.5,"damping_angle_deg":2,
            "drive_amplitude_m":2e-6,"phase_error_deg":1,"phase_error_reverse_deg":1}"#;
        let p: ResonatorParams = serde_json::from_str(text).unwrap();
        assert_eq!(p, ResonatorParams::paper_004());
        let unknown = text.replace("q_sense", "q_sens");
        assert!(serde_json::from_str::<ResonatorParams>(&unknown).is_err());
    }
}
