//! `gyrofx ar`: autoregressive models of a record by Yule–Walker, and the order AIC picks.

use std::process::ExitCode;

use anyhow::Result;

use gyrofx_model::analysis::ar;

use super::options::CsvColumn;

/// AR(1..p) models of a record and the order AIC picks (paper 003).
///
/// Fitted by Yule–Walker (Levinson–Durbin): each order's coefficients, σ_a² and AIC.
// The CSV flags are the shared ones, worded for AR; without a trailing period, as clap shows a
// one-sentence doc comment.
#[derive(clap::Args)]
#[command(mut_arg("input", |a| a.help("CSV file with a header line; `#` lines are skipped, and rows with an empty cell or blank rows are skipped and counted")))]
#[command(mut_arg("column", |a| a.help("Column to model")))]
pub struct Args {
    #[command(flatten)]
    csv: CsvColumn,
    /// Largest order, 1..=1000 (the work grows as its square).
    #[arg(long, default_value_t = 3, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=MAX_ORDER))]
    max_order: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// Largest `--max-order`: Levinson–Durbin's work and the table grow as its square.
const MAX_ORDER: u64 = 1000;

/// Prints every order's coefficients, noise variance and AIC (a table, or JSON).
pub fn run(args: Args) -> Result<ExitCode> {
    let Args {
        csv,
        max_order,
        json,
    } = args;
    let column = &csv.column()?;
    let (values, skipped) = csv.read_with_gaps()?;
    if let Some(note) = super::options::gaps_note(&csv.input, column, skipped) {
        eprintln!("{note}");
    }
    let models = ar::fit_orders(&values, max_order)
        .map_err(|e| anyhow::anyhow!("{}, column {column}: {e}", csv.input.display()))?;
    let chosen = ar::select_by_aic(&models).order;
    if json {
        let value = serde_json::json!({
            "samples": values.len(),
            "skipped_empty_cells": skipped,
            "aic_order": chosen,
            "models": models.iter().map(|m| serde_json::json!({
                "order": m.order,
                "coefficients": m.coefficients,
                "noise_variance": m.noise_variance,
                "aic": m.aic,
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{} samples of {column}; AIC = N ln(sigma_a^2) + 2n",
            values.len()
        );
        println!("order  sigma_a^2      AIC            coefficients (phi1..phip)");
        for m in &models {
            let phi: Vec<String> = m.coefficients.iter().map(|c| format!("{c:+.5}")).collect();
            let mark = if m.order == chosen { "  <- AIC" } else { "" };
            println!(
                "{:>5}  {:<13.6e}  {:<13.4}  {}{mark}",
                m.order,
                m.noise_variance,
                m.aic,
                phi.join(" ")
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
