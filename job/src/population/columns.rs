//! The columns of `population.csv`: the member, its status, the values drawn and every figure,
//! one row per member. Numbers are Rust's shortest round-trip decimal form (the same on every
//! platform); an empty cell is a figure that does not exist (a member that could not run, a
//! gyro that did not lock, Allan terms without noise).

use gyrofx_model::gyro_loop::figures::ModeCharacterization;
use gyrofx_model::population::study::{GyroFigures, MemberFigures};

use super::{MemberResult, Population};

/// A member's status.
pub fn status(result: &MemberResult) -> &'static str {
    match &result.figures {
        Err(_) => "invalid",
        Ok(f) if f.gyros.iter().all(|g| g.lock.locked) => "ok",
        Ok(_) => "unlocked",
    }
}

/// Per gyro: each figure's column name (after the gyro's `a_`/`b_`) and how to read it.
type GyroColumn = (&'static str, fn(&GyroFigures) -> Option<f64>);

fn normal(g: &GyroFigures) -> &ModeCharacterization {
    &g.characterization.normal
}

fn reverse(g: &GyroFigures) -> &ModeCharacterization {
    &g.characterization.reverse
}

/// The gyro columns, in order.
const GYRO_COLUMNS: [GyroColumn; 20] = [
    ("locked", |g| Some(f64::from(u8::from(g.lock.locked)))),
    ("lock_ms", |g| g.lock.lock_ms),
    ("drive_frequency_hz", |g| {
        Some(normal(g).drive_frequency_hz.measured)
    }),
    ("scale_factor_normal", |g| {
        Some(normal(g).scale_factor.measured)
    }),
    ("scale_factor_reverse", |g| {
        Some(reverse(g).scale_factor.measured)
    }),
    ("bias_normal_dps", |g| Some(normal(g).bias_dps.measured)),
    ("bias_normal_predicted_dps", |g| {
        Some(normal(g).bias_dps.predicted)
    }),
    ("bias_reverse_dps", |g| Some(reverse(g).bias_dps.measured)),
    ("bias_reverse_predicted_dps", |g| {
        Some(reverse(g).bias_dps.predicted)
    }),
    ("residual_dps", |g| {
        Some(g.characterization.residual_bias_dps.measured)
    }),
    ("residual_predicted_dps", |g| {
        Some(g.characterization.residual_bias_dps.predicted)
    }),
    ("residual_configured_dps", |g| {
        Some(g.characterization.residual_configured_phase_dps)
    }),
    ("settling_normal_ms", |g| {
        Some(normal(g).settling_ms.measured)
    }),
    ("settling_reverse_ms", |g| {
        Some(reverse(g).settling_ms.measured)
    }),
    ("rate_settling_normal_ms", |g| {
        Some(normal(g).rate_settling_ms.measured)
    }),
    ("rate_settling_reverse_ms", |g| {
        Some(reverse(g).rate_settling_ms.measured)
    }),
    ("saturations", |g| {
        Some((normal(g).saturations.total() + reverse(g).saturations.total()) as f64)
    }),
    ("transient_saturations", |g| {
        Some(
            (normal(g).transient_saturations.total() + reverse(g).transient_saturations.total())
                as f64,
        )
    }),
    ("chain_saturations_used", |g| {
        Some(g.saturations_used as f64)
    }),
    ("chain_saturations_blanked", |g| {
        Some(g.saturations_blanked as f64)
    }),
];

/// The pair's columns, in order.
type PairColumn = (&'static str, fn(&MemberFigures) -> Option<f64>);

const PAIR_COLUMNS: [PairColumn; 9] = [
    ("output_samples", |f| Some(f.chain.output_samples as f64)),
    ("output_mean_dps", |f| f.chain.output_mean_dps),
    ("output_std_dps", |f| f.chain.output_std_dps),
    ("bias_estimate_a_dps", |f| {
        f.chain.bias_estimate_dps.map(|b| b[0])
    }),
    ("bias_estimate_b_dps", |f| {
        f.chain.bias_estimate_dps.map(|b| b[1])
    }),
    ("chain_overflows", |f| Some(f.chain.chain_overflows as f64)),
    ("arw_deg_per_sqrt_h", |f| f.chain.arw_deg_per_sqrt_h),
    ("bias_instability_deg_per_h", |f| {
        f.chain.bias_instability_deg_per_h
    }),
    ("gyro_samples", |f| Some(f.gyro_samples as f64)),
];

/// The header of `population.csv`.
pub fn header(population: &Population) -> Vec<String> {
    let mut columns = vec!["member".to_string(), "status".into(), "message".into()];
    for gyro in ["a", "b"] {
        for (parameter, _) in &population.spreads {
            columns.push(format!("{gyro}.{}", parameter.name()));
        }
    }
    for gyro in ["a", "b"] {
        for (name, _) in GYRO_COLUMNS {
            columns.push(format!("{gyro}_{name}"));
        }
    }
    columns.extend(PAIR_COLUMNS.iter().map(|(name, _)| name.to_string()));
    columns
}

/// A number as a cell: the shortest round-trip form, empty for none or a non-finite value.
pub fn cell(value: Option<f64>) -> String {
    match value {
        Some(v) if v.is_finite() => format!("{v}"),
        _ => String::new(),
    }
}

/// The message column: why a member could not run, or why a gyro did not lock.
fn message(result: &MemberResult) -> String {
    match &result.figures {
        Err(e) => e.clone(),
        Ok(f) => f
            .gyros
            .iter()
            .zip(["a", "b"])
            .filter_map(|(g, name)| g.lock.why_not.as_ref().map(|w| format!("gyro {name}: {w}")))
            .collect::<Vec<_>>()
            .join("; "),
    }
}

/// A record as one line of `population.csv`, `\n` ended: a cell holding `,`, `"`, `\r` or
/// `\n` in double quotes with its quotes doubled, every other cell as it is (what the `csv`
/// crate's default writer writes, so that the CLI and the Python package, which both write
/// through this, give the same bytes).
pub fn csv_line<S: AsRef<str>>(cells: &[S]) -> String {
    let mut line = String::new();
    for (k, cell) in cells.iter().enumerate() {
        let cell = cell.as_ref();
        if k > 0 {
            line.push(',');
        }
        if cell.contains([',', '"', '\r', '\n']) || (cells.len() == 1 && cell.is_empty()) {
            line.push('"');
            line.push_str(&cell.replace('"', "\"\""));
            line.push('"');
        } else {
            line.push_str(cell);
        }
    }
    line.push('\n');
    line
}

/// A member's row, in the order of [`header`].
pub fn row(result: &MemberResult) -> Vec<String> {
    let mut cells = vec![
        result.member.index.to_string(),
        status(result).to_string(),
        message(result),
    ];
    cells.extend(result.member.drawn.iter().map(|v| cell(Some(*v))));
    match &result.figures {
        Ok(f) => {
            for g in &f.gyros {
                cells.extend(GYRO_COLUMNS.iter().map(|(_, read)| cell(read(g))));
            }
            cells.extend(PAIR_COLUMNS.iter().map(|(_, read)| cell(read(f))));
        }
        Err(_) => cells.resize(
            cells.len() + 2 * GYRO_COLUMNS.len() + PAIR_COLUMNS.len(),
            String::new(),
        ),
    }
    cells
}
