//! `[resonator_a]`, `[resonator_b]` (each gyro's structure, SPEC §1.6), `[front_end]` (pick-off,
//! ADC, DAC, thermal and electronic noise, drift: both gyros'), the optional `[front_end_a]` and
//! `[front_end_b]` (one gyro's own front-end keys over `[front_end]`) and `[loop]` (one gyro's
//! digital drive and sense loop, the same for both): what `gyrofx loop` runs.
//!
//! `[front_end]`'s sample rate is `[loop]`'s `adc_rate_hz`, and `[loop]`'s rounding and
//! overflow are the config's `rounding` and `overflow`, so neither can disagree.

use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop::closed::FixedHarness;
use gyrofx_model::gyro_loop::figures::{characterize, Procedure};
use gyrofx_model::gyro_loop::gyro::{LoopSettings, Plan, Spec};
use gyrofx_model::resonator::{PhysicsSettings, ResonatorParams};
use gyrofx_model::sequencer::Schedule;

use super::Config;
use crate::error::{Error, Result};

/// One gyro's resolved loop: its plan, its structure and its front end.
#[derive(Clone, Debug, PartialEq)]
pub struct GyroLoop {
    /// `a` or `b`.
    pub name: &'static str,
    /// The loop's plan, designed from the nominal structure.
    pub plan: Plan,
    /// The structure.
    pub params: ResonatorParams,
    /// The front end (noise and drift on; callers switch them off where they want).
    pub front_end: PhysicsSettings,
}

impl GyroLoop {
    /// The spec its plan was made from: the `[loop]` settings and this gyro's structure and
    /// front end.
    pub fn spec(&self) -> Spec {
        Spec {
            settings: self.plan.settings.clone(),
            resonator: self.params,
            front_end: self.front_end,
        }
    }
}

/// Deserializes `table` (a config section after overlaying) as `T`, naming the section in the
/// error.
fn section<T: serde::de::DeserializeOwned>(name: &str, table: toml::Table) -> Result<T> {
    typed(name, table).map_err(|(key, message)| Error::ConfigSyntax {
        origin: "config".into(),
        message: format!("{key}: {message}"),
    })
}

/// `table` as the section `name`'s type, or the dotted key that does not fit and why.
fn typed<T: serde::de::DeserializeOwned>(
    name: &str,
    table: toml::Table,
) -> std::result::Result<T, (String, String)> {
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let key = e.path().to_string();
        let key = if key == "." || key.is_empty() {
            name.to_string()
        } else {
            format!("{name}.{key}")
        };
        (key, e.inner().message().trim().replace('\n', " "))
    })
}

impl Config {
    /// The first key of `[loop]` or `[front_end]` (sections kept as tables until a loop is
    /// built) whose value has the wrong type, and why: checked when the config is read, so
    /// that the error can name the user's line.
    pub(super) fn section_type_error(&self) -> Option<(String, String)> {
        let mut table = self.gyro_loop.clone();
        table.insert("rounding".into(), self.rounding.clone().into());
        table.insert("overflow".into(), self.overflow.clone().into());
        if let Err(e) = typed::<LoopSettings>("loop", table) {
            return Some(e);
        }
        let mut front_end = self.front_end.clone();
        front_end.insert("sample_rate_hz".into(), 1.0.into());
        typed::<PhysicsSettings>("front_end", front_end.clone())
            .err()
            .or_else(|| {
                [("a", &self.front_end_a), ("b", &self.front_end_b)]
                    .into_iter()
                    .find_map(|(gyro, overlay)| {
                        // `[front_end]` alone is typed: what fails now is the overlay's.
                        typed::<PhysicsSettings>(
                            &format!("front_end_{gyro}"),
                            overlaid(&front_end, overlay),
                        )
                        .err()
                    })
            })
    }

    /// Gyro `gyro`'s (`a` or `b`) front-end table: `[front_end]` with `[front_end_<gyro>]`
    /// over it, and the section a key of it is named by in errors.
    fn front_end_of(&self, gyro: &str) -> (toml::Table, &toml::Table) {
        let overlay = if gyro == "a" {
            &self.front_end_a
        } else {
            &self.front_end_b
        };
        (overlaid(&self.front_end, overlay), overlay)
    }

    /// Both gyros' loops, validated and designed.
    ///
    /// # Errors
    /// [`Error::Config`] naming the first bad field of `[resonator_a]`, `[resonator_b]`,
    /// `[front_end]` or `[loop]`, or a loop the design refuses.
    pub fn gyro_loops(&self) -> Result<[GyroLoop; 2]> {
        let mut table = self.gyro_loop.clone();
        table.insert("rounding".into(), self.rounding.clone().into());
        table.insert("overflow".into(), self.overflow.clone().into());
        let settings: LoopSettings = section("loop", table)?;
        let resolve = |name: &'static str, params: &ResonatorParams| -> Result<GyroLoop> {
            let key = format!("resonator_{name}");
            params
                .validate()
                .map_err(|e| prefixed(&key, e.to_string()))?;
            let (mut front_end, overlay) = self.front_end_of(name);
            let own = format!("front_end_{name}");
            front_end.insert("sample_rate_hz".into(), settings.adc_rate_hz.into());
            let front_end: PhysicsSettings = section(&own, front_end)?;
            front_end.validate(params).map_err(|e| {
                let message = e.to_string();
                // A value gyro `name`'s own section set is named there.
                let field = message.split(" = ").next().unwrap_or_default();
                let section = if overlay.contains_key(field) {
                    own.as_str()
                } else {
                    "front_end"
                };
                prefixed(section, message)
            })?;
            let plan = Plan::new(&Spec {
                settings: settings.clone(),
                resonator: *params,
                front_end,
            })
            .map_err(|e| prefixed("loop", e.to_string()))?;
            Ok(GyroLoop {
                name,
                plan,
                params: *params,
                front_end,
            })
        };
        Ok([
            resolve("a", &self.resonator_a)?,
            resolve("b", &self.resonator_b)?,
        ])
    }
}

/// Checks that the loops can feed the chain: their output rate is `fs_hz` (Hz) and their
/// output format the chain's `input`, and the sequencer's blanking covers each loop's measured
/// settling after a switch (rate within 0.01 °/s, noise off), in both modes.
///
/// # Errors
/// [`Error::Config`] naming the field that disagrees.
pub(super) fn check_chain(
    loops: &[GyroLoop; 2],
    fs_hz: f64,
    input: Format,
    schedule: &Schedule,
) -> Result<()> {
    for gyro in loops {
        let rate = gyro.plan.chain_rate_hz();
        if (rate - fs_hz).abs() > 1e-9 * fs_hz {
            return Err(Error::config(
                "stimulus.fs_hz",
                fs_hz,
                format!(
                    "the resonator loop's output rate loop.adc_rate_hz / loop.decimation = {rate} Hz"
                ),
            ));
        }
        let output: Format = gyro.plan.settings.output_format.parse().map_err(|_| {
            Error::config(
                "loop.output_format",
                &gyro.plan.settings.output_format,
                "a format such as s24.14",
            )
        })?;
        if output != input {
            return Err(Error::config(
                "loop.output_format",
                output,
                format!("the chain's input format kf.input_format = {input}"),
            ));
        }
    }
    let blank_ms = schedule.blank as f64 * 1e3 / fs_hz;
    for gyro in loops {
        let figures = characterize::<FixedHarness>(
            &gyro.plan,
            &gyro.params,
            &gyro.front_end,
            &Procedure::default(),
        )
        .map_err(|e| prefixed(&format!("resonator_{}", gyro.name), e.to_string()))?;
        let settling = figures
            .normal
            .rate_settling_ms
            .measured
            .max(figures.reverse.rate_settling_ms.measured);
        if blank_ms < settling {
            return Err(Error::config(
                "sequencer.blank",
                schedule.blank,
                format!(
                    "at least {} samples: the blanking ({blank_ms} ms at {fs_hz} Hz) must cover gyro {}'s settling after a switch, {settling} ms",
                    (settling * fs_hz / 1e3).ceil(),
                    gyro.name
                ),
            ));
        }
    }
    Ok(())
}

/// `base` with `overlay`'s keys over it (inline tables merged key by key).
fn overlaid(base: &toml::Table, overlay: &toml::Table) -> toml::Table {
    let mut table = base.clone();
    super::merge(&mut table, overlay.clone());
    table
}

/// The model's "`field = value is not allowed: …`" under the section's name.
fn prefixed(section: &str, message: String) -> Error {
    match message.split_once(" = ") {
        Some((field, rest)) => match rest.split_once(" is not allowed: ") {
            Some((value, allowed)) => {
                // The loop's plan names its own keys already (`loop.nco_phase_bits`); the
                // resonator's sample rate is `[loop]`'s `adc_rate_hz`.
                let field = match field {
                    "sample_rate_hz" => "loop.adc_rate_hz".to_string(),
                    f if f.starts_with(&format!("{section}.")) => f.to_string(),
                    f => format!("{section}.{f}"),
                };
                Error::config(field, value, allowed.to_string())
            }
            None => Error::config(section, message, "see the annotated default (gyrofx init)"),
        },
        None => Error::config(section, message, "see the annotated default (gyrofx init)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded default's loops are paper 004's gyro with the default loop, and a bad
    /// structure or loop setting is refused naming its section and key.
    #[test]
    fn the_default_loops_are_paper_004s_and_bad_fields_are_named() {
        let [a, b] = Config::embedded().gyro_loops().unwrap();
        assert_eq!(a.params, ResonatorParams::paper_004());
        assert_eq!(b.params, ResonatorParams::paper_004());
        assert_eq!(a.front_end.sample_rate_hz, a.plan.adc_rate_hz);
        for (text, field) in [
            (
                "[resonator_b]\nq_drive = -3.0\n",
                "resonator_b.q_drive = -3",
            ),
            ("[resonator_a]\nmass_kg = 0.0\n", "resonator_a.mass_kg = 0"),
            ("[loop]\nnco_phase_bits = 70\n", "loop.nco_phase_bits = 70"),
            ("[loop]\ndemod_output_format = \"x12\"\n", "loop.demod_output_format"),
            ("[loop]\nadc_format = \"s20.19\"\n", "loop.adc_format = s20.19"),
            ("[loop]\nadc_rate_hz = -1.0\n", "loop.adc_rate_hz = -1"),
            ("[loop]\ndemod_state_format = \"s10.2\"\n", "loop.demod_state_format"),
            ("[loop]\ndecimation = 0\n", "loop.decimation = 0"),
            ("[loop]\ncic_tap_width = 1\n", "loop.cic_tap_width = 1"),
            ("[loop]\npll_gain_width = 1\n", "loop.pll_gain_width = 1"),
            (
                "[loop]\npll_integrator_format = \"s8.2\"\n",
                "loop.pll_integrator_format = s8.2",
            ),
            (
                "[loop]\nagc_output_format = \"s4.0\"\n",
                "loop.agc_output_format = s4.0 is not allowed: a format whose largest value is at least",
            ),
        ] {
            let err = Config::from_toml(text, "test.toml")
                .and_then(|c| c.gyro_loops().map(|_| ()))
                .unwrap_err()
                .to_string();
            assert!(err.contains(field), "{text}: {err}");
            assert!(!err.contains("loop.loop"), "{text}: {err}");
        }
        // Rounding and overflow are the config's: [loop] has no keys of its own for them.
        assert!(Config::from_toml("[loop]\nrounding = \"floor\"\n", "test.toml").is_err());
        let floor = Config::from_toml("rounding = \"floor\"\n", "test.toml").unwrap();
        assert_eq!(
            floor.gyro_loops().unwrap()[0].plan.settings.rounding,
            "floor"
        );
    }

    /// `[front_end_b]` sets gyro B's own keys over `[front_end]` (an inline table key by key)
    /// and leaves gyro A's; its unknown keys, wrong types and bad values are named in it.
    #[test]
    fn a_gyros_own_front_end_overlays_the_shared_one() {
        let text = "[front_end]\npickoff_noise_v_per_sqrt_hz = 2e-9\n\
                    [front_end_b]\npickoff_noise_v_per_sqrt_hz = 3e-9\n\
                    phase_drift = { std = 0.001 }\n";
        let config = Config::from_toml(text, "test.toml").unwrap();
        let [a, b] = config.gyro_loops().unwrap();
        assert_eq!(a.front_end.pickoff_noise_v_per_sqrt_hz, 2e-9);
        assert_eq!(b.front_end.pickoff_noise_v_per_sqrt_hz, 3e-9);
        assert_eq!(a.front_end.phase_drift.std, 0.02);
        assert_eq!(b.front_end.phase_drift.std, 0.001);
        assert_eq!(
            b.front_end.phase_drift.correlation_time_s,
            a.front_end.phase_drift.correlation_time_s
        );
        // The resolved config keeps the overlay, and an empty one stays out of it.
        let again = Config::from_toml(&config.to_toml(), "resolved").unwrap();
        assert_eq!(again.gyro_loops().unwrap()[1].front_end, b.front_end);
        assert!(!Config::embedded().to_toml().contains("front_end_a"));
        for (text, named) in [
            (
                "[front_end_a]\npickoff_gain = 1.0\n",
                "unknown key front_end_a.pickoff_gain (line 2)",
            ),
            (
                "[front_end_b]\ntemperature_k = \"warm\"\n",
                "front_end_b.temperature_k",
            ),
            (
                "[front_end_b]\npickoff_noise_v_per_sqrt_hz = -1.0\n",
                "front_end_b.pickoff_noise_v_per_sqrt_hz = -1 is not allowed",
            ),
            (
                "[front_end]\ntemperature_k = -4.0\n[front_end_a]\nnoise = false\n",
                "front_end.temperature_k = -4 is not allowed",
            ),
        ] {
            let err = Config::from_toml(text, "test.toml")
                .and_then(|c| c.gyro_loops().map(|_| ()))
                .unwrap_err()
                .to_string();
            assert!(err.contains(named), "{text}: {err}");
        }
    }
}
