//! Closed forms of the demodulated gyro outputs per mode, and what mode reversal leaves
//! (SPEC §1.6). These are the oracle the simulation in [`super::physics`] must reproduce.
//!
//! In mode `σ` (+1 normal: x driven, y sensed; −1 reverse: y driven, x sensed), with `a` the
//! driven and `s` the sensed axis, the drive holds `q_a = q0 cos(w t)` at
//! `w = sqrt(k_aa / m)` and the sense axis sees the force
//! `−k_xy q_a − d_xy q_a′ − 2 σ m Ω q_a′`. With the sense impedance
//! `Z = k_ss − m w² + i w d_ss = |Z| e^{iψ}` and a demodulation reference that lags the
//! Coriolis component of the sense signal by the phase error `φ` (`φ′` in reverse mode):
//!
//! ```text
//! I  = SF (σ Ω + B)                                            in-phase output, m
//! SF = 2 m w q0 cos φ / |Z|                                     m per rad/s
//! B  = d_xy / (2m) + k_xy tan φ / (2 m w)                       rad/s (damping + quadrature leak)
//! Q  = (q0/|Z|) [k_xy cos φ − w (d_xy + 2 σ m Ω) sin φ]         quadrature output, m
//! ```
//!
//! After the front end flips reverse mode's sign and divides by SF, the chain sees
//! `S = Ω + B` and `S′ = Ω − B′`, so `(S + S′)/2 = Ω + (B − B′)/2`: the reversal residual.

use std::f64::consts::PI;

use super::{Mode, ResonatorParams};

/// Radians per degree (rates: rad/s per °/s).
const RAD_PER_DEG: f64 = PI / 180.0;

/// The closed-form figures of one mode. Rates in rad/s, lengths in m, unless a name says
/// otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeFigures {
    /// The mode.
    pub mode: Mode,
    /// `w = sqrt(k_aa / m)`: the driven axis's resonance, rad/s.
    pub drive_angular_frequency: f64,
    /// `|Z|`, N/m.
    pub sense_impedance: f64,
    /// `ψ = arg Z`, rad, in (−π, π].
    pub sense_phase: f64,
    /// The phase error of this mode (`φ` or `φ′`), rad.
    pub phase_error: f64,
    /// Drive amplitude `q0`, m.
    pub drive_amplitude: f64,
    /// `SF = 2 m w q0 cos φ / |Z|`, m per rad/s.
    pub scale_factor: f64,
    /// Damping-coupling bias `d_xy / (2m)`, rad/s.
    pub bias_damping: f64,
    /// Quadrature-leak bias `k_xy tan φ / (2 m w)`, rad/s.
    pub bias_quadrature_leak: f64,
    /// Mechanical quadrature `k_xy / (2 m w)`, rad/s: the quadrature force expressed as the
    /// rate whose Coriolis force has the same amplitude.
    pub mechanical_quadrature: f64,
    /// Mass, kg, coupling terms `k_xy` (N/m) and `d_xy` (N·s/m), kept for [`Self::quadrature`].
    mass: f64,
    k_xy: f64,
    d_xy: f64,
    /// Ring-down time constant of the drive mode once the drive stops, s: `2 m / d_mode`
    /// with `d_mode = uᵀ D u` the damping along the mode's principal stiffness axis `u`
    /// (`d1 cos²(ε−θ) + d2 sin²(ε−θ)` normal, `d1 sin²(ε−θ) + d2 cos²(ε−θ)` reverse). This
    /// is `2 Q1 / w1` (normal) when `θ = ε`; first order in the coupling, so it holds for
    /// modes split by more than the damping couples them.
    pub ring_down_time_constant: f64,
}

impl ModeFigures {
    /// The resonator's mass, kg.
    pub fn mass_kg(&self) -> f64 {
        self.mass
    }

    /// The figures of `mode` for `params` (assumed valid, see [`ResonatorParams::validate`]).
    pub fn new(params: &ResonatorParams, mode: Mode) -> Self {
        let m = params.mass_kg;
        let mats = params.matrices();
        let k_aa = mats.k[mode.axes()[0]][mode.axes()[0]];
        let phase_deg = match mode {
            Mode::Normal => params.phase_error_deg,
            Mode::Reverse => params.phase_error_reverse_deg,
        };
        let (k_xy, d_xy) = (mats.k[0][1], mats.d[0][1]);
        let misalignment = (params.stiffness_angle_deg - params.damping_angle_deg) * RAD_PER_DEG;
        let (c2, s2) = (
            libm::cos(misalignment) * libm::cos(misalignment),
            libm::sin(misalignment) * libm::sin(misalignment),
        );
        let [d1, d2] = mats.d_principal;
        let d_mode = match mode {
            Mode::Normal => d1 * c2 + d2 * s2,
            Mode::Reverse => d1 * s2 + d2 * c2,
        };
        let w = (k_aa / m).sqrt();
        let (z_abs, psi) = sense_impedance(params, mode, w);
        let phi = phase_deg * RAD_PER_DEG;
        let q0 = params.drive_amplitude_m;
        ModeFigures {
            mode,
            drive_angular_frequency: w,
            sense_impedance: z_abs,
            sense_phase: psi,
            phase_error: phi,
            drive_amplitude: q0,
            scale_factor: 2.0 * m * w * q0 * libm::cos(phi) / z_abs,
            bias_damping: d_xy / (2.0 * m),
            bias_quadrature_leak: k_xy * libm::tan(phi) / (2.0 * m * w),
            mechanical_quadrature: k_xy / (2.0 * m * w),
            mass: m,
            k_xy,
            d_xy,
            ring_down_time_constant: 2.0 * m / d_mode,
        }
    }

    /// `σ`: +1 in normal mode, −1 in reverse mode.
    pub fn sigma(&self) -> f64 {
        match self.mode {
            Mode::Normal => 1.0,
            Mode::Reverse => -1.0,
        }
    }

    /// Drive frequency `w / 2π`, Hz.
    pub fn drive_frequency_hz(&self) -> f64 {
        self.drive_angular_frequency / (2.0 * PI)
    }

    /// Scale factor, m per °/s.
    pub fn scale_factor_m_per_dps(&self) -> f64 {
        self.scale_factor * RAD_PER_DEG
    }

    /// `B`, rad/s.
    pub fn bias(&self) -> f64 {
        self.bias_damping + self.bias_quadrature_leak
    }

    /// `B`, °/s.
    pub fn bias_dps(&self) -> f64 {
        self.bias() / RAD_PER_DEG
    }

    /// `dB/dφ = k_xy / (2 m w cos² φ)`: rad/s of bias per radian of phase error, which is
    /// the same number as °/s per degree.
    pub fn bias_sensitivity_to_phase(&self) -> f64 {
        let c = libm::cos(self.phase_error);
        self.mechanical_quadrature / (c * c)
    }

    /// In-phase output `I = SF (σ Ω + B)` for the rate `omega` (rad/s), m.
    pub fn in_phase(&self, omega: f64) -> f64 {
        self.scale_factor * (self.sigma() * omega + self.bias())
    }

    /// Quadrature output `Q = (q0/|Z|) [k_xy cos φ − w (d_xy + 2 σ m Ω) sin φ]` for the rate
    /// `omega` (rad/s), m.
    pub fn quadrature(&self, omega: f64) -> f64 {
        let damping = self.d_xy + 2.0 * self.sigma() * self.mass * omega;
        self.drive_amplitude / self.sense_impedance
            * (self.k_xy * libm::cos(self.phase_error)
                - self.drive_angular_frequency * damping * libm::sin(self.phase_error))
    }

    /// The phase error (rad, in (−π, π]) that a mode's zero-rate outputs imply: with
    /// `A = k_xy` and `C = w d_xy`, `Q + iI = (q0/|Z|)(A + iC) e^{iφ}` at `Ω = 0`, so
    /// `φ = arg(Q + iI) − arg(A + iC)`. `in_phase` and `quadrature` are in one unit (m, or both
    /// divided by one scale factor, as the loop's rate and quadrature outputs are): their
    /// common gain cancels. This is how the phase a loop realizes is read from its outputs
    /// (issue 32), whatever phase this mode's figures were made with.
    pub fn phase_from_outputs(&self, in_phase: f64, quadrature: f64) -> f64 {
        self.phase_from_outputs_at(in_phase, quadrature, self.drive_angular_frequency)
    }

    /// `arg(k_xy + i w d_xy)` at the drive's `angular_frequency` (rad/s), rad: the phase of
    /// the coupling force on the sense axis against the drive displacement (less π).
    pub fn mechanical_angle(&self, angular_frequency: f64) -> f64 {
        libm::atan2(angular_frequency * self.d_xy, self.k_xy)
    }

    /// [`Self::phase_from_outputs`] for a drive at `angular_frequency` (rad/s) instead of
    /// `w`: a loop locks on the coupled resonance, where `C = w_L d_xy`.
    pub fn phase_from_outputs_at(
        &self,
        in_phase: f64,
        quadrature: f64,
        angular_frequency: f64,
    ) -> f64 {
        let angle = libm::atan2(in_phase, quadrature) - self.mechanical_angle(angular_frequency);
        // Wrapped to (−π, π].
        let turns = libm::ceil((angle - PI) / (2.0 * PI));
        angle - 2.0 * PI * turns
    }
}

/// The sense axis's impedance `Z_ss(w) = k_ss − m w² + i w d_ss` of `mode` at the angular
/// frequency `w` (rad/s), as `(|Z|, arg Z)` in N/m and rad (`arg` in (−π, π]).
pub fn sense_impedance(params: &ResonatorParams, mode: Mode, w: f64) -> (f64, f64) {
    let mats = params.matrices();
    let s = mode.axes()[1];
    let (re, im) = (mats.k[s][s] - params.mass_kg * w * w, w * mats.d[s][s]);
    (libm::hypot(re, im), libm::atan2(im, re))
}

/// The coupled drive resonance of `mode` at `Ω = 0`, Hz: where `Re(Z_aa − Z_as²/Z_ss) = 0`
/// with `Z_ij = k_ij − m w² δ_ij + i w d_ij` (bisection within ±5 % of `sqrt(k_aa/m)`).
pub fn coupled_resonance_hz(params: &ResonatorParams, mode: Mode) -> f64 {
    let mats = params.matrices();
    let m = params.mass_kg;
    let [a, s] = mode.axes();
    let real_part = |w: f64| {
        let zaa_re = mats.k[a][a] - m * w * w;
        let (zss_re, zss_im) = (mats.k[s][s] - m * w * w, w * mats.d[s][s]);
        let (c_re, c_im) = (mats.k[0][1], w * mats.d[0][1]);
        // Z_as² / Z_ss.
        let (n_re, n_im) = (c_re * c_re - c_im * c_im, 2.0 * c_re * c_im);
        let den = zss_re * zss_re + zss_im * zss_im;
        let q_re = (n_re * zss_re + n_im * zss_im) / den;
        zaa_re - q_re
    };
    let w0 = (mats.k[a][a] / m).sqrt();
    let (mut lo, mut hi) = (0.95 * w0, 1.05 * w0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if real_part(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi) / (2.0 * std::f64::consts::PI)
}

/// Both modes and what mode reversal leaves of the bias.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reversal {
    /// Normal mode.
    pub normal: ModeFigures,
    /// Reverse mode.
    pub reverse: ModeFigures,
}

impl Reversal {
    /// Both modes of `params`.
    pub fn new(params: &ResonatorParams) -> Self {
        Reversal {
            normal: ModeFigures::new(params, Mode::Normal),
            reverse: ModeFigures::new(params, Mode::Reverse),
        }
    }

    /// `(B − B′)/2`, rad/s: what `(S + S′)/2` adds to the rate when each mode is divided by
    /// its own SF.
    pub fn residual_own_scale_factor(&self) -> f64 {
        (self.normal.bias() - self.reverse.bias()) / 2.0
    }

    /// `SF′/SF`: how the reverse mode's scale factor compares with normal mode's.
    pub fn scale_factor_ratio(&self) -> f64 {
        self.reverse.scale_factor / self.normal.scale_factor
    }

    /// Relative rate-gain error of `(S + S′)/2` when both modes are divided by normal mode's
    /// SF (paper 004's scheme): `(SF′/SF − 1)/2` (dimensionless; −0.0073 is −0.73 %).
    pub fn shared_scale_factor_gain_error(&self) -> f64 {
        (self.scale_factor_ratio() - 1.0) / 2.0
    }

    /// Residual bias of `(S + S′)/2` in that scheme: `(B − (SF′/SF) B′)/2`, rad/s.
    pub fn residual_shared_scale_factor(&self) -> f64 {
        (self.normal.bias() - self.scale_factor_ratio() * self.reverse.bias()) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEG: f64 = RAD_PER_DEG;

    /// The zero-rate outputs at a phase error give that phase back, in both modes, for any
    /// common gain on them; another mode's figures (made at another phase) read it the same.
    #[test]
    fn the_phase_is_read_back_from_the_zero_rate_outputs() {
        for phase_deg in [-3.0, -0.5, 0.0, 0.999, 1.0, 2.5] {
            let mut params = ResonatorParams::paper_004();
            params.phase_error_deg = phase_deg;
            params.phase_error_reverse_deg = -phase_deg / 2.0;
            let reading = Reversal::new(&ResonatorParams::paper_004());
            for (mode, want) in [(Mode::Normal, phase_deg), (Mode::Reverse, -phase_deg / 2.0)] {
                let f = ModeFigures::new(&params, mode);
                let reader = match mode {
                    Mode::Normal => reading.normal,
                    Mode::Reverse => reading.reverse,
                };
                for gain in [1.0, 1e10, 1.0 / f.scale_factor] {
                    let got =
                        reader.phase_from_outputs(gain * f.in_phase(0.0), gain * f.quadrature(0.0));
                    close(got / DEG, want, 1e-9, "phase read back (°)");
                }
            }
        }
    }

    fn close(got: f64, want: f64, tolerance: f64, what: &str) {
        assert!(
            (got - want).abs() <= tolerance,
            "{what}: {got} vs {want} (± {tolerance})"
        );
    }

    /// SPEC §1.6's worked numbers for paper 004's Table 1 and the defaults, each to the
    /// digits SPEC prints.
    #[test]
    fn reproduces_spec_1_6_numbers() {
        let r = Reversal::new(&ResonatorParams::paper_004());
        let (n, v) = (r.normal, r.reverse);
        close(
            n.scale_factor_m_per_dps() * 1e12,
            97.80,
            0.005,
            "SF (pm per °/s)",
        );
        close(
            v.scale_factor_m_per_dps() * 1e12,
            96.37,
            0.005,
            "SF′ (pm per °/s)",
        );
        close(n.bias_dps(), 20.376, 5e-4, "B (°/s)");
        close(n.bias_damping / DEG, 17.479, 5e-4, "B, damping (°/s)");
        close(
            n.bias_quadrature_leak / DEG,
            2.897,
            5e-4,
            "B, quadrature leak (°/s)",
        );
        close(v.bias_dps(), 20.395, 5e-4, "B′ (°/s)");
        // "About 166 °/s".
        close(
            n.mechanical_quadrature / DEG,
            166.0,
            0.5,
            "quadrature (°/s)",
        );
        close(
            r.residual_own_scale_factor() / DEG,
            -0.0094,
            5e-5,
            "(B − B′)/2 (°/s)",
        );
        close(
            r.shared_scale_factor_gain_error() * 100.0,
            -0.73,
            0.005,
            "gain (%)",
        );
        close(
            r.residual_shared_scale_factor() / DEG,
            0.14,
            0.005,
            "shared residual",
        );
        // 2.9 °/s per degree of φ (rad/s per rad is the same number).
        close(n.bias_sensitivity_to_phase(), 2.9, 0.05, "dB/dφ");
        // Sense phase differs by about 136° between the modes (sense above vs below its
        // resonance), and the drive is at sqrt(kxx/m) ≈ 8195 Hz.
        close(
            (n.sense_phase - v.sense_phase) / DEG,
            135.7,
            0.05,
            "ψ − ψ′ (°)",
        );
        close(n.drive_frequency_hz(), 8195.0, 0.01, "w/2π (Hz)");
        // SPEC prints "2Q/w = 7.2 ms"; 2 · 184 / (2π · 8195 Hz) is 7.147 ms.
        close(n.ring_down_time_constant * 1e3, 7.147, 0.001, "2Q/w (ms)");
        close(v.ring_down_time_constant * 1e3, 7.623, 0.001, "2Q′/w′ (ms)");
    }

    #[test]
    fn in_phase_and_quadrature_follow_the_rate() {
        let r = Reversal::new(&ResonatorParams::paper_004());
        let omega = 100.0 * DEG;
        // Linear in Ω with slope σ SF, and zero where σΩ = −B.
        close(
            r.normal.in_phase(omega) - r.normal.in_phase(0.0),
            r.normal.scale_factor * omega,
            1e-20,
            "normal slope",
        );
        close(
            r.reverse.in_phase(omega) - r.reverse.in_phase(0.0),
            -r.reverse.scale_factor * omega,
            1e-20,
            "reverse slope",
        );
        close(r.normal.in_phase(-r.normal.bias()), 0.0, 1e-20, "null");
        // Q/SF at Ω = 0: mechanical quadrature minus the damping term's leak, in rate units.
        let q_rate = r.normal.quadrature(0.0) / r.normal.scale_factor;
        let phi = r.normal.phase_error;
        let want = r.normal.mechanical_quadrature - r.normal.bias_damping * libm::tan(phi);
        close(q_rate, want, 1e-9, "Q in rate units");
    }
}
