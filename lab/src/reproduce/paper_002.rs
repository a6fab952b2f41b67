//! Paper 002 (DAVAR, 60 000 samples at 100 Hz): Table 3 (mean N, B, K over the windows for
//! L = 1001, 3001 and adaptive, against a reference) and Table 2 (the disturbance's edges and
//! the run time) on a simulated noise burst.

use std::fmt::Write as _;

use gyrofx_model::plant::GyroErrors;

use super::{gyro_record, paper_gyro, terms};
use gyrofx_job::error::{Error, Result};

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
    let clean = gyro_record(gyro, FS_002_HZ, &vec![0.0; samples], seed);
    // The reference from two hours of the same gyro: ten minutes cannot separate B and K.
    let long = REFERENCE_SAMPLES_002;
    let reference_record = gyro_record(gyro, FS_002_HZ, &vec![0.0; long], seed + 1);
    let reference_terms = terms(&reference_record, FS_002_HZ);
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
