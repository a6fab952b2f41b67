//! The two-gyro plant under mode reversal (SPEC §1.1; simulation only, float, deterministic).
//!
//! Per gyro `g` and sample `k` (period `T = 1/fs`), after the front end has undone the sign
//! flip of reverse mode, with `p = ±1` the gyro's mode for that sample:
//!
//! ```text
//! y_g(k) = SF_{g,p} Ω(k) + p (b_g(k) + δb_{g,p}) + d_g(k) + n_g(k)
//! ```
//!
//! - `SF_{g,+} = 1 + sf_ppm·10⁻⁶`, `SF_{g,−} = SF_{g,+} + sf_mode_mismatch_ppm·10⁻⁶`: a mismatch
//!   between the modes leaks rate into the bias estimate (`ΔSF·Ω/2` with the paper's estimator).
//! - `δb_{g,+} = 0`, `δb_{g,−} = bias_mode_mismatch`: a part of the bias that reversal does not
//!   flip, so it cannot remove it.
//! - `b_g(k) = bias + BI(k) + RRW(k) + R·t`. Bias instability `BI`: a sum of first-order
//!   Gauss–Markov processes, two per decade with correlation times spread over
//!   `[bi_tau_min, bi_tau_max]`. A GM process of variance `q` and correlation time `Tc` has the
//!   Allan variance `q (Tc/τ)² [2τ/Tc − 3 + 4e^{−τ/Tc} − e^{−2τ/Tc}]`; `q` (the same for each)
//!   is set so that the sum's Allan deviation at the band's geometric centre is exactly
//!   `0.6643·B` (the flicker floor). The floor is flat to ±5 % for τ from `6·bi_tau_min` to
//!   `bi_tau_max/2` and rolls off outside (tests check both the analytic sum and a simulated
//!   record). RRW: integrated white noise, `K·√T` per sample.
//! - `d_g`: the switching transient. When the mode flips, the bias term jumps from `p_old·b`
//!   to `p_new·b`; the output follows with time constant `settle_tau`: at a switch `d` takes
//!   the jump `p_old·b_old − p_new·b_new` and decays by `e^{−T/settle_tau}` per sample.
//! - `n_g`: white noise, `N/√T` rms (N in °/√s).
//!
//! Units in: ARW °/√h, B °/h, RRW °/h/√h, R °/h², biases °/s, converted once
//! (`N = ARW/60`, `B/3600`, `K = RRW/216000`, `R/3600²`). Every noise source of every gyro has
//! its own ChaCha8 stream ([`crate::stimulus::Stream`]).

use crate::stimulus::{Gaussian, Stream};

/// One gyro's errors (also the `[gyro_a]` / `[gyro_b]` config sections).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GyroErrors {
    /// Scale-factor error in normal mode, ppm.
    pub sf_ppm: f64,
    /// Reverse-mode scale factor minus normal-mode, ppm.
    pub sf_mode_mismatch_ppm: f64,
    /// Bias at t = 0, °/s.
    pub bias_dps: f64,
    /// Bias part that does not flip with the mode (added in reverse mode), °/s.
    pub bias_mode_mismatch_dps: f64,
    /// Angle random walk, °/√h.
    pub arw_deg_per_sqrt_h: f64,
    /// Bias instability B, °/h.
    pub bias_instability_deg_per_h: f64,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_per_h_per_sqrt_h: f64,
    /// Rate ramp (bias drift), °/h².
    pub rate_ramp_deg_per_h2: f64,
    /// Settling time constant after a mode switch, s (0: none).
    pub settle_tau_s: f64,
}

/// The plant: two gyros on one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant {
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// Gyro A and gyro B.
    pub gyros: [GyroErrors; 2],
    /// Shortest correlation time of the bias-instability processes, s.
    pub bi_tau_min_s: f64,
    /// Longest correlation time, s.
    pub bi_tau_max_s: f64,
}

/// A simulated record of both gyros (before the ADC).
#[derive(Clone, Debug, PartialEq)]
pub struct TwoGyroRecord {
    /// Gyro outputs, °/s.
    pub y: [Vec<f64>; 2],
    /// The slowly varying bias `b_g(k)` of each gyro (normal-mode value), °/s.
    pub bias: [Vec<f64>; 2],
}

/// Allan variance of a unit-variance first-order Gauss–Markov process of correlation time
/// `tc` at averaging time `tau` (both s).
pub fn gauss_markov_avar(tc: f64, tau: f64) -> f64 {
    let x = tau / tc;
    (tc / tau) * (tc / tau) * (2.0 * x - 3.0 + 4.0 * libm::exp(-x) - libm::exp(-2.0 * x))
}

impl Plant {
    /// Correlation times of the bias-instability processes: two per decade, log-spaced over
    /// `[bi_tau_min, bi_tau_max]`.
    pub fn bias_instability_times(&self) -> Vec<f64> {
        let decades = libm::log10(self.bi_tau_max_s / self.bi_tau_min_s);
        let count = ((2.0 * decades).round() as usize).max(1) + 1;
        (0..count)
            .map(|j| {
                let f = if count == 1 {
                    0.0
                } else {
                    j as f64 / (count - 1) as f64
                };
                self.bi_tau_min_s * libm::pow(self.bi_tau_max_s / self.bi_tau_min_s, f)
            })
            .collect()
    }

    /// Variance of each bias-instability process for `B` in °/s: the sum's Allan deviation at
    /// the band's geometric centre is `0.6643·B`.
    pub fn bias_instability_variance(&self, b_dps: f64) -> f64 {
        let centre = (self.bi_tau_min_s * self.bi_tau_max_s).sqrt();
        let unit: f64 = self
            .bias_instability_times()
            .iter()
            .map(|tc| gauss_markov_avar(*tc, centre))
            .sum();
        (0.6643 * b_dps) * (0.6643 * b_dps) / unit
    }

    /// Simulates both gyros for the true rate `rate` (°/s per sample) under the per-sample
    /// modes `modes` (`[p_A, p_B]`, ±1), from `seed`.
    ///
    /// # Panics
    /// When `rate` and `modes` differ in length.
    pub fn simulate(&self, rate: &[f64], modes: &[[i8; 2]], seed: u64) -> TwoGyroRecord {
        assert_eq!(rate.len(), modes.len(), "one mode pair per rate sample");
        let n = rate.len();
        let records = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..2u8)
                .map(|g| scope.spawn(move || self.simulate_gyro(g, rate, modes, seed)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("the plant simulation does not panic"))
                .collect::<Vec<_>>()
        });
        let [(ya, ba), (yb, bb)]: [(Vec<f64>, Vec<f64>); 2] =
            records.try_into().expect("two gyros");
        debug_assert_eq!(ya.len(), n);
        TwoGyroRecord {
            y: [ya, yb],
            bias: [ba, bb],
        }
    }

    /// Gyro `g`'s sample-by-sample simulator from `seed`: what [`Plant::simulate`] runs, for
    /// callers that stream records of any length in bounded memory.
    pub fn gyro_stream(&self, g: u8, seed: u64) -> GyroStream {
        let e = self.gyros[usize::from(g)];
        let t = 1.0 / self.fs_hz;
        let b_dps = e.bias_instability_deg_per_h / 3600.0;
        let q = if b_dps > 0.0 {
            self.bias_instability_variance(b_dps)
        } else {
            0.0
        };
        let instability = if q > 0.0 {
            self.bias_instability_times()
                .iter()
                .enumerate()
                .map(|(j, tc)| {
                    let mut source = Gaussian::new(seed, Stream::BiasInstability(g, j as u8));
                    let decay = libm::exp(-t / tc);
                    GaussMarkov {
                        // Stationary from the first sample.
                        x: q.sqrt() * source.sample(),
                        decay,
                        drive: (q * (1.0 - decay * decay)).sqrt(),
                        source,
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        let walk_sigma = e.rrw_deg_per_h_per_sqrt_h / 216_000.0 * t.sqrt();
        let sf_normal = 1.0 + e.sf_ppm * 1e-6;
        GyroStream {
            errors: e,
            white_sigma: e.arw_deg_per_sqrt_h / 60.0 / t.sqrt(),
            walk_sigma,
            ramp_per_sample: e.rate_ramp_deg_per_h2 / (3600.0 * 3600.0) * t,
            sf_normal,
            sf_reverse: sf_normal + e.sf_mode_mismatch_ppm * 1e-6,
            settle: if e.settle_tau_s > 0.0 {
                libm::exp(-t / e.settle_tau_s)
            } else {
                0.0
            },
            instability,
            walk: (walk_sigma > 0.0).then(|| Gaussian::new(seed, Stream::RateRandomWalk(g))),
            random_walk: 0.0,
            white: Gaussian::new(seed, Stream::AngleRandomWalk(g)),
            transient: 0.0,
            previous: None,
            k: 0,
        }
    }

    fn simulate_gyro(
        &self,
        g: u8,
        rate: &[f64],
        modes: &[[i8; 2]],
        seed: u64,
    ) -> (Vec<f64>, Vec<f64>) {
        let mut stream = self.gyro_stream(g, seed);
        rate.iter()
            .zip(modes)
            .map(|(omega, p)| stream.step(*omega, p[usize::from(g)]))
            .unzip()
    }
}

/// One first-order Gauss–Markov process of the bias instability, on its own stream.
#[derive(Clone, Debug)]
struct GaussMarkov {
    x: f64,
    decay: f64,
    drive: f64,
    source: Gaussian,
}

/// One gyro of a [`Plant`], sample by sample ([`Plant::gyro_stream`]): the same record as
/// [`Plant::simulate`] gives, in constant memory.
#[derive(Clone, Debug)]
pub struct GyroStream {
    errors: GyroErrors,
    white_sigma: f64,
    walk_sigma: f64,
    ramp_per_sample: f64,
    sf_normal: f64,
    sf_reverse: f64,
    settle: f64,
    instability: Vec<GaussMarkov>,
    walk: Option<Gaussian>,
    random_walk: f64,
    white: Gaussian,
    transient: f64,
    previous: Option<(i8, f64)>,
    k: u64,
}

impl GyroStream {
    /// The next sample at true rate `omega` (°/s) in mode `p` (±1): the output and the slowly
    /// varying bias `b(k)` (normal-mode value), both °/s.
    pub fn step(&mut self, omega: f64, p: i8) -> (f64, f64) {
        let e = &self.errors;
        // Slow part of the bias: instability, random walk, ramp (summed in that order).
        let mut b = e.bias_dps;
        for process in &mut self.instability {
            b += process.x;
            process.x = process.decay * process.x + process.drive * process.source.sample();
        }
        if let Some(walk) = self.walk.as_mut() {
            b += self.random_walk;
            self.random_walk += self.walk_sigma * walk.sample();
        }
        if self.ramp_per_sample != 0.0 {
            b += self.ramp_per_sample * self.k as f64;
        }
        self.k += 1;
        let (sf, offset) = if p > 0 {
            (self.sf_normal, 0.0)
        } else {
            (self.sf_reverse, e.bias_mode_mismatch_dps)
        };
        let term = f64::from(p) * (b + offset);
        self.transient *= self.settle;
        if let Some((previous_mode, previous_term)) = self.previous {
            if p != previous_mode {
                self.transient += previous_term - term;
            }
        }
        self.previous = Some((p, term));
        let y = sf * omega + term + self.transient + self.white_sigma * self.white.sample();
        (y, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quiet() -> GyroErrors {
        GyroErrors {
            sf_ppm: 0.0,
            sf_mode_mismatch_ppm: 0.0,
            bias_dps: 0.0,
            bias_mode_mismatch_dps: 0.0,
            arw_deg_per_sqrt_h: 0.0,
            bias_instability_deg_per_h: 0.0,
            rrw_deg_per_h_per_sqrt_h: 0.0,
            rate_ramp_deg_per_h2: 0.0,
            settle_tau_s: 0.0,
        }
    }

    fn plant(a: GyroErrors, b: GyroErrors) -> Plant {
        Plant {
            fs_hz: 50.0,
            gyros: [a, b],
            bi_tau_min_s: 0.5,
            bi_tau_max_s: 500.0,
        }
    }

    /// Overlapping Allan deviation of `y` (°/s) at `m` samples (a simple reference here; the
    /// analysis module has the full one).
    fn oadev(y: &[f64], m: usize) -> f64 {
        let mut phase = vec![0.0; y.len() + 1];
        for (k, v) in y.iter().enumerate() {
            phase[k + 1] = phase[k] + v;
        }
        let n = phase.len();
        let terms = n - 2 * m;
        let sum: f64 = (0..terms)
            .map(|i| {
                let d = phase[i + 2 * m] - 2.0 * phase[i + m] + phase[i];
                d * d
            })
            .sum();
        (sum / (2.0 * (m * m) as f64 * terms as f64)).sqrt()
    }

    #[test]
    fn mode_reversal_flips_the_bias_and_keeps_the_rate() {
        let mut a = quiet();
        a.bias_dps = 0.3;
        a.bias_mode_mismatch_dps = 0.01;
        a.sf_ppm = 1000.0;
        a.sf_mode_mismatch_ppm = 500.0;
        let p = plant(a, quiet());
        let modes: Vec<[i8; 2]> = (0..4)
            .map(|k| if k < 2 { [1, -1] } else { [-1, 1] })
            .collect();
        let r = p.simulate(&[10.0; 4], &modes, 1);
        assert!((r.y[0][0] - (10.0 * 1.001 + 0.3)).abs() < 1e-12);
        assert!((r.y[0][3] - (10.0 * 1.0015 - 0.31)).abs() < 1e-12);
        assert_eq!(r.y[1], vec![10.0; 4]);
    }

    #[test]
    fn the_switching_transient_starts_from_the_bias_jump_and_decays() {
        let mut a = quiet();
        a.bias_dps = 1.0;
        a.settle_tau_s = 0.1; // 5 samples at 50 Hz
        let p = plant(a, quiet());
        let modes: Vec<[i8; 2]> = (0..40)
            .map(|k| if k < 10 { [1, -1] } else { [-1, 1] })
            .collect();
        let r = p.simulate(&[0.0; 40], &modes, 1);
        assert_eq!(r.y[0][9], 1.0);
        // The output starts at the old value (+1) and settles toward −1.
        assert!((r.y[0][10] - 1.0).abs() < 1e-12);
        let decay = libm::exp(-0.02 / 0.1);
        assert!((r.y[0][11] - (-1.0 + 2.0 * decay)).abs() < 1e-12);
        assert!((r.y[0][39] + 1.0).abs() < 1e-2);
    }

    #[test]
    fn bias_instability_floor_is_0_6643_b_within_a_few_percent() {
        let mut a = quiet();
        a.bias_instability_deg_per_h = 36.0; // 0.01 °/s
        let p = plant(a, quiet());
        let n = 1 << 20; // ~5.8 h at 50 Hz
        let modes = vec![[1i8, -1i8]; n];
        let r = p.simulate(&vec![0.0; n], &modes, 3);
        let target = 0.6643 * 0.01;
        // Across the band's middle decade (τ = 5..50 s, 250..2500 samples).
        for m in [250usize, 500, 1000, 2500] {
            let adev = oadev(&r.y[0], m);
            assert!(
                (adev / target - 1.0).abs() < 0.06,
                "τ = {} s: {adev} vs {target}",
                m as f64 / 50.0
            );
        }
        // The analytic sum is flat to a few percent over the band.
        let unit = p.bias_instability_variance(0.01);
        for tau in [3.0, 5.0, 20.0, 50.0, 100.0, 250.0] {
            let avar: f64 = p
                .bias_instability_times()
                .iter()
                .map(|tc| unit * gauss_markov_avar(*tc, tau))
                .sum();
            assert!(
                (avar.sqrt() / target - 1.0).abs() < 0.05,
                "τ = {tau}: {}",
                avar.sqrt()
            );
        }
    }

    #[test]
    fn streams_are_independent_per_gyro_and_deterministic() {
        let mut a = quiet();
        a.arw_deg_per_sqrt_h = 10.0;
        let p = plant(a, a);
        let modes = vec![[1i8, -1i8]; 1000];
        let r = p.simulate(&[0.0; 1000], &modes, 9);
        assert_ne!(r.y[0], r.y[1]);
        assert_eq!(r, p.simulate(&[0.0; 1000], &modes, 9));
    }
}
