//! The KF vector set: the schedule of samples (stimulus, `bw_sel` switches, resets, rounding
//! ties, full scale), the expected response of the fixed model, and the float comparisons.

use gyrofx_model::kf::bound::rate_error_bound_lsb;
use gyrofx_model::kf::{FixedKf, FloatKf, OverflowCounts, Plan};
use serde::Serialize;

use crate::job::Stimulus;

/// Which part of the vector set a row belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Segment {
    /// The configured stimulus (with `bw_sel` switches and one reset half-way).
    Stimulus,
    /// A reset followed by one input that lands exactly on a rounding tie.
    Tie,
    /// Full-scale positive and negative inputs.
    FullScale,
}

impl Segment {
    /// Name in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Segment::Stimulus => "stimulus",
            Segment::Tie => "tie",
            Segment::FullScale => "full_scale",
        }
    }
}

/// One clock-enable of the vector set.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Part of the set.
    pub segment: Segment,
    /// Reset this sample (no output).
    pub rst: bool,
    /// ROM address.
    pub bw_sel: usize,
    /// Input code (input format).
    pub z: i64,
    /// The DUT must flag a valid output.
    pub valid: bool,
    /// Expected `rate_out` code (output format); 0 when not valid.
    pub rate: i64,
    /// Float model with the quantized gains, °/s.
    pub float_rate: f64,
    /// Float model with the designed (unquantized) gains, °/s.
    pub ideal_rate: f64,
    /// True rate, °/s, where known.
    pub true_rate: Option<f64>,
}

/// Fixed-vs-float error over the stimulus rows, in output LSB.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Valid stimulus rows compared.
    pub samples: u64,
    /// Largest `|fixed − float|` with the same quantized gains.
    pub max_lsb: f64,
    /// Rms of the same.
    pub rms_lsb: f64,
    /// The derived worst-case bound for this many samples and switches.
    pub bound_lsb: f64,
    /// Largest `|fixed − ideal|` (ideal: unquantized gains): what the coefficients' and the
    /// states' word lengths cost together.
    pub ideal_max_lsb: f64,
    /// Rms of the same.
    pub ideal_rms_lsb: f64,
    /// Signal-to-quantization-noise ratio of `rate_hat` against the ideal model, dB.
    pub sqnr_db: f64,
}

/// Tie-case inputs found for one ROM entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TieCases {
    /// ROM address.
    pub bw_sel: usize,
    /// Input code that puts the `x1` update on a tie from reset, if one exists in range.
    pub x1: Option<i64>,
    /// Same for `x2`.
    pub x2: Option<i64>,
    /// Same for the output quantizer.
    pub rate_hat: Option<i64>,
}

/// The vector set.
#[derive(Clone, Debug)]
pub struct Vectors {
    /// One row per clock-enable.
    pub rows: Vec<Row>,
    /// Overflow counts of the fixed model over the whole set.
    pub overflow: OverflowCounts,
    /// Error statistics over the stimulus rows.
    pub stats: ErrorStats,
    /// Tie cases per ROM entry.
    pub ties: Vec<TieCases>,
}

/// Samples of the full-scale segment at each polarity.
const FULL_SCALE_SAMPLES: usize = 64;
/// Largest |z| searched for a tie case.
const TIE_SEARCH_LIMIT: i64 = 1 << 16;

/// Builds the schedule for `stimulus` and runs the models over it.
pub fn build(plan: &Plan, stimulus: &Stimulus) -> Vectors {
    let entries = plan.rom.len();
    let n = stimulus.z.len();
    let chunk = (n / (2 * entries)).max(1);
    let mut schedule: Vec<(Segment, bool, usize, i64, Option<f64>)> = Vec::with_capacity(n + 256);
    for (k, z) in stimulus.z.iter().enumerate() {
        if n >= 4 && k == n / 2 {
            schedule.push((Segment::Stimulus, true, 0, 0, None));
        }
        let truth = stimulus.true_rate.as_ref().map(|t| t[k]);
        schedule.push((Segment::Stimulus, false, (k / chunk) % entries, *z, truth));
    }

    let ties = find_ties(plan);
    for tie in &ties {
        for z in [tie.x1, tie.x2, tie.rate_hat].into_iter().flatten() {
            schedule.push((Segment::Tie, true, tie.bw_sel, 0, None));
            schedule.push((Segment::Tie, false, tie.bw_sel, z, None));
        }
    }
    let widest = entries - 1;
    let (max, min) = (plan.input.max_code() as i64, plan.input.min_code() as i64);
    schedule.push((Segment::FullScale, true, widest, 0, None));
    for (z, count) in [
        (max, FULL_SCALE_SAMPLES),
        (min, FULL_SCALE_SAMPLES),
        (max, 8),
        (0, 16),
    ] {
        for _ in 0..count {
            schedule.push((Segment::FullScale, false, widest, z, None));
        }
    }

    let mut fixed = FixedKf::new(plan);
    let mut float = FloatKf::new(plan.quantized_gains());
    let mut ideal = FloatKf::new(plan.gains.clone());
    let lsb = plan.output.lsb();
    let mut rows = Vec::with_capacity(schedule.len());
    let (mut count, mut max_err, mut sum_sq, mut ideal_max, mut ideal_sq, mut signal_sq) =
        (0u64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut switches = 0u64;
    let mut previous_sel = None;
    for (segment, rst, bw_sel, z, true_rate) in schedule {
        if rst {
            fixed.reset();
            float.reset();
            ideal.reset();
            rows.push(Row {
                segment,
                rst,
                bw_sel,
                z,
                valid: false,
                rate: 0,
                float_rate: 0.0,
                ideal_rate: 0.0,
                true_rate,
            });
            continue;
        }
        let rate = fixed.step(z, bw_sel);
        let z_real = plan.input.to_f64(i128::from(z));
        let float_rate = float.step(z_real, bw_sel);
        let ideal_rate = ideal.step(z_real, bw_sel);
        if segment == Segment::Stimulus {
            if previous_sel.is_some_and(|p| p != bw_sel) {
                switches += 1;
            }
            previous_sel = Some(bw_sel);
            let fixed_real = plan.output.to_f64(i128::from(rate));
            let err = (fixed_real - float_rate) / lsb;
            let ideal_err = (fixed_real - ideal_rate) / lsb;
            count += 1;
            max_err = max_err.max(err.abs());
            sum_sq += err * err;
            ideal_max = ideal_max.max(ideal_err.abs());
            ideal_sq += ideal_err * ideal_err;
            signal_sq += (ideal_rate / lsb) * (ideal_rate / lsb);
        }
        rows.push(Row {
            segment,
            rst,
            bw_sel,
            z,
            valid: true,
            rate,
            float_rate,
            ideal_rate,
            true_rate,
        });
    }
    let mean = |s: f64| {
        if count == 0 {
            0.0
        } else {
            (s / count as f64).sqrt()
        }
    };
    let stats = ErrorStats {
        samples: count,
        max_lsb: max_err,
        rms_lsb: mean(sum_sq),
        bound_lsb: rate_error_bound_lsb(plan, count, switches),
        ideal_max_lsb: ideal_max,
        ideal_rms_lsb: mean(ideal_sq),
        sqnr_db: if ideal_sq > 0.0 {
            10.0 * libm::log10(signal_sq / ideal_sq)
        } else {
            f64::INFINITY
        },
    };
    Vectors {
        rows,
        overflow: fixed.overflow_counts(),
        stats,
        ties,
    }
}

/// For each ROM entry, an input that from reset lands each quantization point exactly on a
/// tie. From reset a state update is `Q(g·z·2^a)`, which is a tie only when `z`'s lowest set
/// bit sits at one particular position, so powers of two (both signs) are tried first; then
/// every |z| up to [`TIE_SEARCH_LIMIT`] (positive first) for what is still missing.
fn find_ties(plan: &Plan) -> Vec<TieCases> {
    let kf = FixedKf::new(plan);
    let max = plan.input.max_code() as i64;
    let limit = TIE_SEARCH_LIMIT.min(max);
    let powers = (0..plan.input.width - 1).map(|bit| 1i64 << bit);
    let candidates: Vec<i64> = powers
        .chain(1..=limit)
        .flat_map(|magnitude| [magnitude, -magnitude])
        .collect();
    (0..plan.rom.len())
        .map(|bw_sel| {
            let mut found: [Option<i64>; 3] = [None; 3];
            for z in &candidates {
                let ties = kf.ties(*z, bw_sel);
                for (slot, tie) in found.iter_mut().zip(ties) {
                    if tie && slot.is_none() {
                        *slot = Some(*z);
                    }
                }
                if found.iter().all(Option::is_some) {
                    break;
                }
            }
            TieCases {
                bw_sel,
                x1: found[0],
                x2: found[1],
                rate_hat: found[2],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::job::Job;

    #[test]
    fn the_default_set_has_switches_a_reset_ties_and_full_scale() {
        let mut config = Config::embedded();
        config.samples = 2000;
        let job = Job::new(config).unwrap();
        let vectors = build(&job.plan, &job.stimulus().unwrap());
        let stimulus_resets = vectors
            .rows
            .iter()
            .filter(|r| r.segment == Segment::Stimulus && r.rst)
            .count();
        assert_eq!(stimulus_resets, 1);
        let sels: std::collections::BTreeSet<usize> =
            vectors.rows.iter().map(|r| r.bw_sel).collect();
        assert_eq!(sels.len(), 3);
        // Each tie input really is a tie from reset, and one exists for x1 and the output.
        let kf = FixedKf::new(&job.plan);
        for tie in &vectors.ties {
            let z = tie.x1.expect("an x1 tie exists in range");
            assert!(kf.ties(z, tie.bw_sel)[0]);
            let z = tie.rate_hat.expect("an output tie exists in range");
            assert!(kf.ties(z, tie.bw_sel)[2]);
        }
        let max = job.plan.input.max_code() as i64;
        assert!(vectors
            .rows
            .iter()
            .any(|r| r.segment == Segment::FullScale && r.z == max));
        assert!(vectors.stats.max_lsb <= 1.0);
        assert!(vectors.stats.max_lsb <= vectors.stats.bound_lsb);
        assert!(vectors.stats.sqnr_db > 60.0, "{}", vectors.stats.sqnr_db);
        // Invalid rows are exactly the resets.
        assert!(vectors.rows.iter().all(|r| r.valid != r.rst));
    }
}
