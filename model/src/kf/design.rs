//! Offline design of the steady-state Kalman filter (f64, nalgebra).
//!
//! Model (SPEC §1.4, paper 000): state `X = [ω, b]` (°/s), `F = 0`, `H = [1 1]`,
//! `Q = diag(q_w, q_b)`, `R = q_n`, sample period `T = 1/fs` (s). Discrete:
//! `F_d = I`, `Q_d = diag(q_w, q_b)·T`, `R_d = q_n / T`.
//!
//! Units: `q_w` in (°/s)²/s (the true rate is a random walk driven by it; it sets the
//! bandwidth), `q_b = RRW²` in (°/s)²/s with RRW in °/s/√s, `q_n = ARW²` in (°/s)²·s with ARW in
//! °/√s.
//!
//! # The innovation recursion
//!
//! Both discretisations are the recursion `x ← x + g (z − x1 − x2)`, i.e. `A = I − g H`,
//! `B = g`:
//!
//! - **direct**: the exact discrete steady-state filter, `A = I − K H`, `B = K`, so `g = K`.
//! - **paper** (eqs 12–17): `kc = K / T`, `m = −kc H`, `λ = −(kc1 + kc2)`. Because
//!   `m² = kc (H kc) H = λ m`, the exponential series collapses:
//!   `e^{mT} = I + m (e^{λT} − 1)/λ` and `∫₀ᵀ e^{mt} dt = T I + m (e^{λT} − 1 − λT)/λ²`.
//!   With `S = k1 + k2` (so `λT = −S`): `A = I − K H (1 − e^{−S})/S` and, since
//!   `m kc = λ kc`, `B = Bint kc = K (1 − e^{−S})/S`. So `g = K (1 − e^{−S})/S`.
//!
//! # Transfer function and bandwidth
//!
//! With `S = g1 + g2`, Sherman–Morrison on `(I − A z⁻¹)⁻¹ g` gives exactly
//! `X(z)/Z(z) = g / (1 − (1 − S) z⁻¹)`: a first-order low-pass with pole `p = 1 − S` (the
//! eigenvalue at 1 of `A` cancels). So `ω̂/z = g1 / (1 − p z⁻¹)` with DC gain `g1 / S`, and the
//! half-power (−3.01 dB) frequency solves `1 − 2p cos θ + p² = 2 S²`:
//! `cos θ = (−1 + 4p − p²) / (2p)`, `f = θ fs / 2π`. A cut-off below Nyquist exists for
//! `3 − 2√2 ≤ p < 1` (`0 < S ≤ 0.828`); wider filters have none.

use nalgebra::{Matrix1x2, Matrix2, Vector2};

/// Noise and process parameters of the KF model, in the units of the module doc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// `q_w`, (°/s)²/s: random-walk intensity of the modelled true rate (sets the bandwidth).
    pub q_w: f64,
    /// `q_b = RRW²`, (°/s)²/s: rate-random-walk intensity of the bias.
    pub q_b: f64,
    /// `q_n = ARW²`, (°/s)²·s: white rate noise (angle random walk).
    pub q_n: f64,
}

impl Noise {
    /// From customary gyro units: ARW in °/√h, RRW in °/h/√h (°/h^1.5), and `q_w`.
    /// `ARW[°/√s] = ARW[°/√h]/60`, `RRW[°/s/√s] = RRW[°/h^1.5]/216000`.
    pub fn from_gyro_units(
        arw_deg_per_sqrt_h: f64,
        rrw_deg_per_h_per_sqrt_h: f64,
        q_w: f64,
    ) -> Noise {
        let arw = arw_deg_per_sqrt_h / 60.0;
        let rrw = rrw_deg_per_h_per_sqrt_h / 216_000.0;
        Noise {
            q_w,
            q_b: rrw * rrw,
            q_n: arw * arw,
        }
    }
}

/// Which discretisation produces the innovation gain `g` (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// `g = K`: the exact discrete steady-state filter (default).
    Direct,
    /// `g = K (1 − e^{−S})/S`: paper 000's discretisation of the continuous filter.
    Paper,
}

impl Method {
    /// Config/CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Direct => "direct",
            Method::Paper => "paper",
        }
    }
}

impl std::str::FromStr for Method {
    type Err = DesignError;
    fn from_str(text: &str) -> Result<Self, DesignError> {
        match text {
            "direct" => Ok(Method::Direct),
            "paper" => Ok(Method::Paper),
            _ => Err(DesignError::MethodName {
                text: text.to_string(),
            }),
        }
    }
}

/// Stopping rule of the Riccati iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Convergence {
    /// Stop when `max_i |K_i(k) − K_i(k−1)| / |K_i(k)|` falls below this.
    pub tolerance: f64,
    /// Give up (an error) after this many iterations.
    pub max_iterations: u64,
}

impl Default for Convergence {
    fn default() -> Self {
        Convergence {
            tolerance: 1e-14,
            max_iterations: 10_000_000,
        }
    }
}

/// Errors of the design. Each names the parameter, its value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DesignError {
    /// A parameter that must be positive and finite is not.
    #[error("{name} = {value} is not allowed: it must be a finite number > 0")]
    NotPositive {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// The Riccati iteration did not converge.
    #[error("the Riccati iteration did not converge within max_iterations = {max_iterations} (last relative gain change {last_change:e}, tolerance {tolerance:e}); raise max_iterations or the tolerance")]
    NotConverged {
        /// The iteration limit.
        max_iterations: u64,
        /// Relative change of the gain in the last iteration.
        last_change: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The target bandwidth cannot be reached at this sample rate.
    #[error("bandwidth {target_hz} Hz cannot be designed at fs = {fs_hz} Hz with this method: it reaches at most {max_hz} Hz (the direct method fs/2 = {} Hz; the paper's discretisation saturates lower), and the target must be > 0", .fs_hz / 2.0)]
    BandwidthUnreachable {
        /// The bandwidth asked for, Hz.
        target_hz: f64,
        /// The sample rate, Hz.
        fs_hz: f64,
        /// The largest reachable bandwidth, Hz.
        max_hz: f64,
    },
    /// An unknown method name.
    #[error("'{text}' is not a discretisation method: expected direct or paper")]
    MethodName {
        /// The text given.
        text: String,
    },
}

/// A designed filter: the steady-state Kalman gain and what follows from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// The noise model it was designed for.
    pub noise: Noise,
    /// Sample rate, Hz.
    pub fs_hz: f64,
    /// Discretisation.
    pub method: Method,
    /// Steady-state Kalman gain `K = [k1, k2]` (dimensionless).
    pub k: [f64; 2],
    /// Innovation gain `g` of `x ← x + g (z − x1 − x2)` (dimensionless).
    pub g: [f64; 2],
    /// Riccati iterations until convergence.
    pub iterations: u64,
    /// Exact −3 dB (half-power) frequency of `ω̂/z`, Hz; `None` when the response does not
    /// fall by 3 dB below Nyquist.
    pub bandwidth_hz: Option<f64>,
    /// DC gain of `ω̂/z`: `g1 / (g1 + g2)`.
    pub dc_gain: f64,
}

fn check_positive(name: &'static str, value: f64) -> Result<(), DesignError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(DesignError::NotPositive { name, value })
    }
}

fn check_inputs(noise: &Noise, fs_hz: f64) -> Result<(), DesignError> {
    check_positive("q_w", noise.q_w)?;
    check_positive("q_b", noise.q_b)?;
    check_positive("q_n", noise.q_n)?;
    check_positive("fs", fs_hz)
}

/// Steady-state gain by iterating the discrete Riccati recursion (Joseph form, paper eqs 9–11)
/// from `P0 = 0`. `P` grows without bound (the pair is rank-1 observable) but `K` converges.
///
/// Returns `(K, iterations)`.
///
/// # Errors
/// [`DesignError::NotPositive`] for a non-positive input, [`DesignError::NotConverged`] when
/// the gain has not settled within `convergence.max_iterations`.
pub fn riccati_gain(
    noise: &Noise,
    fs_hz: f64,
    convergence: Convergence,
) -> Result<([f64; 2], u64), DesignError> {
    check_inputs(noise, fs_hz)?;
    let t = 1.0 / fs_hz;
    let q_d = Matrix2::new(noise.q_w * t, 0.0, 0.0, noise.q_b * t);
    let r_d = noise.q_n / t;
    let h = Matrix1x2::new(1.0, 1.0);
    let identity = Matrix2::identity();
    let mut p = Matrix2::zeros();
    let mut k_prev = Vector2::new(f64::INFINITY, f64::INFINITY);
    let mut last_change = f64::INFINITY;
    for iteration in 1..=convergence.max_iterations {
        let p_pred = p + q_d;
        let innovation_variance = (h * p_pred * h.transpose())[(0, 0)] + r_d;
        let k: Vector2<f64> = p_pred * h.transpose() / innovation_variance;
        let i_kh = identity - k * h;
        p = i_kh * p_pred * i_kh.transpose() + k * r_d * k.transpose();
        last_change = ((k - k_prev).component_div(&k)).abs().max();
        if last_change < convergence.tolerance {
            return Ok(([k[0], k[1]], iteration));
        }
        k_prev = k;
    }
    Err(DesignError::NotConverged {
        max_iterations: convergence.max_iterations,
        last_change,
        tolerance: convergence.tolerance,
    })
}

/// Closed form of the discrete steady-state gain (the oracle of [`riccati_gain`]):
/// `q = (q_w + q_b) T`, `R_d = q_n / T`, `P⁻ = (q + √(q² + 4 q R_d)) / 2`,
/// `K = P⁻/(P⁻ + R_d) · [q_w, q_b] / (q_w + q_b)`.
pub fn closed_form_gain(noise: &Noise, fs_hz: f64) -> [f64; 2] {
    let t = 1.0 / fs_hz;
    let q = (noise.q_w + noise.q_b) * t;
    let r_d = noise.q_n / t;
    let p_pred = (q + (q * q + 4.0 * q * r_d).sqrt()) / 2.0;
    let s = p_pred / (p_pred + r_d);
    let total = noise.q_w + noise.q_b;
    [s * noise.q_w / total, s * noise.q_b / total]
}

/// Innovation gain `g` for a Kalman gain `k` under `method` (see the module doc).
/// Uses the pure-Rust `libm::expm1`, so the result does not depend on the platform.
pub fn innovation_gain(k: [f64; 2], method: Method) -> [f64; 2] {
    match method {
        Method::Direct => k,
        Method::Paper => {
            let s = k[0] + k[1];
            let factor = -libm::expm1(-s) / s;
            [k[0] * factor, k[1] * factor]
        }
    }
}

/// The paper form's matrices, evaluated literally from SPEC §1.4: `A = e^{mT}` and
/// `B = (∫₀ᵀ e^{mt} dt) kc`. For tests of [`innovation_gain`]; the model uses `g` directly.
pub fn paper_matrices(k: [f64; 2], fs_hz: f64) -> (Matrix2<f64>, Vector2<f64>) {
    let t = 1.0 / fs_hz;
    let kc = Vector2::new(k[0] / t, k[1] / t);
    let m = -(kc * Matrix1x2::new(1.0, 1.0));
    let lambda = -(kc[0] + kc[1]);
    let e = libm::exp(lambda * t);
    let a = Matrix2::identity() + m * ((e - 1.0) / lambda);
    let b_int = Matrix2::identity() * t + m * ((e - 1.0 - lambda * t) / (lambda * lambda));
    (a, b_int * kc)
}

/// Exact half-power (−3.01 dB) frequency of `ω̂/z = g1 / (1 − (1 − S) z⁻¹)`, Hz; `None` when
/// the magnitude does not fall by 3 dB below Nyquist (`S > 2√2 − 2` or `S ≤ 0`).
/// Uses the pure-Rust `libm::acos`.
pub fn bandwidth_hz(g: [f64; 2], fs_hz: f64) -> Option<f64> {
    let s = g[0] + g[1];
    let p = 1.0 - s;
    if !(p > 0.0 && p < 1.0) {
        return None;
    }
    let cos_theta = (-1.0 + 4.0 * p - p * p) / (2.0 * p);
    if !(-1.0..=1.0).contains(&cos_theta) {
        return None;
    }
    Some(libm::acos(cos_theta) * fs_hz / (2.0 * std::f64::consts::PI))
}

/// Magnitude `|ω̂/z|` at `f_hz`, evaluated directly from the transfer function (for tests and
/// plots).
pub fn magnitude(g: [f64; 2], fs_hz: f64, f_hz: f64) -> f64 {
    let p = 1.0 - (g[0] + g[1]);
    let theta = 2.0 * std::f64::consts::PI * f_hz / fs_hz;
    let re = 1.0 - p * libm::cos(theta);
    let im = p * libm::sin(theta);
    g[0] / (re * re + im * im).sqrt()
}

/// DC gain of `ω̂/z`: `g1 / (g1 + g2)`.
pub fn dc_gain(g: [f64; 2]) -> f64 {
    g[0] / (g[0] + g[1])
}

/// Designs the filter for a given noise model.
///
/// # Errors
/// As [`riccati_gain`].
pub fn design(
    noise: Noise,
    fs_hz: f64,
    method: Method,
    convergence: Convergence,
) -> Result<Design, DesignError> {
    let (k, iterations) = riccati_gain(&noise, fs_hz, convergence)?;
    let g = innovation_gain(k, method);
    Ok(Design {
        noise,
        fs_hz,
        method,
        k,
        g,
        iterations,
        bandwidth_hz: bandwidth_hz(g, fs_hz),
        dc_gain: dc_gain(g),
    })
}

/// Inverse design: the `q_w` whose filter has the −3 dB bandwidth `target_hz`, found by
/// bisection on `log q_w` (the bandwidth grows monotonically with `q_w`), then the full design
/// at that `q_w`. `noise.q_w` is ignored.
///
/// # Errors
/// [`DesignError::BandwidthUnreachable`] for a target ≤ 0 or beyond what the filter reaches at
/// this `fs`, and the errors of [`design`].
pub fn design_for_bandwidth(
    target_hz: f64,
    noise: Noise,
    fs_hz: f64,
    method: Method,
    convergence: Convergence,
) -> Result<Design, DesignError> {
    check_positive("fs", fs_hz)?;
    check_positive("q_b", noise.q_b)?;
    check_positive("q_n", noise.q_n)?;
    let unreachable = || DesignError::BandwidthUnreachable {
        target_hz,
        fs_hz,
        max_hz: fs_hz / 2.0,
    };
    if !(target_hz.is_finite() && target_hz > 0.0 && target_hz < fs_hz / 2.0) {
        return Err(unreachable());
    }
    // The bisection runs on the closed-form gain (cheap, monotone); the returned design then
    // comes from the Riccati iteration at the q_w found. The largest finite bandwidth met is
    // kept: the paper's discretisation saturates below fs/2 (its gain sum passes 1, where the
    // response no longer has a -3 dB point), and that is the limit to report.
    let reached = std::cell::Cell::new(0.0_f64);
    let bandwidth_at = |q_w: f64| {
        let k = closed_form_gain(&Noise { q_w, ..noise }, fs_hz);
        match bandwidth_hz(innovation_gain(k, method), fs_hz) {
            Some(bandwidth) => {
                reached.set(reached.get().max(bandwidth));
                bandwidth
            }
            None => f64::INFINITY,
        }
    };
    let beyond = || DesignError::BandwidthUnreachable {
        target_hz,
        fs_hz,
        max_hz: reached.get(),
    };
    let r_d = noise.q_n * fs_hz;
    let (mut lo, mut hi) = (r_d, r_d);
    let mut expansions = 0;
    while bandwidth_at(lo) > target_hz {
        lo /= 16.0;
        expansions += 1;
        if expansions > 400 || lo == 0.0 {
            return Err(unreachable());
        }
    }
    while bandwidth_at(hi) < target_hz {
        hi *= 16.0;
        expansions += 1;
        if expansions > 400 || !hi.is_finite() {
            return Err(beyond());
        }
    }
    for _ in 0..200 {
        // The geometric mean without overflowing lo * hi.
        let mid = lo.sqrt() * hi.sqrt();
        if mid <= lo || mid >= hi {
            break;
        }
        if bandwidth_at(mid) < target_hz {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let q_w = lo.sqrt() * hi.sqrt();
    // A jump from a finite bandwidth below the target to none at all is a saturation, not a
    // solution.
    let found = bandwidth_at(q_w);
    if !found.is_finite() || (found - target_hz).abs() > 1e-6 * target_hz {
        return Err(beyond());
    }
    design(Noise { q_w, ..noise }, fs_hz, method, convergence)
}

#[cfg(test)]
mod tests;
