//! The residual-bias budget of a config's two gyro loops (issue 32): what each part of the loop
//! moves `(B − B′)/2` by (`gyrofx_model::gyro_loop::residual_budget`), the cheapest NCO and
//! trim that keep it within a target, what each NCO width and latency would cost, and the
//! closed fixed loop's measured residual beside the budget, for `gyrofx formats
//! --residual-budget`.

use std::fmt;

use serde::Serialize;

use gyrofx_model::gyro_loop::closed::FixedHarness;
use gyrofx_model::gyro_loop::figures::characterize;
use gyrofx_model::gyro_loop::gyro::{Plan, Spec};
use gyrofx_model::gyro_loop::residual_budget::{
    choose, procedure, twin_leftover_dps, Choice, Cost, ResidualBudget,
};

use crate::config::Config;
use crate::config::GyroLoop;
use crate::error::{Error, Result};

/// The NCO and trim settings the budget chooses between.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct NcoSettings {
    /// `nco_address_bits`, `A`.
    pub nco_address_bits: u32,
    /// `nco_phase_bits`, `P`.
    pub nco_phase_bits: u32,
    /// `nco_error_feedback`.
    pub nco_error_feedback: bool,
    /// `phase_trim`.
    pub phase_trim: bool,
}

/// One gyro's budget as configured and as chosen, with the fixed loop's measured departure
/// from `R_c` for each.
#[derive(Clone, Debug, Serialize)]
pub struct GyroBudget {
    /// `a` or `b`.
    pub gyro: &'static str,
    /// The configured loop's budget.
    pub configured: ResidualBudget,
    /// The closed fixed loop's residual less `R_c`, as configured, °/s.
    pub configured_measured_dps: f64,
    /// The chosen loop's budget.
    pub chosen: ResidualBudget,
    /// The closed fixed loop's residual less `R_c`, as chosen, °/s.
    pub chosen_measured_dps: f64,
}

/// What one setting's values cost in residual at gyro `a`, the rest as configured: `(value,
/// °/s)`.
#[derive(Clone, Debug, Serialize)]
pub struct Sweep {
    /// The `[loop]` key.
    pub setting: &'static str,
    /// The budget parts it sets (their costs summed).
    pub part: &'static str,
    /// Each value and its part's cost (a bound), °/s.
    pub costs: Vec<(u32, f64)>,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The target, °/s.
    pub target_dps: f64,
    /// The settings as configured.
    pub configured: NcoSettings,
    /// The settings chosen.
    pub chosen: NcoSettings,
    /// Both gyros.
    pub gyros: Vec<GyroBudget>,
    /// NCO address bits, phase bits and latency, each alone.
    pub sweeps: Vec<Sweep>,
}

impl NcoSettings {
    fn of(spec: &Spec) -> Self {
        let s = &spec.settings;
        NcoSettings {
            nco_address_bits: s.nco_address_bits,
            nco_phase_bits: s.nco_phase_bits,
            nco_error_feedback: s.nco_error_feedback,
            phase_trim: s.phase_trim,
        }
    }

    fn apply(&self, spec: &Spec) -> Spec {
        let mut spec = spec.clone();
        let s = &mut spec.settings;
        s.nco_address_bits = self.nco_address_bits;
        s.nco_phase_bits = self.nco_phase_bits;
        s.nco_error_feedback = self.nco_error_feedback;
        s.phase_trim = self.phase_trim;
        spec
    }
}

fn spec_of(gyro: &GyroLoop) -> Spec {
    Spec {
        settings: gyro.plan.settings.clone(),
        resonator: gyro.params,
        front_end: gyro.front_end,
    }
}

/// Parses a `--residual-budget` target: a number of mdps (`1mdps`) or °/s (`0.001dps`),
/// positive.
pub fn parse_target(text: &str) -> std::result::Result<f64, String> {
    let trimmed = text.trim();
    let (number, scale) = if let Some(n) = trimmed.strip_suffix("mdps") {
        (n, 1e-3)
    } else if let Some(n) = trimmed.strip_suffix("dps") {
        (n, 1.0)
    } else {
        return Err(format!("--residual-budget {text} is not a target: a residual bias in mdps (1mdps) or °/s (0.001dps)"));
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
        _ => Err(format!(
            "--residual-budget {text} is not a target: a positive residual bias in mdps (1mdps) or °/s (0.001dps)"
        )),
    }
}

/// The closed fixed loop's residual less `R_c`, °/s, noise off.
fn measured_departure(spec: &Spec, budget: &ResidualBudget) -> Result<f64> {
    let plan = Plan::new(spec).map_err(|e| loop_error(e.to_string()))?;
    let c = characterize::<FixedHarness>(&plan, &spec.resonator, &spec.front_end, &procedure())
        .map_err(|e| loop_error(e.to_string()))?;
    Ok(c.residual_bias_dps.measured - budget.configured_dps)
}

fn loop_error(message: String) -> Error {
    Error::Config {
        field: "loop".into(),
        value: String::new(),
        allowed: message,
    }
}

/// Why there is no budget: the target (a usage error) or the config.
#[derive(Debug, thiserror::Error)]
pub enum BudgetError {
    /// No NCO meets the target; the message names the floor.
    #[error("--residual-budget {target_mdps} mdps is not allowed: {message}")]
    Target {
        /// The target, mdps.
        target_mdps: f64,
        /// What the finest loop leaves.
        message: String,
    },
    /// The loops cannot be planned or measured.
    #[error(transparent)]
    Config(#[from] Error),
}

/// The budget of `config`'s loops, the choice for `target_dps` and the measured residuals.
///
/// # Errors
/// A config whose loops cannot be planned, or a target no NCO meets (naming the floor).
pub fn residual_budget(
    config: &Config,
    target_dps: f64,
) -> std::result::Result<Report, BudgetError> {
    let loops = config.gyro_loops()?;
    let specs: Vec<Spec> = loops.iter().map(spec_of).collect();
    let leftovers = specs
        .iter()
        .map(twin_leftover_dps)
        .collect::<std::result::Result<Vec<f64>, String>>()
        .map_err(loop_error)?;
    let Choice {
        nco_address_bits,
        nco_phase_bits,
        nco_error_feedback,
        phase_trim,
        budgets,
    } = choose(&specs, &leftovers, target_dps).map_err(|message| BudgetError::Target {
        target_mdps: 1e3 * target_dps,
        message,
    })?;
    let chosen = NcoSettings {
        nco_address_bits,
        nco_phase_bits,
        nco_error_feedback,
        phase_trim,
    };
    let mut gyros = Vec::new();
    for (((gyro, spec), chosen_budget), &leftover) in
        loops.iter().zip(&specs).zip(budgets).zip(&leftovers)
    {
        let configured = ResidualBudget::new(&gyro.plan, &gyro.params).with_twin(leftover);
        let chosen_spec = chosen.apply(spec);
        gyros.push(GyroBudget {
            gyro: gyro.name,
            configured_measured_dps: measured_departure(spec, &configured)?,
            chosen_measured_dps: measured_departure(&chosen_spec, &chosen_budget)?,
            configured,
            chosen: chosen_budget,
        });
    }
    Ok(Report {
        target_dps,
        configured: NcoSettings::of(&specs[0]),
        chosen,
        gyros,
        sweeps: sweeps(&specs[0]),
    })
}

/// Each of `A`, `P` and `L` alone, the rest of `spec` as configured.
fn sweeps(spec: &Spec) -> Vec<Sweep> {
    let cost = |part: &'static str, set: &dyn Fn(&mut Spec)| -> Option<f64> {
        let mut spec = spec.clone();
        set(&mut spec);
        let plan = Plan::new(&spec).ok()?;
        let budget = ResidualBudget::new(&plan, &spec.resonator);
        let names: Vec<&str> = part.split(" + ").collect();
        Some(
            budget
                .parts
                .iter()
                .filter(|p| names.contains(&p.name))
                .map(|p| match p.cost {
                    Cost::Bound(v) | Cost::Derived(v) | Cost::Measured(v) => v,
                })
                .sum(),
        )
    };
    let sweep =
        |setting, part, values: std::ops::RangeInclusive<u32>, set: fn(&mut Spec, u32)| Sweep {
            setting,
            part,
            costs: values
                .filter_map(|v| cost(part, &|s| set(s, v)).map(|c| (v, c)))
                .collect(),
        };
    vec![
        sweep("nco_address_bits", "NCO truncation", 6..=14, |s, v| {
            s.settings.nco_address_bits = v;
        }),
        sweep(
            "nco_phase_bits",
            "offset word + PLL frequency step",
            16..=36,
            |s, v| {
                s.settings.nco_phase_bits = v;
            },
        ),
        sweep("adc_to_dac_latency_samples", "latency", 0..=8, |s, v| {
            s.settings.adc_to_dac_latency_samples = v;
        }),
    ]
}

impl Report {
    /// Writes the chosen settings into `config`'s `[loop]`.
    pub fn apply(&self, config: &mut Config) {
        let c = &self.chosen;
        let table = &mut config.gyro_loop;
        table.insert(
            "nco_address_bits".into(),
            i64::from(c.nco_address_bits).into(),
        );
        table.insert("nco_phase_bits".into(), i64::from(c.nco_phase_bits).into());
        table.insert("nco_error_feedback".into(), c.nco_error_feedback.into());
        table.insert("phase_trim".into(), c.phase_trim.into());
    }
}

/// A phase in degrees, `0` where a part does not move it.
fn degrees(phase: f64) -> String {
    if phase == 0.0 {
        "0".into()
    } else {
        format!("{phase:+.2e}")
    }
}

/// A cost in mdps to three significant digits.
fn short_mdps(dps: f64) -> String {
    let m = 1e3 * dps;
    if m.abs() >= 1e-3 {
        format!("{m:.3}")
    } else {
        format!("{m:.1e}")
    }
}

fn mdps(cost: Cost) -> String {
    match cost {
        Cost::Derived(v) | Cost::Measured(v) => format!("{:+.4}", 1e3 * v),
        Cost::Bound(v) => format!("≤ {:.4}", 1e3 * v),
    }
}

impl fmt::Display for NcoSettings {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "nco_address_bits = {}, nco_phase_bits = {}, nco_error_feedback = {}, phase_trim = {}",
            self.nco_address_bits, self.nco_phase_bits, self.nco_error_feedback, self.phase_trim
        )
    }
}

impl fmt::Display for GyroBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (c, h) = (&self.configured, &self.chosen);
        writeln!(
            f,
            "gyro {}: R_c = {:+.4} mdps at the configured phases; |dB/dφ| = {:.4} / {:.4} °/s per degree (normal / reverse)",
            self.gyro,
            1e3 * c.configured_dps,
            c.slope_dps_per_deg[0],
            c.slope_dps_per_deg[1]
        )?;
        writeln!(
            f,
            "  {:<20} {:<40} {:>22} {:>12} {:>12}",
            "part", "settings", "phase deg (normal, reverse)", "configured", "chosen"
        )?;
        for (part, chosen) in c.parts.iter().zip(&h.parts) {
            writeln!(
                f,
                "  {:<20} {:<40} {:>11},{:>10} {:>12} {:>12}",
                part.name,
                part.settings,
                degrees(part.phase_deg[0]),
                degrees(part.phase_deg[1]),
                mdps(part.cost),
                mdps(chosen.cost)
            )?;
        }
        let rows: [(&str, f64, f64); 4] = [
            ("derived + twin", c.derived_dps(), h.derived_dps()),
            ("bounds", c.bound_dps(), h.bound_dps()),
            ("worst case", c.worst_dps(), h.worst_dps()),
            (
                "measured",
                self.configured_measured_dps,
                self.chosen_measured_dps,
            ),
        ];
        for (name, configured, chosen) in rows {
            writeln!(
                f,
                "  {:<20} {:<63} {:>+12.4} {:>+12.4}",
                name,
                "",
                1e3 * configured,
                1e3 * chosen
            )?;
        }
        for (mode, p, q) in &c.small_fractions {
            writeln!(
                f,
                "  warning: the {mode} mode locks on {p}/{q} of the ADC rate, where the ROM's and the DAC's roundings repeat instead of averaging out (up to 1.4e-3° of phase seen): the budget does not cover that; another adc_rate_hz moves the lock off it"
            )?;
        }
        Ok(())
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "residual bias after reversal, (B − B′)/2: what each part of the loop moves it by from R_c, mdps (derived: signed; ≤: a bound; measured: the closed fixed loop, noise off)"
        )?;
        for gyro in &self.gyros {
            write!(f, "{gyro}")?;
        }
        writeln!(
            f,
            "each setting alone (gyro a, the rest as configured), mdps:"
        )?;
        for sweep in &self.sweeps {
            write!(f, "  {:<27} ({}):", sweep.setting, sweep.part)?;
            for (value, cost) in &sweep.costs {
                write!(f, " {value}: {}", short_mdps(*cost))?;
            }
            writeln!(f)?;
        }
        writeln!(f, "configured: {}", self.configured)?;
        writeln!(
            f,
            "chosen for {:.4} mdps (the fewest ROM address bits, then phase bits, whose worst case meets it): {}",
            1e3 * self.target_dps,
            self.chosen
        )
    }
}
