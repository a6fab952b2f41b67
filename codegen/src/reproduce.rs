//! `gyrofx reproduce --paper 000|002|003|004`: a paper's pipeline on simulated data, its tables
//! beside ours, and where they differ, why. Every report is a pure function of the seed (no
//! timings in it).
//!
//! Paper 000 (ADXRS300, 200 Hz, steady-state KF at 10/20/30 Hz): Table 2 (noise density, ARW,
//! bias drift before and after), Table 3 (constant rates 10/30/50/80 °/s, KF 10 Hz: mean and
//! STD of the error), Table 4 (20 °/s swing at 0.1/0.3/0.5 Hz, KF 20 Hz: amplitude and STD of
//! the error). See [`paper_000`].
//!
//! Paper 003 (MPU6050 X axis at rest, 50 Hz, N = 3600 — the length its AIC values imply):
//! Allan noise terms of the raw drift (its Table 2), mean filter with gross-error rejection
//! (L = 20, r = 0.3 °/s), AR(1..3) by Yule–Walker with AIC (Table 3), the scalar KF on the AR(1)
//! model, and the variance and noise terms before and after (Tables 3 and 4). Here a static gyro
//! is simulated with Table 2's ARW, bias instability, RRW and rate ramp, and run through the
//! same steps with gyrofx's models (float golden models; the fixed-point ones agree within their
//! bounds).

use std::fmt::Write as _;

use gyrofx_model::analysis::allan::{self, Grid, Kind, Point};
use gyrofx_model::analysis::ar::{self, ArModel};
use gyrofx_model::analysis::denoise;
use gyrofx_model::analysis::emd::Ensemble;
use gyrofx_model::analysis::noise;
use gyrofx_model::analysis::spectrum;
use gyrofx_model::ar_kf::{self, FloatArKf};
use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::kf::design::{design_for_bandwidth, Convergence, Method, Noise};
use gyrofx_model::kf::FloatKf;
use gyrofx_model::mean_filter::{self, FloatMeanFilter};
use gyrofx_model::plant::{GyroErrors, Plant};

use crate::error::{Error, Result};

/// Labelled Allan curves, for the report's plot.
pub type Curves = Vec<(String, Vec<Point>)>;

/// Paper 003's sample rate, Hz.
pub const FS_HZ: f64 = 50.0;
/// Its record length: its Table 3 AIC values are `N ln σ² + 2n` with N = 3600 samples of the
/// mean-filter output, i.e. 72000 raw samples (24 min at 50 Hz) if that output is decimated.
pub const SAMPLES: usize = 72_000;
/// Its mean filter: L and r (°/s).
pub const WINDOW: u32 = 20;
/// r, °/s.
pub const THRESHOLD_DPS: f64 = 0.3;

/// Paper 003's Table 2 (raw drift): quantization noise (µrad), ARW (°/√h), bias instability
/// (°/h), RRW (°/h/√h), rate ramp (°/h²); and Table 4's values after its Kalman filter.
pub const PAPER_TERMS_RAW: [f64; 5] = [0.1663, 0.95164, 0.60565, 0.07759, 0.43223];
/// Table 4, after the Kalman filter.
pub const PAPER_TERMS_FILTERED: [f64; 5] = [3.526e-4, 0.03816, 0.03352, 0.01568, 0.09564];
/// Table 3 (variance): raw, after the mean filter, after the Kalman filter, (°/s)².
pub const PAPER_VARIANCE: [f64; 3] = [0.0667, 0.0528, 0.0021];
/// Table 3 (models): φ1..φ3, σ_a² and AIC of AR(1), AR(2), AR(3).
pub const PAPER_AR: [([f64; 3], f64, f64); 3] = [
    ([-0.2855, 0.0, 0.0], 0.0577, -10266.9931),
    ([-0.2738, -0.0411, 0.0], 0.0576, -10271.2378),
    ([-0.2796, -0.0802, -0.1428], 0.0564, -10345.0300),
];

/// What the run of paper 003's pipeline found.
#[derive(Clone, Debug)]
pub struct Paper003 {
    /// Samples simulated (50 Hz).
    pub samples: usize,
    /// Seed.
    pub seed: u64,
    /// Variance of the raw record (mean and trend removed), after the mean filter, after the
    /// KF, (°/s)².
    pub variance: [f64; 3],
    /// Mean-filter outputs, and how many of their blocks dropped at least one sample.
    pub blocks: usize,
    /// Blocks with a rejected sample.
    pub blocks_with_rejections: usize,
    /// AR(1..3) of the mean-filter output.
    pub models: Vec<ArModel>,
    /// The order AIC picks.
    pub aic_order: usize,
    /// R used by the KF: the variance of the mean-filtered data.
    pub measurement_variance: f64,
    /// The KF's steady-state gain and its DC gain `K/(1 − (1 − K)φ)`.
    pub steady_gain: f64,
    /// DC gain of the steady-state filter.
    pub dc_gain: f64,
    /// The R (as a multiple of the mean-filtered variance) for which the KF lowers the variance
    /// by the paper's ratio 0.0021/0.0528, and the DC gain it then has.
    pub paper_ratio_r: Option<(f64, f64)>,
    /// Noise terms (as [`PAPER_TERMS_RAW`]) of the raw record and of the KF output.
    pub terms: [[f64; 5]; 2],
    /// Allan curves of the raw record and the KF output.
    pub curves: Curves,
}

/// A static gyro with Table 2's ARW, bias instability, RRW and rate ramp.
fn paper_gyro() -> GyroErrors {
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
fn detrend(values: &[f64]) -> Vec<f64> {
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

fn variance(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n
}

/// The five noise terms of `rate` (°/s at `rate_hz`) in Table 2's units.
fn terms(rate: &[f64], rate_hz: f64) -> [f64; 5] {
    let points = allan::curve(Kind::Overlapping, rate, rate_hz, Grid::Octave);
    let fitted = noise::fit(&points);
    let report = noise::report(&points, &fitted);
    [
        report.quantization_urad.value,
        report.arw_deg_per_sqrt_h.value,
        report.bias_instability_deg_per_h.value,
        report.rrw_deg_per_h_per_sqrt_h.value,
        report.rate_ramp_deg_per_h2.value,
    ]
}

/// Runs paper 003's pipeline on `samples` simulated samples from `seed`.
///
/// # Errors
/// [`Error::Simulation`] when the record is too short for the AR fit or the filters.
pub fn paper_003(samples: usize, seed: u64) -> Result<Paper003> {
    if samples < 40 * WINDOW as usize {
        return Err(Error::Simulation(format!(
            "--samples {samples} is too few for paper 003's pipeline: at least {} (40 mean-filter blocks)",
            40 * WINDOW
        )));
    }
    let plant = Plant {
        fs_hz: FS_HZ,
        gyros: [paper_gyro(), paper_gyro()],
        bi_tau_min_s: 0.5,
        bi_tau_max_s: 500.0,
    };
    let record = plant.simulate(&vec![0.0; samples], &vec![[1, 1]; samples], seed);
    let raw = detrend(&record.y[0]);

    // Mean filter (float golden model: r as the input format quantizes it, s24.14).
    let input = Format::signed(24, 14).expect("s24.14");
    let plan = mean_filter::Plan::new(&mean_filter::Spec {
        input,
        output: input,
        window: WINDOW,
        threshold_dps: THRESHOLD_DPS,
        reciprocal_width: 25,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    })
    .expect("paper 003's mean filter plans");
    let mut filter = FloatMeanFilter::new(&plan);
    let mut filtered = Vec::with_capacity(samples / WINDOW as usize);
    let mut blocks_with_rejections = 0;
    for x in &raw {
        if let Some((y, kept)) = filter.step(*x) {
            filtered.push(y);
            blocks_with_rejections += usize::from(kept < WINDOW);
        }
    }

    let models = ar::fit_orders(&filtered, 3)
        .map_err(|e| Error::Simulation(format!("AR fit of the mean-filter output: {e}")))?;
    let aic_order = ar::select_by_aic(&models).order;
    let ar1 = &models[0];
    let measurement_variance = variance(&filtered);
    let spec = |r: f64| ar_kf::Spec {
        phi: ar1.coefficients[0],
        process_variance: ar1.noise_variance,
        measurement_variance: r,
        tolerance: 1e-12,
        max_entries: 256,
        input,
        state: Format::signed(32, 22).expect("s32.22"),
        output: input,
        coefficient_width: 25,
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
    };
    let run_kf = |plan: &ar_kf::Plan| -> Vec<f64> {
        let mut kf = FloatArKf::designed(plan);
        filtered.iter().map(|z| kf.step(*z)).collect()
    };
    let dc_gain_of = |plan: &ar_kf::Plan| {
        let k = *plan.gains.last().expect("a schedule");
        (k, k / (1.0 - (1.0 - k) * plan.phi))
    };
    let kf_plan = ar_kf::Plan::new(&spec(measurement_variance))
        .map_err(|e| Error::Simulation(format!("AR(1) KF: {e}")))?;
    let kf_output = run_kf(&kf_plan);
    let (steady_gain, dc_gain) = dc_gain_of(&kf_plan);
    // Bisection in log R for the paper's variance ratio (the output variance falls as R grows).
    let target = PAPER_VARIANCE[2] / PAPER_VARIANCE[1];
    let ratio_at = |r: f64| -> Option<f64> {
        let plan = ar_kf::Plan::new(&spec(r)).ok()?;
        Some(variance(&run_kf(&plan)) / measurement_variance)
    };
    let (mut lo, mut hi) = (measurement_variance * 1e-3, measurement_variance * 1e6);
    let paper_ratio_r = match (ratio_at(lo), ratio_at(hi)) {
        (Some(a), Some(b)) if a > target && b < target => {
            for _ in 0..60 {
                let mid = (lo * hi).sqrt();
                match ratio_at(mid) {
                    Some(ratio) if ratio > target => lo = mid,
                    _ => hi = mid,
                }
            }
            ar_kf::Plan::new(&spec(hi))
                .ok()
                .map(|plan| (hi / measurement_variance, dc_gain_of(&plan).1))
        }
        _ => None,
    };

    let filtered_rate = FS_HZ / f64::from(WINDOW);
    Ok(Paper003 {
        samples,
        seed,
        variance: [variance(&raw), variance(&filtered), variance(&kf_output)],
        blocks: filtered.len(),
        blocks_with_rejections,
        models,
        aic_order,
        measurement_variance,
        steady_gain,
        dc_gain,
        paper_ratio_r,
        terms: [terms(&raw, FS_HZ), terms(&kf_output, filtered_rate)],
        curves: vec![
            (
                "raw (50 Hz)".into(),
                allan::curve(Kind::Overlapping, &raw, FS_HZ, Grid::Octave),
            ),
            (
                "mean filter + AR(1) KF (2.5 Hz)".into(),
                allan::curve(Kind::Overlapping, &kf_output, filtered_rate, Grid::Octave),
            ),
        ],
    })
}

impl Paper003 {
    /// The report: each table, paper beside ours, then the differences explained.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "# Paper 003 reproduced on simulated data\n\n\
             A static gyro with the paper's Table 2 noise terms (ARW {} °/√h, bias instability {} \
             °/h, RRW {} °/h/√h, rate ramp {} °/h²), {} samples at {} Hz, seed {}; mean and trend \
             removed; mean filter L = {}, r = {} °/s; AR(1..3) by Yule–Walker on the mean-filter \
             output; the AR(1) KF with Q = σ_a² of AR(1), R = the variance of the mean-filtered \
             data (the paper: \"the variance of the estimation error of the sample data\"), \
             P0 = 0, x0 = z0.\n\n",
            PAPER_TERMS_RAW[1],
            PAPER_TERMS_RAW[2],
            PAPER_TERMS_RAW[3],
            PAPER_TERMS_RAW[4],
            self.samples,
            FS_HZ,
            self.seed,
            WINDOW,
            THRESHOLD_DPS,
        );
        out.push_str("## Variance, (°/s)² (Table 3)\n\n| | raw | mean filter | Kalman filter |\n|---|---:|---:|---:|\n");
        let _ = writeln!(
            out,
            "| paper | {} | {} | {} |\n| gyrofx | {:.4} | {:.4} | {:.4} |",
            PAPER_VARIANCE[0],
            PAPER_VARIANCE[1],
            PAPER_VARIANCE[2],
            self.variance[0],
            self.variance[1],
            self.variance[2]
        );
        out.push_str("\n## AR models of the mean-filter output (Table 3)\n\n| | φ1 | φ2 | φ3 | σ_a² | AIC |\n|---|---:|---:|---:|---:|---:|\n");
        for (i, (phi, var, aic)) in PAPER_AR.iter().enumerate() {
            let _ = writeln!(
                out,
                "| paper AR({}) | {} | {} | {} | {} | {} |",
                i + 1,
                phi[0],
                phi[1],
                phi[2],
                var,
                aic
            );
        }
        for m in &self.models {
            let phi: Vec<String> = (0..3)
                .map(|j| {
                    m.coefficients
                        .get(j)
                        .map_or("0".to_string(), |c| format!("{c:.4}"))
                })
                .collect();
            let _ = writeln!(
                out,
                "| gyrofx AR({}) | {} | {:.4} | {:.2} |",
                m.order,
                phi.join(" | "),
                m.noise_variance,
                m.aic
            );
        }
        let _ = writeln!(
            out,
            "\nAIC picks AR({}) here. The paper's text picks AR(1), but by its own table AR(3) has \
             the smallest AIC (its values are N ln σ² + 2n with N = 3600).",
            self.aic_order
        );
        out.push_str("\n## Noise terms before and after the Kalman filter (Tables 2 and 4)\n\n| term | paper raw | gyrofx raw | paper KF | gyrofx KF |\n|---|---:|---:|---:|---:|\n");
        let names = [
            "quantization noise (µrad)",
            "ARW (°/√h)",
            "bias instability (°/h)",
            "RRW (°/h/√h)",
            "rate ramp (°/h²)",
        ];
        for (i, name) in names.iter().enumerate() {
            let _ = writeln!(
                out,
                "| {name} | {} | {:.4} | {} | {:.4} |",
                PAPER_TERMS_RAW[i], self.terms[0][i], PAPER_TERMS_FILTERED[i], self.terms[1][i]
            );
        }
        let white_variance = (PAPER_TERMS_RAW[1] / 60.0).powi(2) * FS_HZ;
        let _ = write!(
            out,
            "\n## Where and why they differ\n\n\
             - Raw variance: an ARW of {arw} °/√h at {fs} Hz is a white-noise variance of \
             (ARW/60)²·fs = {white:.4} (°/s)², which is what the simulation gives ({raw:.4}); the \
             paper's {paper_raw} needs an ARW of about {needed:.2} °/√h. Its Table 2 and its \
             variance do not describe the same record.\n\
             - Mean filter: a 20-sample block mean of white noise has 1/20 of its variance; with \
             r = {r} °/s ≈ {sigmas:.1} σ of this record {rejected} of {blocks} blocks dropped a \
             sample, and the variance fell from {raw:.4} to {mf:.4}. The paper's 0.0667 → 0.0528 \
             (−21 %) is not what averaging 20 samples of its own AR(1) data does; its filter \
             output may not be decimated.\n\
             - Kalman filter: the steady-state gain is K = {k:.4}; the filter's DC gain is \
             K/(1 − (1 − K)φ) = {dc:.4}. A filter with DC gain below 1 scales everything slow by \
             that factor — bias instability, rate ramp, and a true constant rate alike — so the \
             after-filter noise terms drop with it. Paper 003's 94–96 % lower ARW and bias \
             instability are of that kind: the filter shrinks the output toward zero; it would do \
             the same to a real rotation. A filter with unity DC gain (gyrofx's steady-state KF of \
             paper 000) cannot lower the Allan deviation at long τ.{ratio}\n\
             - Noise terms: with ARW N = {arw} °/√h and bias instability B = {b} °/h, the white \
             noise's Allan deviation N/√τ stays above the flicker floor 0.664·B until \
             τ = (N/(0.664·B))² ≈ {crossover:.0} s; this record lasts {length:.0} s, so B, RRW and \
             the rate ramp are below the white noise at every τ it allows and the fit sets them to \
             0 — the paper's values for them cannot be read from a record this short either. The \
             KF output is a low-passed, correlated signal at {rate} Hz: its Allan curve bends \
             below white noise at the shortest τ, which the five-term fit reads as quantization \
             noise — an artifact of filtering, not a noise source.\n",
            arw = PAPER_TERMS_RAW[1],
            fs = FS_HZ,
            white = white_variance,
            raw = self.variance[0],
            paper_raw = PAPER_VARIANCE[0],
            needed = (PAPER_VARIANCE[0] / FS_HZ).sqrt() * 60.0,
            r = THRESHOLD_DPS,
            sigmas = THRESHOLD_DPS / self.variance[0].sqrt(),
            rejected = self.blocks_with_rejections,
            blocks = self.blocks,
            mf = self.variance[1],
            k = self.steady_gain,
            dc = self.dc_gain,
            ratio = match self.paper_ratio_r {
                Some((factor, dc)) => format!(
                    " To lower the variance by the paper's 0.0021/0.0528 the KF needs R = {factor:.1} × \
                     the data's variance; its DC gain is then {dc:.4}: the paper's reduction is this \
                     scaling."
                ),
                None => String::new(),
            },
            b = PAPER_TERMS_RAW[2],
            crossover = ((PAPER_TERMS_RAW[1] / 60.0) / (0.6643 * PAPER_TERMS_RAW[2] / 3600.0)).powi(2),
            length = self.samples as f64 / FS_HZ,
            rate = FS_HZ / f64::from(WINDOW),
        );
        out
    }
}

/// Paper 000's sample rate, Hz.
pub const FS_000_HZ: f64 = 200.0;
/// Samples per test of paper 000 by default: 30 minutes at 200 Hz.
pub const SAMPLES_000: usize = 360_000;
/// Its Table 2, original gyro and KF at 10, 20, 30 Hz: noise density (°/s/√Hz), ARW (°/√h),
/// bias drift (°/h).
pub const PAPER_000_TABLE_2: [(&str, f64, f64, f64); 4] = [
    ("original", 0.150, 4.8668, 44.4129),
    ("KF 10 Hz", 0.013, 0.4006, 4.1344),
    ("KF 20 Hz", 0.040, 1.2037, 12.1383),
    ("KF 30 Hz", 0.061, 1.8879, 19.7388),
];
/// Its Table 3 (KF 10 Hz): rate, mean error before/after, STD before/after, °/s.
pub const PAPER_000_TABLE_3: [(f64, f64, f64, f64, f64); 4] = [
    (10.0, 0.0413, -0.0421, 1.9378, 0.1120),
    (30.0, 0.0197, -0.0209, 2.0195, 0.1075),
    (50.0, 0.0582, -0.0607, 1.9751, 0.1069),
    (80.0, 0.0776, -0.0812, 2.6189, 0.1407),
];
/// Its Table 4 (KF about 20 Hz, 20 °/s swing): frequency, amplitude before/after, STD error
/// before/after.
pub const PAPER_000_TABLE_4: [(f64, f64, f64, f64, f64); 3] = [
    (0.1, 22.4481, 20.0973, 1.6749, 0.3836),
    (0.3, 22.6760, 20.1926, 1.6242, 0.5510),
    (0.5, 23.1104, 20.7806, 1.7234, 0.6866),
];

/// What paper 000's pipeline gives here.
#[derive(Clone, Debug)]
pub struct Paper000 {
    /// Samples per test.
    pub samples: usize,
    /// Seed.
    pub seed: u64,
    /// Table 2 rows as [`PAPER_000_TABLE_2`]: density in the 1–5 Hz band and over the whole
    /// band (median), ARW and bias instability from the Allan fit.
    pub static_rows: Vec<[f64; 4]>,
    /// Table 3 rows: rate, mean error before/after, STD before/after.
    pub constant_rows: Vec<[f64; 5]>,
    /// Table 4 rows: frequency, amplitude before/after, STD error before/after.
    pub swing_rows: Vec<[f64; 5]>,
    /// Allan curves of the static test: raw and KF 10, 20, 30 Hz.
    pub curves: Curves,
}

/// The float steady-state KF of paper 000 designed for `bandwidth_hz` (direct method, the
/// paper's noise model).
fn paper_000_kf(bandwidth_hz: f64) -> Result<FloatKf> {
    let noise = Noise::from_gyro_units(PAPER_TERMS_000[0], 1200.0, 0.0);
    let design = design_for_bandwidth(
        bandwidth_hz,
        noise,
        FS_000_HZ,
        Method::Direct,
        Convergence::default(),
    )
    .map_err(|e| Error::Simulation(format!("paper 000's KF at {bandwidth_hz} Hz: {e}")))?;
    Ok(FloatKf::new(vec![design.g]))
}

/// Paper 000's gyro: ARW and bias instability of its Table 2, RRW of its noise model.
const PAPER_TERMS_000: [f64; 2] = [4.87, 44.41];

fn paper_000_gyro() -> GyroErrors {
    GyroErrors {
        arw_deg_per_sqrt_h: PAPER_TERMS_000[0],
        bias_instability_deg_per_h: PAPER_TERMS_000[1],
        rrw_deg_per_h_per_sqrt_h: 0.0,
        rate_ramp_deg_per_h2: 0.0,
        ..paper_gyro()
    }
}

/// Simulates paper 000's gyro for `rate` (°/s per sample).
fn paper_000_record(rate: &[f64], seed: u64) -> Vec<f64> {
    let plant = Plant {
        fs_hz: FS_000_HZ,
        gyros: [paper_000_gyro(), paper_000_gyro()],
        bi_tau_min_s: 0.5,
        bi_tau_max_s: 500.0,
    };
    let n = rate.len();
    plant.simulate(rate, &vec![[1, 1]; n], seed).y[0].clone()
}

fn filter_all(kf: &mut FloatKf, record: &[f64]) -> Vec<f64> {
    record.iter().map(|z| kf.step(*z, 0)).collect()
}

/// Amplitude of the `frequency_hz` sine in `signal` (least squares on sin and cos), °/s.
fn sine_amplitude(signal: &[f64], frequency_hz: f64, fs_hz: f64) -> f64 {
    let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, y) in signal.iter().enumerate() {
        let phase = 2.0 * std::f64::consts::PI * frequency_hz * k as f64 / fs_hz;
        let (s, c) = (libm::sin(phase), libm::cos(phase));
        ss += s * s;
        sc += s * c;
        cc += c * c;
        ys += y * s;
        yc += y * c;
    }
    let det = ss * cc - sc * sc;
    let a = (ys * cc - yc * sc) / det;
    let b = (yc * ss - ys * sc) / det;
    (a * a + b * b).sqrt()
}

/// Runs paper 000's three tests on `samples` simulated samples each, from `seed`.
///
/// # Errors
/// [`Error::Simulation`] for too few samples or a KF that cannot be designed.
pub fn paper_000(samples: usize, seed: u64) -> Result<Paper000> {
    if samples < 4096 {
        return Err(Error::Simulation(format!(
            "--samples {samples} is too few for paper 000's tests: at least 4096"
        )));
    }
    // Skip the filter's start-up (the state starts at 0).
    let settle = (FS_000_HZ as usize).min(samples / 10);
    let static_record = paper_000_record(&vec![0.0; samples], seed);
    // The classic readings: ARW = σ(1 s) (white rate noise: σ(τ) = N/√τ), bias instability =
    // the Allan floor / 0.6643 — not a five-term fit, which the filtered curve's short-τ
    // roll-off would mislead.
    let static_row = |signal: &[f64]| -> [f64; 4] {
        let signal = &signal[settle..];
        let psd = spectrum::welch(signal, FS_000_HZ, 4096.min(signal.len()));
        let low = psd.median_density(1.0, 5.0).unwrap_or(f64::NAN);
        let whole = psd.median_density(0.0, FS_000_HZ / 2.0).unwrap_or(f64::NAN);
        let phase = allan::phase(signal);
        let at_one_second =
            allan::deviation(Kind::Overlapping, &phase, FS_000_HZ as usize, FS_000_HZ)
                .map_or(f64::NAN, |(dev, _)| dev);
        let floor = allan::curve(Kind::Overlapping, signal, FS_000_HZ, Grid::Octave)
            .iter()
            .filter(|p| p.tau_s >= 1.0)
            .map(|p| p.dev)
            .fold(f64::INFINITY, f64::min);
        [low, whole, at_one_second * 60.0, floor / 0.6643 * 3600.0]
    };
    let mut static_rows = vec![static_row(&static_record)];
    let curve = |signal: &[f64]| {
        allan::curve(
            Kind::Overlapping,
            &signal[settle..],
            FS_000_HZ,
            Grid::Octave,
        )
    };
    let mut curves = vec![("raw".to_string(), curve(&static_record))];
    for bandwidth in [10.0, 20.0, 30.0] {
        let mut kf = paper_000_kf(bandwidth)?;
        let filtered = filter_all(&mut kf, &static_record);
        static_rows.push(static_row(&filtered));
        curves.push((format!("KF {bandwidth} Hz"), curve(&filtered)));
    }

    let mut constant_rows = Vec::new();
    for (i, rate) in [10.0, 30.0, 50.0, 80.0].into_iter().enumerate() {
        let record = paper_000_record(&vec![rate; samples], seed + 1 + i as u64);
        let mut kf = paper_000_kf(10.0)?;
        let filtered = filter_all(&mut kf, &record);
        let truth = vec![rate; samples - settle];
        let (std_raw, mean_raw) = spectrum::one_sigma_error(&record[settle..], &truth);
        let (std_kf, mean_kf) = spectrum::one_sigma_error(&filtered[settle..], &truth);
        constant_rows.push([rate, mean_raw, mean_kf, std_raw, std_kf]);
    }

    let mut swing_rows = Vec::new();
    for (i, frequency) in [0.1, 0.3, 0.5].into_iter().enumerate() {
        let truth: Vec<f64> = (0..samples)
            .map(|k| {
                20.0 * libm::sin(2.0 * std::f64::consts::PI * frequency * k as f64 / FS_000_HZ)
            })
            .collect();
        let record = paper_000_record(&truth, seed + 10 + i as u64);
        let mut kf = paper_000_kf(20.0)?;
        let filtered = filter_all(&mut kf, &record);
        let (std_raw, _) = spectrum::one_sigma_error(&record[settle..], &truth[settle..]);
        let (std_kf, _) = spectrum::one_sigma_error(&filtered[settle..], &truth[settle..]);
        swing_rows.push([
            frequency,
            sine_amplitude(&record, frequency, FS_000_HZ),
            sine_amplitude(&filtered, frequency, FS_000_HZ),
            std_raw,
            std_kf,
        ]);
    }
    Ok(Paper000 {
        samples,
        seed,
        static_rows,
        constant_rows,
        swing_rows,
        curves,
    })
}

impl Paper000 {
    /// The report: the three tables, paper beside ours, and the differences explained.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "# Paper 000 reproduced on simulated data\n\n\
             A gyro with the paper's ARW {} °/√h and bias instability {} °/h at {} Hz, {} samples \
             per test (seed {}), filtered by gyrofx's steady-state KF designed for each bandwidth \
             (direct method, the float model; the fixed-point KF agrees within its bound). The \
             first second (the filter's start from 0) is left out.\n\n\
             ## Table 2: static test\n\n\
             ARW read as σ(τ = 1 s), bias instability as the Allan floor (τ ≥ 1 s) / 0.6643.\n\n\
             | | paper density (°/s/√Hz) | gyrofx density 1–5 Hz | gyrofx density, whole band | paper ARW (°/√h) | gyrofx ARW | paper bias drift (°/h) | gyrofx bias instability |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|\n",
            PAPER_TERMS_000[0], PAPER_TERMS_000[1], FS_000_HZ, self.samples, self.seed
        );
        for ((name, density, arw, drift), row) in PAPER_000_TABLE_2.iter().zip(&self.static_rows) {
            let _ = writeln!(
                out,
                "| {name} | {density} | {:.4} | {:.4} | {arw} | {:.3} | {drift} | {:.2} |",
                row[0], row[1], row[2], row[3]
            );
        }
        out.push_str("\n## Table 3: constant rates, KF 10 Hz (°/s)\n\n| rate | paper mean error raw / KF | gyrofx | paper STD raw / KF | gyrofx |\n|---:|---:|---:|---:|---:|\n");
        for (p, g) in PAPER_000_TABLE_3.iter().zip(&self.constant_rows) {
            let _ = writeln!(
                out,
                "| {} | {} / {} | {:.4} / {:.4} | {} / {} | {:.4} / {:.4} |",
                p.0, p.1, p.2, g[1], g[2], p.3, p.4, g[3], g[4]
            );
        }
        out.push_str("\n## Table 4: 20 °/s swing, KF 20 Hz (°/s)\n\n| f (Hz) | paper amplitude raw / KF | gyrofx | paper STD error raw / KF | gyrofx |\n|---:|---:|---:|---:|---:|\n");
        for (p, g) in PAPER_000_TABLE_4.iter().zip(&self.swing_rows) {
            let _ = writeln!(
                out,
                "| {} | {} / {} | {:.4} / {:.4} | {} / {} | {:.4} / {:.4} |",
                p.0, p.1, p.2, g[1], g[2], p.3, p.4, g[3], g[4]
            );
        }
        let raw = &self.static_rows[0];
        let ten = &self.static_rows[1];
        let arw_dps = PAPER_TERMS_000[0] / 60.0;
        let _ = write!(
            out,
            "\n## Where and why they differ\n\n\
             - ARW and bias instability: the KF has unity DC gain (g1/(g1 + g2) = 1 − 10⁻⁶), so \
             below its bandwidth it passes the gyro's noise unchanged: the Allan deviation at τ \
             well above 1/bandwidth — where ARW and bias instability are read — is the raw one. \
             Here the KF at 10 Hz gives ARW {arw10:.2} against {arw_raw:.2} °/√h raw, bias \
             instability {b10:.1} against {b_raw:.1} °/h (the raw one below the simulated 44.4: \
             30 minutes hold few averages at the floor). The paper's tenfold reductions (4.87 → \
             0.40 °/√h, 44.4 → 4.1 °/h) cannot come from a unity-gain low-pass; they need a \
             filter that attenuates DC (or a fit over τ shorter than 1/bandwidth, where the \
             filtered curve falls faster than τ^-1/2).\n\
             - Noise density: below the bandwidth it is unchanged ({low10:.4} against \
             {low_raw:.4} °/s/√Hz at 1–5 Hz, both the ARW {arw_dps:.4} °/√s); the paper's 0.150 → \
             0.013 (11.5×) can only be a figure over the whole band, whose median the low-pass \
             does lower: {whole_raw:.4} → {whole10:.4} ({whole_ratio:.1}×) here. The raw 0.150 is also about twice the density an ARW of 4.87 \
             °/√h implies ({arw_dps:.4}).\n\
             - Constant rates: the KF lowers the STD {ratio:.2}× here. White noise sampled at \
             {fs} Hz fills fs/2 = {half} Hz; a first-order low-pass at 10 Hz passes a noise \
             bandwidth of π/2·10 = 15.7 Hz, so the STD falls by √(100/15.7) = 2.52. The paper's \
             ~18× would need a noise bandwidth of 100/18² = 0.31 Hz (a 0.2 Hz filter). The mean \
             error is the gyro's bias, which the KF (unity DC gain) keeps — the paper's means flip \
             sign after filtering, which a unity-gain filter cannot do.\n\
             - Swing: the raw amplitude is 20 °/s plus noise here; the paper's 22.4–23.1 °/s raw \
             amplitudes suggest a scale-factor error of ~12–15 % in its gyro, which the KF \
             (unity gain at 0.1–0.5 Hz) would keep; its filtered 20.1–20.8 °/s are not what a \
             unity-gain filter does to that input.\n",
            arw10 = ten[2],
            arw_raw = raw[2],
            b10 = ten[3],
            b_raw = raw[3],
            low10 = ten[0],
            low_raw = raw[0],
            whole_raw = raw[1],
            whole10 = ten[1],
            whole_ratio = raw[1] / ten[1],
            ratio = self.constant_rows[0][3] / self.constant_rows[0][4],
            fs = FS_000_HZ,
            half = FS_000_HZ / 2.0,
        );
        out
    }
}

/// Paper 004's Table 2 (°/s units): Q (µrad), N (°/√s), B (°/s), K (°/s^1.5), R (°/s²) for
/// gyro A, gyro B, mode reversal, and mode reversal with threshold denoising.
pub const PAPER_004_TABLE_2: [[f64; 4]; 5] = [
    [0.0026, 0.0021, 0.0020, 8.26e-4],
    [1.18e-4, 2.04e-4, 5.67e-4, 2.19e-5],
    [0.0066, 0.0055, 0.0022, 0.0011],
    [0.0456, 0.0494, 0.0513, 0.0045],
    [0.2094, 0.1709, 0.302, 0.0195],
];
/// Paper 004's record: 1000 s at 50 Hz, analysed as 1 s averages.
pub const SAMPLES_004: usize = 50_000;

/// What paper 004's pipeline gives here: per column (gyro A, gyro B, mode reversal, mode
/// reversal + denoising) the five terms in Table 2's units.
#[derive(Clone, Debug)]
pub struct Paper004 {
    /// Samples at 50 Hz.
    pub samples: usize,
    /// Seed.
    pub seed: u64,
    /// `[column][term]`.
    pub terms: [[f64; 5]; 4],
    /// ADEV at τ = 1 s of each column (of the 50 Hz signal), °/s.
    pub adev_1s: [f64; 4],
    /// Allan curves of the four columns (1 s averages).
    pub curves: Curves,
}

/// Averages of `block` consecutive samples.
fn block_means(x: &[f64], block: usize) -> Vec<f64> {
    x.chunks_exact(block)
        .map(|c| c.iter().sum::<f64>() / block as f64)
        .collect()
}

/// Runs paper 004's comparison with the `gu2019` preset's gyros and schedule: the raw gyros
/// (same noise, no reversal), the calibrated output of gyrofx's fixed-point chain, and that
/// output denoised by ICEEMDAN thresholding (blocks of 4096, 50 realizations, soft).
///
/// # Errors
/// Config errors of the preset; too few samples.
pub fn paper_004(samples: usize, seed: u64) -> Result<Paper004> {
    use gyrofx_model::chain::FixedChain;
    use gyrofx_model::sequencer::Sequencer;
    use gyrofx_model::stimulus::adc;

    if samples < 20_000 {
        return Err(Error::Simulation(format!(
            "--samples {samples} is too few for paper 004's comparison: at least 20000 (400 s)"
        )));
    }
    let mut config = crate::config::Config::from_preset_and_file(Some("gu2019"), None)?;
    config.samples = samples;
    config.seed = seed;
    let job = crate::job::Job::new(config)?;
    let est = &job.chain.estimator;
    let fs = job.config.stimulus.fs_hz;
    let mut sequencer = Sequencer::new(&est.schedule);
    let modes: Vec<[i8; 2]> = (0..samples)
        .map(|_| {
            let slot = sequencer.advance();
            [slot.mode_a, slot.mode_b]
        })
        .collect();
    let rate = vec![0.0; samples];
    let plant = &job.settings.plant;
    let record = plant.simulate(&rate, &modes, seed);
    let raw = plant.simulate(&rate, &vec![[1, 1]; samples], seed);
    let (ya, _) = adc(&record.y[0], est.input);
    let (yb, _) = adc(&record.y[1], est.input);
    let mut chain = FixedChain::new(&job.chain);
    let mut calibrated = Vec::with_capacity(samples);
    let mut first_estimate = None;
    for k in 0..samples {
        let out = chain.step([ya[k], yb[k]], 0);
        let value = if out.estimator.combined_valid {
            est.calibrated.to_f64(i128::from(out.estimator.combined))
        } else {
            *calibrated.last().unwrap_or(&0.0)
        };
        calibrated.push(value);
        if first_estimate.is_none() && out.estimator.estimated {
            first_estimate = Some(k);
        }
    }
    // From the first estimate on (before it the output is not calibrated).
    let start = first_estimate.unwrap_or(0);
    let calibrated = &calibrated[start..];
    let ensemble = Ensemble {
        realizations: 50,
        ..Ensemble::default()
    };
    let (denoised, _) = denoise::denoise(calibrated, 4096, &ensemble, denoise::Rule::Soft);
    let columns: [&[f64]; 4] = [
        &raw.y[0][start..],
        &raw.y[1][start..],
        calibrated,
        &denoised,
    ];
    let average = fs.round() as usize;
    let mut terms_out = [[0.0; 5]; 4];
    let mut adev_1s = [0.0; 4];
    let labels = [
        "gyro A",
        "gyro B",
        "mode reversal",
        "mode reversal + denoising",
    ];
    let mut curves = Vec::new();
    for (c, column) in columns.iter().enumerate() {
        let seconds = block_means(column, average);
        curves.push((
            labels[c].to_string(),
            allan::curve(Kind::Overlapping, &seconds, 1.0, Grid::Octave),
        ));
        let t = terms(&seconds, 1.0);
        // Table 2's units: Q µrad, N °/√s, B °/s, K °/s^1.5, R °/s².
        terms_out[c] = [
            t[0],
            t[1] / 60.0,
            t[2] / 3600.0,
            t[3] / 216_000.0,
            t[4] / 3600.0 / 3600.0,
        ];
        adev_1s[c] = allan::deviation(Kind::Overlapping, &allan::phase(column), average, fs)
            .map_or(f64::NAN, |(dev, _)| dev);
    }
    Ok(Paper004 {
        samples,
        seed,
        terms: terms_out,
        adev_1s,
        curves,
    })
}

impl Paper004 {
    /// The report: Table 2, paper beside ours, and the differences explained.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "# Paper 004 reproduced on simulated data\n\n\
             The `gu2019` preset (two gyros with the paper's N and B, 50 Hz, L = 150, W = 4, \
             alternating, M = 10 blanked), {} samples ({} s, seed {}) at rest; gyrofx's \
             fixed-point chain calibrates; the calibrated output is denoised by ICEEMDAN \
             thresholding (blocks of 4096, 50 realizations, ε0 = 0.2, soft). As in the paper, the \
             terms come from 1 s averages. Paper | gyrofx per column.\n\n\
             | term | gyro A | gyro B | mode reversal | mode reversal + denoising |\n\
             |---|---:|---:|---:|---:|\n",
            self.samples,
            self.samples as f64 / 50.0,
            self.seed
        );
        let names = ["Q (µrad)", "N (°/√s)", "B (°/s)", "K (°/s^1.5)", "R (°/s²)"];
        for (t, name) in names.iter().enumerate() {
            let cells: Vec<String> = (0..4)
                .map(|c| {
                    format!(
                        "{:.3e} \\| {:.3e}",
                        PAPER_004_TABLE_2[t][c], self.terms[c][t]
                    )
                })
                .collect();
            let _ = writeln!(out, "| {name} | {} |", cells.join(" | "));
        }
        let _ = writeln!(
            out,
            "| ADEV at 1 s (°/s), 50 Hz data | – \\| {:.3e} | – \\| {:.3e} | – \\| {:.3e} | – \\| {:.3e} |",
            self.adev_1s[0], self.adev_1s[1], self.adev_1s[2], self.adev_1s[3]
        );
        let floor = 0.6643 * self.terms[0][2];
        let _ = write!(
            out,
            "\n## Where and why they differ\n\n\
             - Raw N: with B = {b_a:.2e} °/s the Allan floor 0.664·B = {floor:.2e} °/s lies far \
             above the white noise's N/√τ ≤ {n_paper:.2e} °/s at every τ ≥ 1 s, so from 1 s \
             averages N is not identifiable: the fit sets it to {n_a:.1e}. The paper's raw N \
             values (1.18e-4, 2.04e-4 °/√s) cannot have come from its 1 s averages either.\n\
             - Mode reversal: the fit gives B {b_mr:.2e} °/s (raw {b_a:.2e}, {b_b:.2e}) and puts \
             the calibrated output's power into Q and N ({q_mr:.1e} µrad, {n_mr:.2e} °/√s). Our \
             reading, not checked beyond these figures: the residual bias error switches with \
             the mode every interval (3 s), a mode-synchronous component that reads as short-τ \
             noise — the noise folding paper 004 describes (its N rises 5×). The ADEV at 1 s is {a_mr:.2e} °/s against {a_a:.2e} and {a_b:.2e} raw.\n\
             - Denoising: the ADEV at 1 s goes from {a_mr:.2e} to {a_dn:.2e} °/s (×{gain:.2}). \
             The calibrated output's short-term content is not white: the IMFs that carry it \
             hold more than 4× their modelled noise and are kept whole, and the thresholded, \
             noise-dominated IMFs hold little. The paper's \
             26× lower N and 10–15× lower K and R after denoising are not what thresholding \
             noise-dominated IMFs can do to this signal; the paper gives neither its thresholds' \
             fGn parameters nor how block edges were handled, which is where such long-τ \
             changes could come from.\n\
             - A 1000 s record holds only a few averages at τ of hundreds of seconds: K and R \
             from it carry intervals of tens of percent either way.\n",
            b_a = self.terms[0][2],
            b_b = self.terms[1][2],
            floor = floor,
            n_paper = PAPER_004_TABLE_2[1][1],
            n_a = self.terms[0][1],
            b_mr = self.terms[2][2],
            q_mr = self.terms[2][0],
            n_mr = self.terms[2][1],
            a_mr = self.adev_1s[2],
            a_a = self.adev_1s[0],
            a_b = self.adev_1s[1],
            a_dn = self.adev_1s[3],
            gain = self.adev_1s[3] / self.adev_1s[2],
        );
        out
    }
}

/// Paper 002's record: 60000 samples at 100 Hz, a disturbance from 237.3 s to 286.3 s.
pub const SAMPLES_002: usize = 60_000;
/// Its sample rate, Hz.
pub const FS_002_HZ: f64 = 100.0;
/// Its reference noise terms (Table 3): N (°/√h), B (°/h), K (°/h/√h).
pub const PAPER_002_REFERENCE: [f64; 3] = [1.72, 18.89, 102.28];
/// Its Table 3 rows: window (1001, 3001, adaptive) and the mean N, B, K.
pub const PAPER_002_TABLE_3: [(&str, [f64; 3]); 3] = [
    ("1001", [2.01, 14.71, 91.04]),
    ("3001", [1.99, 7.86, 34.07]),
    ("adaptive", [1.79, 15.32, 95.76]),
];
/// Its Table 2 rows: window, detected start and end (s), run time (s); reference 237.3–286.3.
pub const PAPER_002_TABLE_2: [(&str, f64, f64, f64); 3] = [
    ("1001", 231.6, 289.7, 20.87),
    ("3001", 218.8, 296.5, 89.46),
    ("adaptive", 235.5, 285.4, 8.65),
];
/// Samples of the undisturbed record the reference terms come from (2 h at 100 Hz).
const REFERENCE_SAMPLES_002: usize = 720_000;
/// The disturbance: white noise of this many times the gyro's ARW, from..to (s).
const DISTURBANCE: (f64, f64, f64) = (8.0, 237.3, 286.3);

/// Disturbances found: (start, end), s.
pub type Disturbances = Vec<(f64, f64)>;

/// What paper 002's pipeline gives here.
#[derive(Clone, Debug)]
pub struct Paper002 {
    /// Samples at 100 Hz.
    pub samples: usize,
    /// Seed.
    pub seed: u64,
    /// N, B, K of the undisturbed record (the reference).
    pub reference: [f64; 3],
    /// The rate ramp R (°/h²) the reference fit also found.
    pub reference_ramp: f64,
    /// Per setting (1001, 3001, adaptive): mean N, B, K over the windows, and the disturbances
    /// found (start, end, s).
    pub settings: Vec<([f64; 3], Disturbances)>,
    /// The adaptive window's DAVAR and coefficients, for the report's plot.
    pub adaptive: (
        gyrofx_model::analysis::davar::Davar,
        gyrofx_model::analysis::davar::Coefficients,
    ),
}

/// Runs paper 002's DAVAR comparison on `samples` simulated samples from `seed`.
///
/// # Errors
/// Too few samples for the disturbance and the longest window.
pub fn paper_002(samples: usize, seed: u64) -> Result<Paper002> {
    use gyrofx_model::analysis::davar::{coefficients, davar, disturbances, Pid, Window};
    use gyrofx_model::stimulus::{Gaussian, Stream};

    let (factor, from, to) = DISTURBANCE;
    let needed = (to * FS_002_HZ) as usize + 3001;
    if samples < needed {
        return Err(Error::Simulation(format!(
            "--samples {samples} is too few for paper 002's record: at least {needed} (the disturbance ends at {to} s)"
        )));
    }
    let gyro = GyroErrors {
        arw_deg_per_sqrt_h: PAPER_002_REFERENCE[0],
        bias_instability_deg_per_h: PAPER_002_REFERENCE[1],
        rrw_deg_per_h_per_sqrt_h: PAPER_002_REFERENCE[2],
        rate_ramp_deg_per_h2: 0.0,
        ..paper_gyro()
    };
    let plant = Plant {
        fs_hz: FS_002_HZ,
        gyros: [gyro, gyro],
        bi_tau_min_s: 0.5,
        bi_tau_max_s: 500.0,
    };
    let clean = plant
        .simulate(&vec![0.0; samples], &vec![[1, 1]; samples], seed)
        .y[0]
        .clone();
    // The reference from two hours of the same gyro: ten minutes cannot separate B and K.
    let long = REFERENCE_SAMPLES_002;
    let reference_record = plant.simulate(&vec![0.0; long], &vec![[1, 1]; long], seed + 1);
    let reference_terms = terms(&reference_record.y[0], FS_002_HZ);
    // The disturbance: extra white noise, (factor − 1)·ARW per √s, on its own stream.
    let mut burst = Gaussian::new(seed, Stream::AngleRandomWalk(7));
    let sigma = (factor - 1.0) * PAPER_002_REFERENCE[0] / 60.0 * FS_002_HZ.sqrt();
    let disturbed: Vec<f64> = clean
        .iter()
        .enumerate()
        .map(|(k, y)| {
            let t = k as f64 / FS_002_HZ;
            if (from..to).contains(&t) {
                y + sigma * burst.sample()
            } else {
                *y
            }
        })
        .collect();
    let modes = [
        Window::Fixed(1001),
        Window::Fixed(3001),
        Window::Adaptive(Pid {
            min: 300,
            max: 3001,
            kp: 3001.0 / 25.0,
            ki: 3001.0 / 50.0,
            kd: 0.0,
        }),
    ];
    let mut adaptive = None;
    let settings = modes
        .iter()
        .map(|mode| {
            let step = 50;
            let d = davar(&disturbed, FS_002_HZ, *mode, step);
            let c = coefficients(&d);
            if matches!(mode, Window::Adaptive(_)) {
                adaptive = Some((d.clone(), c.clone()));
            }
            let mean = |v: &[f64]| {
                let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
                finite.iter().sum::<f64>() / finite.len().max(1) as f64
            };
            (
                [
                    mean(&c.arw_deg_per_sqrt_h),
                    mean(&c.bias_instability_deg_per_h),
                    mean(&c.rrw_deg_per_h_per_sqrt_h),
                ],
                disturbances(&d, 2.0),
            )
        })
        .collect();
    Ok(Paper002 {
        samples,
        seed,
        reference: [reference_terms[1], reference_terms[2], reference_terms[3]],
        reference_ramp: reference_terms[4],
        settings,
        adaptive: adaptive.expect("the adaptive setting ran"),
    })
}

/// `|start − 237.3| + |end − 286.3|` of the first disturbance found (∞ if none).
fn edge_error(runs: &[(f64, f64)]) -> f64 {
    let (_, from, to) = DISTURBANCE;
    runs.first()
        .map_or(f64::INFINITY, |(a, b)| (a - from).abs() + (b - to).abs())
}

fn edge_text(settings: &[Vec<(f64, f64)>]) -> String {
    ["1001", "3001", "adaptive"]
        .iter()
        .zip(settings)
        .map(|(name, runs)| format!("{name} {:.1} s", edge_error(runs)))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Paper002 {
    /// The report: Tables 2 and 3, paper beside ours, and the differences explained.
    pub fn markdown(&self) -> String {
        let (factor, from, to) = DISTURBANCE;
        let mut out = format!(
            "# Paper 002 reproduced on simulated data\n\n\
             A gyro with the paper's reference N {} °/√h, B {} °/h, K {} °/h/√h, {} samples at \
             {} Hz (seed {}), with white noise of {}× its ARW added from {} s to {} s (the \
             paper's mutation; its cause is not given). DAVAR windows move by 50 samples; the \
             adaptive window runs 300–3001 samples under the PID on the kurtosis index \
             (scale-free: paper 002's σ/mean is undefined for a gyro at rest).\n\n\
             ## Table 3: mean noise coefficients over the windows\n\n\
             | window | paper N / B / K | gyrofx N / B / K |\n|---|---:|---:|\n\
             | reference (gyrofx: 2 h undisturbed) | {} / {} / {} | {:.2} / {:.2} / {:.2} |\n",
            PAPER_002_REFERENCE[0],
            PAPER_002_REFERENCE[1],
            PAPER_002_REFERENCE[2],
            self.samples,
            FS_002_HZ,
            self.seed,
            factor,
            from,
            to,
            PAPER_002_REFERENCE[0],
            PAPER_002_REFERENCE[1],
            PAPER_002_REFERENCE[2],
            self.reference[0],
            self.reference[1],
            self.reference[2],
        );
        for ((name, paper), (ours, _)) in PAPER_002_TABLE_3.iter().zip(&self.settings) {
            let _ = writeln!(
                out,
                "| {name} | {} / {} / {} | {:.2} / {:.2} / {:.2} |",
                paper[0], paper[1], paper[2], ours[0], ours[1], ours[2]
            );
        }
        let _ = write!(
            out,
            "\n## Table 2: the disturbance found (s)\n\n\
             | window | paper start–end | gyrofx start–end | paper run time (s) |\n|---|---:|---:|---:|\n\
             | reference | {from}–{to} | {from}–{to} | – |\n"
        );
        for ((name, start, end, time), (_, runs)) in PAPER_002_TABLE_2.iter().zip(&self.settings) {
            let found = if runs.is_empty() {
                "none".to_string()
            } else {
                runs.iter()
                    .map(|(a, b)| format!("{a:.1}–{b:.1}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let _ = writeln!(out, "| {name} | {start}–{end} | {found} | {time} |");
        }
        let _ = write!(
            out,
            "\n## Where and why they differ\n\n\
             - Run time: gyrofx keeps each window's Allan sums as exact sliding sums, so a \
             window's cost does not grow with its length; `cargo bench` \
             (allan/davar_60000_window_3001_step_1) measured 25.5 ms for L = 3001 moving by one \
             sample, against the paper's 89.46 s for L = 3001 and 8.65 s adaptive. The times are \
             not in this report so that it stays byte-identical from run to run.\n\
             - Reference: the 2-hour fit of the undisturbed gyro gives N {rn:.2} °/√h, B {rb:.2} \
             °/h, K {rk:.2} °/h/√h (rate ramp {rr:.1} °/h²) for a simulated K of 102.28: N is \
             recovered, B within the spread of a single record, and the fit finds no long-τ \
             rise at all — the octave curve's last points (τ ≥ 10³ s) hold a handful of \
             averages, and the non-negative fit assigns them to B's floor. Not examined \
             further here; issue 4's tests recover K within 25 % from 2²⁰ samples.\n\
             - Coefficients: each window's fit uses white-FM degrees of freedom (no per-window \
             noise type), and a window of 1001 samples (10 s) holds τ up to ~3 s, where B and K \
             lie below the white noise (their crossover with N is near 70 s): N is determined \
             (raised by the disturbance, which every setting averages in), B and K are not — \
             the spread of both the paper's rows and ours is that, not a property of the \
             window choice.\n\
             - Disturbance edges: a window sees the disturbance as soon as it overlaps it, so a \
             fixed window of L samples widens it by up to L/2 at each end (5 s for 1001, 15 s for \
             3001). Summed edge error here: {edges}; in the paper: {paper_edges}.{verdict}\n",
            rn = self.reference[0],
            rb = self.reference[1],
            rk = self.reference[2],
            rr = self.reference_ramp,
            edges = edge_text(
                &self
                    .settings
                    .iter()
                    .map(|(_, r)| r.clone())
                    .collect::<Vec<_>>()
            ),
            paper_edges = PAPER_002_TABLE_2
                .iter()
                .map(|(name, a, b, _)| format!("{name} {:.1} s", (a - from).abs() + (b - to).abs()))
                .collect::<Vec<_>>()
                .join(", "),
            verdict = {
                let errors: Vec<f64> = self.settings.iter().map(|(_, r)| edge_error(r)).collect();
                if errors[2] <= errors[0] && errors[2] <= errors[1] {
                    " The adaptive window is closest here too."
                } else {
                    " The adaptive window is not the closest here: its PID gains are the CLI \
                     defaults (Kp = L/25, Ki = L/50), not tuned to this record, and it keeps the \
                     window short past the burst's end."
                }
            },
        );
        out
    }
}

/// Writes `report` (markdown) as `report.md`, the Allan `curves` (if any) as `allan.png` and, when
/// given, a DAVAR as `davar.png`, with a `manifest.json` naming them, into `out` — all or
/// nothing, like a package. Returns the files written.
///
/// # Errors
/// A plot error (no font), or the package's output errors.
pub fn write(
    out: &std::path::Path,
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
    let mut package = crate::package::Package::new();
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
        "files": files,
    });
    package.add(
        "manifest.json",
        serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n",
    );
    package.write_atomically(out)?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_003_runs_deterministically_and_finds_what_the_report_says() {
        let a = paper_003(SAMPLES, 1).unwrap();
        let b = paper_003(SAMPLES, 1).unwrap();
        // The paper's variance ratio is reachable, with a DC gain far below one.
        let (_, dc) = a.paper_ratio_r.expect("an R for the paper's ratio");
        assert!(dc < 0.3, "{dc}");
        assert_eq!(a.markdown(), b.markdown());
        // White noise of ARW 0.95164 °/√h at 50 Hz: variance 0.0126 (°/s)², within 10 %.
        let white = (PAPER_TERMS_RAW[1] / 60.0).powi(2) * FS_HZ;
        assert!(
            (a.variance[0] / white - 1.0).abs() < 0.1,
            "{:?}",
            a.variance
        );
        // The mean filter averages 20 samples: the variance falls by roughly 20.
        assert!(a.variance[1] < a.variance[0] / 10.0, "{:?}", a.variance);
        assert_eq!(a.blocks, SAMPLES / 20);
        // The KF's DC gain is below one, and the output variance falls with it.
        assert!(a.dc_gain < 1.0 && a.dc_gain > 0.0, "{}", a.dc_gain);
        assert!(a.variance[2] < a.variance[1]);
        let text = a.markdown();
        for needle in [
            "| paper | 0.0667 | 0.0528 | 0.0021 |",
            "-10345.03",
            "DC gain",
        ] {
            assert!(text.contains(needle), "{needle}: {text}");
        }
    }

    #[test]
    fn paper_000_keeps_arw_and_lowers_the_short_term_noise() {
        let a = paper_000(200_000, 1).unwrap();
        let raw = a.static_rows[0];
        let ten = a.static_rows[1];
        // Unity DC gain: ARW (σ at 1 s), bias instability and the 1–5 Hz density unchanged
        // within 10 %.
        assert!((ten[2] / raw[2] - 1.0).abs() < 0.1, "{raw:?} {ten:?}");
        assert!((ten[3] / raw[3] - 1.0).abs() < 0.1, "{raw:?} {ten:?}");
        assert!((ten[0] / raw[0] - 1.0).abs() < 0.1, "{raw:?} {ten:?}");
        // The whole-band median falls with the bandwidth.
        assert!(ten[1] < a.static_rows[2][1] && a.static_rows[2][1] < raw[1]);
        // Constant rate: the STD falls by √(fs/2 / (π/2·10 Hz)) = 2.52 (white noise through a
        // first-order low-pass), within 10 %; the mean error (the bias, 0 here) is kept.
        let expected = (FS_000_HZ / 2.0 / (std::f64::consts::FRAC_PI_2 * 10.0)).sqrt();
        for row in &a.constant_rows {
            assert!((row[3] / row[4] / expected - 1.0).abs() < 0.1, "{row:?}");
            assert!((row[1] - row[2]).abs() < 0.01, "{row:?}");
        }
        // Swing: the amplitude passes within 1 %.
        for row in &a.swing_rows {
            assert!((row[2] / 20.0 - 1.0).abs() < 0.01, "{row:?}");
        }
        assert!(a.markdown().contains("| KF 10 Hz | 0.013 |"));
    }

    #[test]
    fn paper_002_finds_the_disturbance_with_every_window() {
        let a = paper_002(SAMPLES_002, 1).unwrap();
        // N of the reference is the simulated ARW within 5 %.
        assert!((a.reference[0] / PAPER_002_REFERENCE[0] - 1.0).abs() < 0.05);
        let (_, from, to) = DISTURBANCE;
        for (i, (_, runs)) in a.settings.iter().enumerate() {
            let (start, end) = runs.first().copied().expect("a disturbance");
            // Within half the longest window (15 s) of the true edges.
            assert!(
                (start - from).abs() < 15.5 && (end - to).abs() < 15.5,
                "{i}: {runs:?}"
            );
        }
        assert_eq!(a.markdown(), paper_002(SAMPLES_002, 1).unwrap().markdown());
    }

    #[test]
    fn too_few_samples_are_refused() {
        let err = paper_003(100, 1).unwrap_err().to_string();
        assert!(err.contains("--samples 100 is too few"), "{err}");
    }
}
