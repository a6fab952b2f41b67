//! Serializable summaries of a design and its quantized coefficients (the `design` command's
//! JSON and the manifest share them).

use serde::Serialize;

use gyrofx_model::kf::design::{bandwidth_hz, dc_gain, Design};
use gyrofx_model::kf::{Plan, COEFFICIENT_NAMES};

use crate::text::hex;

/// One quantized coefficient.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoefficientReport {
    /// `g1` or `g2`.
    pub name: String,
    /// ROM address (`bw_sel`).
    pub address: usize,
    /// Label of the entry (e.g. "10 Hz").
    pub entry: String,
    /// The designed value.
    pub value: f64,
    /// Its format.
    pub format: String,
    /// The code.
    pub code: i64,
    /// The code as zero-padded two's-complement hex.
    pub hex: String,
    /// The quantized value.
    pub quantized: f64,
    /// `quantized − value`.
    pub error: f64,
    /// `(quantized − value) / value`.
    pub relative_error: f64,
}

/// One designed ROM entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DesignReport {
    /// ROM address.
    pub address: usize,
    /// Discretisation.
    pub method: String,
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// `q_w`, (°/s)²/s.
    pub q_w: f64,
    /// `q_b`, (°/s)²/s.
    pub q_b: f64,
    /// `q_n`, (°/s)²·s.
    pub q_n: f64,
    /// Steady-state Kalman gain.
    pub k: [f64; 2],
    /// Innovation gain.
    pub g: [f64; 2],
    /// Riccati iterations.
    pub iterations: u64,
    /// Exact −3 dB bandwidth of the designed filter, Hz (null: none below Nyquist).
    pub bandwidth_hz: Option<f64>,
    /// DC gain of `rate_hat / z`.
    pub dc_gain: f64,
    /// Bandwidth with the quantized coefficients, Hz.
    pub quantized_bandwidth_hz: Option<f64>,
    /// DC gain with the quantized coefficients.
    pub quantized_dc_gain: f64,
    /// Eigenvalues of the quantized `A = I − gH`.
    pub eigenvalues: [f64; 2],
}

/// Every coefficient of the plan's ROM.
pub fn coefficients(plan: &Plan) -> Vec<CoefficientReport> {
    let quantized = plan.quantized_gains();
    let mut out = Vec::new();
    for (address, codes) in plan.rom.iter().enumerate() {
        for i in 0..2 {
            let value = plan.gains[address][i];
            let q = quantized[address][i];
            out.push(CoefficientReport {
                name: COEFFICIENT_NAMES[i].to_string(),
                address,
                entry: plan.labels[address].clone(),
                value,
                format: plan.coefficient[i].to_string(),
                code: codes[i] as i64,
                hex: hex(codes[i], plan.coefficient[i]),
                quantized: q,
                error: q - value,
                relative_error: if value == 0.0 {
                    0.0
                } else {
                    (q - value) / value
                },
            });
        }
    }
    out
}

/// The designs with their quantized counterparts.
pub fn designs(designs: &[Design], plan: &Plan) -> Vec<DesignReport> {
    let quantized = plan.quantized_gains();
    designs
        .iter()
        .enumerate()
        .map(|(address, d)| DesignReport {
            address,
            method: d.method.name().to_string(),
            fs_hz: d.fs_hz,
            q_w: d.noise.q_w,
            q_b: d.noise.q_b,
            q_n: d.noise.q_n,
            k: d.k,
            g: d.g,
            iterations: d.iterations,
            bandwidth_hz: d.bandwidth_hz,
            dc_gain: d.dc_gain,
            quantized_bandwidth_hz: bandwidth_hz(quantized[address], d.fs_hz),
            quantized_dc_gain: dc_gain(quantized[address]),
            eigenvalues: plan.eigenvalues(address),
        })
        .collect()
}
