//! Fixed-versus-float error statistics of one signal, accumulated sample by sample.

use serde::Serialize;

/// Fixed-vs-float error of a signal, in LSB of its format.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Samples compared.
    pub samples: u64,
    /// Largest `|fixed − float|` (same quantized coefficients).
    pub max_lsb: f64,
    /// Rms of the same.
    pub rms_lsb: f64,
    /// The derived worst-case bound.
    pub bound_lsb: f64,
    /// Largest `|fixed − ideal|` (ideal: designed coefficients, f64).
    pub ideal_max_lsb: f64,
    /// Rms of the same.
    pub ideal_rms_lsb: f64,
    /// Signal-to-quantization-noise ratio against the ideal model, dB.
    pub sqnr_db: f64,
}

/// Running sums behind an [`ErrorStats`]: O(1) memory whatever the record length.
#[derive(Default)]
pub struct Accumulator {
    count: u64,
    max: f64,
    sum_sq: f64,
    ideal_max: f64,
    ideal_sq: f64,
    signal_sq: f64,
}

impl Accumulator {
    /// Adds one sample: the fixed model's value, the float model's (same quantized
    /// coefficients) and the ideal one (designed coefficients), in the signal's unit, and the
    /// LSB of its format in the same unit.
    pub fn add(&mut self, fixed: f64, float: f64, ideal: f64, lsb: f64) {
        let err = (fixed - float) / lsb;
        let ideal_err = (fixed - ideal) / lsb;
        self.count += 1;
        self.max = self.max.max(err.abs());
        self.sum_sq += err * err;
        self.ideal_max = self.ideal_max.max(ideal_err.abs());
        self.ideal_sq += ideal_err * ideal_err;
        self.signal_sq += (ideal / lsb) * (ideal / lsb);
    }

    /// Samples added so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The statistics, with the derived bound `bound_lsb` beside them.
    pub fn finish(self, bound_lsb: f64) -> ErrorStats {
        let rms = |s: f64| {
            if self.count == 0 {
                0.0
            } else {
                (s / self.count as f64).sqrt()
            }
        };
        ErrorStats {
            samples: self.count,
            max_lsb: self.max,
            rms_lsb: rms(self.sum_sq),
            bound_lsb,
            ideal_max_lsb: self.ideal_max,
            ideal_rms_lsb: rms(self.ideal_sq),
            sqnr_db: if self.ideal_sq > 0.0 {
                10.0 * libm::log10(self.signal_sq / self.ideal_sq)
            } else {
                f64::INFINITY
            },
        }
    }
}
