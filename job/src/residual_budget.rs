//! The residual-bias budget of a config's two gyro loops (issue 32): what each part of the loop
//! moves `(B − B′)/2` by (`gyrofx_model::gyro_loop::residual_budget`), the cheapest NCO and
//! trim that keep it within a target, what each NCO width and latency would cost, and the
//! closed fixed loop's measured residual beside the budget, for `gyrofx formats
//! --residual-budget`.

use std::fmt;

use serde::Serialize;

use gyrofx_model::gyro_loop::closed::FixedHarness;
use gyrofx_model::gyro_loop::figures::{characterize, Procedure};
use gyrofx_model::gyro_loop::gyro::{Plan, Spec};
use gyrofx_model::gyro_loop::residual_budget::{
    choose, twin_leftover_dps, Choice, Cost, NcoSettings, ResidualBudget, Unreachable,
};

use crate::config::Config;
use crate::error::{Error, Result};

/// One gyro's budget as configured and as chosen, with the fixed loop's measured departure
/// from `R_c` for each.
#[derive(Clone, Debug, Serialize)]
pub struct GyroBudget {
    /// `a` or `b`.
    pub gyro: &'static str,
    /// The configured loop's budget.
    pub configured: ResidualBudget,
    /// The closed fixed loop, as configured.
    pub configured_measured: Measured,
    /// The chosen loop's budget.
    pub chosen: ResidualBudget,
    /// The closed fixed loop, as chosen.
    pub chosen_measured: Measured,
}

/// What one setting's values cost in residual at gyro `a`, the rest as configured: `(value,
/// °/s)`.
#[derive(Clone, Debug, Serialize)]
pub struct Sweep {
    /// The `[loop]` key.
    pub setting: &'static str,
    /// The budget parts it sets (their costs summed).
    pub parts: &'static [&'static str],
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

/// The closed fixed loop's residual less `R_c`, °/s, noise off, and what saturated while it
/// was measured (`None`: nothing).
fn measured_departure(spec: &Spec, budget: &ResidualBudget) -> Result<Measured> {
    let plan = Plan::new(spec).map_err(|e| loop_error(e.to_string()))?;
    let c = characterize::<FixedHarness>(
        &plan,
        &spec.resonator,
        &spec.front_end,
        &Procedure::default(),
    )
    .map_err(|e| loop_error(e.to_string()))?;
    let mut saturations = c.normal.saturations;
    saturations.add(&c.reverse.saturations);
    Ok(Measured {
        departure_dps: c.residual_bias_dps.measured - budget.configured_dps,
        clipped: (saturations.total() > 0).then(|| saturations.summary()),
    })
}

/// A closed-loop measurement of the residual.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    /// The residual less `R_c`, °/s.
    pub departure_dps: f64,
    /// The fixed loop's nodes that saturated or wrapped while the figures were measured, as
    /// `gyrofx loop` counts them (`None`: none; otherwise the departure is clipped).
    pub clipped: Option<String>,
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
    #[error("--residual-budget {target_mdps} mdps is not allowed: {unreachable}")]
    Target {
        /// The target, mdps.
        target_mdps: f64,
        /// What the finest loop leaves.
        unreachable: Unreachable,
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
    let mut gyros = Vec::new();
    for gyro in &loops {
        let spec = gyro.spec();
        let leftover = twin_leftover_dps(&spec).map_err(loop_error)?;
        gyros.push((spec, leftover));
    }
    let Choice { settings, budgets } =
        choose(&gyros, target_dps).map_err(|unreachable| BudgetError::Target {
            target_mdps: 1e3 * target_dps,
            unreachable,
        })?;
    let mut reports = Vec::new();
    for ((gyro, (spec, leftover)), chosen) in loops.iter().zip(&gyros).zip(budgets) {
        let configured = ResidualBudget::new(&gyro.plan, &gyro.params).with_twin(*leftover);
        reports.push(GyroBudget {
            gyro: gyro.name,
            configured_measured: measured_departure(spec, &configured)?,
            chosen_measured: measured_departure(&settings.apply(spec), &chosen)?,
            configured,
            chosen,
        });
    }
    Ok(Report {
        target_dps,
        configured: NcoSettings::of(&gyros[0].0),
        chosen: settings,
        gyros: reports,
        sweeps: sweeps(&gyros[0].0),
    })
}

/// Each of `A`, `P` and `L` alone, the rest of `spec` as configured.
fn sweeps(spec: &Spec) -> Vec<Sweep> {
    let cost = |parts: &[&str], set: &dyn Fn(&mut Spec)| -> Option<f64> {
        let mut spec = spec.clone();
        set(&mut spec);
        let plan = Plan::new(&spec).ok()?;
        let budget = ResidualBudget::new(&plan, &spec.resonator);
        Some(
            budget
                .parts
                .iter()
                .filter(|p| parts.contains(&p.name))
                .map(|p| match p.cost {
                    Cost::Bound(v) | Cost::Derived(v) | Cost::Measured(v) => v,
                })
                .sum(),
        )
    };
    let sweep = |setting,
                 parts: &'static [&'static str],
                 values: std::ops::RangeInclusive<u32>,
                 set: fn(&mut Spec, u32)| Sweep {
        setting,
        parts,
        costs: values
            .filter_map(|v| cost(parts, &|s| set(s, v)).map(|c| (v, c)))
            .collect(),
    };
    vec![
        sweep("nco_address_bits", &["NCO truncation"], 6..=14, |s, v| {
            s.settings.nco_address_bits = v;
        }),
        sweep(
            "nco_phase_bits",
            &["offset word", "PLL frequency step"],
            16..=36,
            |s, v| {
                s.settings.nco_phase_bits = v;
            },
        ),
        sweep("adc_to_dac_latency_samples", &["latency"], 0..=8, |s, v| {
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
                self.configured_measured.departure_dps,
                self.chosen_measured.departure_dps,
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
        for (which, measured) in [
            ("configured", &self.configured_measured),
            ("chosen", &self.chosen_measured),
        ] {
            if let Some(clipped) = &measured.clipped {
                writeln!(
                    f,
                    "  warning: the {which} loop saturated while it was measured ({clipped}): its measured residual is clipped, not the loop's"
                )?;
            }
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
            write!(f, "  {:<27} ({}):", sweep.setting, sweep.parts.join(" + "))?;
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
