//! `gyrofx reproduce --paper 000|002|003|004`: a paper's pipeline on simulated data, its tables
//! beside ours, and where they differ, why — one module per paper. Every report is a pure
//! function of the seed (no timings in it); [`write`] puts it in a folder with its plots.

use gyrofx_model::analysis::allan::{self, Grid, Kind, Point};
use gyrofx_model::analysis::noise;
use gyrofx_model::plant::GyroErrors;

use gyrofx_job::error::{Error, Result};

mod paper_000;
mod paper_002;
mod paper_003;
mod paper_004;

pub use paper_000::{
    paper_000, Paper000, FS_000_HZ, PAPER_000_TABLE_2, PAPER_000_TABLE_3, PAPER_000_TABLE_4,
    SAMPLES_000,
};
pub use paper_002::{
    paper_002, Disturbances, Paper002, FS_002_HZ, PAPER_002_REFERENCE, PAPER_002_TABLE_2,
    PAPER_002_TABLE_3, SAMPLES_002,
};
pub use paper_003::{
    paper_003, Paper003, FS_HZ, PAPER_AR, PAPER_TERMS_FILTERED, PAPER_TERMS_RAW, PAPER_VARIANCE,
    SAMPLES, THRESHOLD_DPS, WINDOW,
};
pub use paper_004::{paper_004, Paper004, PAPER_004_TABLE_2, SAMPLES_004};

/// Labelled Allan curves, for the report's plot.
pub type Curves = Vec<(String, Vec<Point>)>;

/// A static gyro with Table 2's ARW, bias instability, RRW and rate ramp.
pub(crate) fn paper_gyro() -> GyroErrors {
    GyroErrors {
        sf_ppm: 0.0,
        sf_mode_mismatch_ppm: 0.0,
        bias_dps: 0.0,
        bias_mode_mismatch_dps: 0.0,
        arw_deg_per_sqrt_h: PAPER_TERMS_RAW[1],
        bias_instability_deg_per_h: PAPER_TERMS_RAW[2],
        rrw_deg_per_h_per_sqrt_h: PAPER_TERMS_RAW[3],
        rate_ramp_deg_per_h2: PAPER_TERMS_RAW[4],
        settle_tau_s: 0.0,
    }
}

/// `values` minus their least-squares line (paper 003's pre-processing: constant and trend
/// removed).
/// Gyro A's output (°/s) for the true rate `rate` at `fs_hz`, at rest in one mode (no
/// reversal), with `gyro`'s errors, from `seed` (bias-instability band 0.5–500 s).
pub(crate) fn gyro_record(gyro: GyroErrors, fs_hz: f64, rate: &[f64], seed: u64) -> Vec<f64> {
    let plant = gyrofx_model::plant::Plant {
        fs_hz,
        gyros: [gyro, gyro],
        bi_tau_min_s: 0.5,
        bi_tau_max_s: 500.0,
    };
    let [a, _] = plant.simulate(rate, &vec![[1, 1]; rate.len()], seed).y;
    a
}

pub(crate) fn detrend(values: &[f64]) -> Vec<f64> {
    let n = values.len() as f64;
    let mean_t = (n - 1.0) / 2.0;
    let mean_y = values.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (k, y) in values.iter().enumerate() {
        let t = k as f64 - mean_t;
        sxy += t * (y - mean_y);
        sxx += t * t;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    values
        .iter()
        .enumerate()
        .map(|(k, y)| y - mean_y - slope * (k as f64 - mean_t))
        .collect()
}

pub(crate) fn variance(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n
}

/// The five noise terms of `rate` (°/s at `rate_hz`) in Table 2's units.
pub(crate) fn terms(rate: &[f64], rate_hz: f64) -> [f64; 5] {
    let points = allan::curve(Kind::Overlapping, rate, rate_hz, Grid::Octave);
    let fitted = noise::fit(&points, Kind::Overlapping);
    let report = noise::report(&points, &fitted, Kind::Overlapping);
    [
        report.quantization_urad.value,
        report.arw_deg_per_sqrt_h.value,
        report.bias_instability_deg_per_h.value,
        report.rrw_deg_per_h_per_sqrt_h.value,
        report.rate_ramp_deg_per_h2.value,
    ]
}

/// Writes `report` (markdown) as `report.md`, the Allan `curves` (if any) as `allan.png` and, when
/// given, a DAVAR as `davar.png`, with a `manifest.json` naming them, into `out` — all or
/// nothing, like a package. Returns the files written.
///
/// # Errors
/// A plot error (no font), or the package's output errors.
pub fn write(
    out: &std::path::Path,
    replace: gyrofx_codegen::output_folder::Replace,
    paper: &str,
    seed: u64,
    report: &str,
    curves: &Curves,
    davar: Option<(
        &gyrofx_model::analysis::davar::Davar,
        &gyrofx_model::analysis::davar::Coefficients,
    )>,
) -> Result<Vec<String>> {
    let scratch = tempfile::tempdir().map_err(|e| Error::io(std::env::temp_dir(), e))?;
    gyrofx_codegen::output_folder::check(
        out,
        gyrofx_codegen::output_folder::Kind::Reproduce,
        replace,
    )?;
    let mut package = gyrofx_codegen::package::Package::new(
        gyrofx_codegen::output_folder::Kind::Reproduce,
        Vec::new(),
    );
    package.add("report.md", report);
    let series: Vec<crate::plot::AllanSeries> = curves
        .iter()
        .map(|(label, points)| crate::plot::AllanSeries {
            label: label.clone(),
            points,
            terms: None,
        })
        .collect();
    if !series.is_empty() {
        let allan_png = scratch.path().join("allan.png");
        crate::plot::allan(&allan_png, &series)?;
        package.add(
            "allan.png",
            std::fs::read(&allan_png).map_err(|e| Error::io(&allan_png, e))?,
        );
    }
    if let Some((d, c)) = davar {
        let davar_png = scratch.path().join("davar.png");
        crate::plot::davar(&davar_png, d, c)?;
        package.add(
            "davar.png",
            std::fs::read(&davar_png).map_err(|e| Error::io(&davar_png, e))?,
        );
    }
    let mut files = package.paths();
    files.push("manifest.json".into());
    let manifest = serde_json::json!({
        "generator": format!("gyrofx {}", env!("CARGO_PKG_VERSION")),
        "command": format!("gyrofx reproduce --paper {paper} --seed {seed}"),
        "files": package.entries(),
    });
    package.add(
        "manifest.json",
        serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n",
    );
    package.write_atomically(out, replace)?;
    Ok(files)
}
