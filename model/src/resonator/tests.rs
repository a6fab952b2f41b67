//! The simulation against independent oracles: SPEC §1.6's closed forms (through an ideal
//! float drive and an ideal float demodulator written here), the continuous-time steady
//! state, equipartition and the fluctuation–dissipation PSD.

use std::f64::consts::PI;

use proptest::prelude::*;
use rustfft::num_complex::Complex64 as C;

use super::*;

const DEG: f64 = PI / 180.0;

/// The axis each mode drives and senses.
fn axes(mode: Mode) -> (usize, usize) {
    match mode {
        Mode::Normal => (0, 1),
        Mode::Reverse => (1, 0),
    }
}

/// Continuous-time steady-state displacement phasors (m) of the undiscretised equation of
/// motion for the force phasors `force` (N) at `w` (rad/s) and the rate `omega` (rad/s):
/// `(K − m w² I + i w (D − G)) q̂ = f̂`.
fn steady_state(params: &ResonatorParams, omega: f64, w: f64, force: [C; 2]) -> [C; 2] {
    let m = params.mass_kg;
    let mats = params.matrices();
    let g = 2.0 * m * omega;
    let d_minus_g = [
        [mats.d[0][0], mats.d[0][1] - g],
        [mats.d[1][0] + g, mats.d[1][1]],
    ];
    let entry = |i: usize, j: usize| {
        let mass = if i == j { m * w * w } else { 0.0 };
        C::new(mats.k[i][j] - mass, w * d_minus_g[i][j])
    };
    let (a, b, c, d) = (entry(0, 0), entry(0, 1), entry(1, 0), entry(1, 1));
    let det = a * d - b * c;
    [
        (d * force[0] - b * force[1]) / det,
        (a * force[1] - c * force[0]) / det,
    ]
}

/// An ideal drive (a float oscillator with perfect PLL and AGC): the held force phasor `f̂`
/// (N) on the driven axis whose fundamental holds `q_a = q0 cos(w t)` exactly at the mode's
/// closed-form `w`, and the resulting continuous steady state.
struct IdealDrive {
    w: f64,
    force: C,
    displacement: [C; 2],
}

fn ideal_drive(params: &ResonatorParams, mode: Mode, omega: f64, fs: f64) -> IdealDrive {
    let w = ModeFigures::new(params, mode).drive_angular_frequency;
    let (driven, _) = axes(mode);
    let mut unit = [C::new(0.0, 0.0); 2];
    unit[driven] = C::new(1.0, 0.0);
    let per_newton = steady_state(params, omega, w, unit);
    let effective = params.drive_amplitude_m / per_newton[driven];
    // A force held over each sample has the fundamental f̂ · sinc(wT/2) e^{−iwT/2}.
    let half = w / fs / 2.0;
    let hold = C::new(libm::cos(-half), libm::sin(-half)) * (libm::sin(half) / half);
    IdealDrive {
        w,
        force: effective / hold,
        displacement: per_newton.map(|q| q * effective),
    }
}

/// Least-squares phasor `v̂` of `v(t_k) = Re{v̂ e^{i w t_k}}`, t_k = (first + k)/fs: over a
/// whole number of cycles this is the ideal I/Q demodulator; over a fraction more it stays
/// exact for a pure sinusoid.
fn phasor(v: &[f64], w: f64, fs: f64, first: usize) -> C {
    let (mut cc, mut cs, mut ss, mut vc, mut vs) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (k, value) in v.iter().enumerate() {
        let phase = w * (first + k) as f64 / fs;
        let (c, s) = (libm::cos(phase), libm::sin(phase));
        cc += c * c;
        cs += c * s;
        ss += s * s;
        vc += value * c;
        vs += value * s;
    }
    let det = cc * ss - cs * cs;
    let a = (vc * ss - vs * cs) / det;
    let b = (vs * cc - vc * cs) / det;
    C::new(a, -b)
}

/// What an ideal demodulator reads: the drive phasor (m) and the sense channel's in-phase and
/// quadrature outputs (m), referenced to the measured drive phase and amplitude as a
/// perfect PLL and AGC would, with the nominal sense phase ψ compensated.
#[derive(Debug)]
struct Demodulated {
    drive: C,
    in_phase: f64,
    quadrature: f64,
}

/// Simulates `mode` at `omega` under the ideal drive — from the continuous steady state, or
/// from rest with `settle` samples to settle — and demodulates `cycles` drive cycles.
fn run(
    params: &ResonatorParams,
    settings: &PhysicsSettings,
    mode: Mode,
    omega: f64,
    from_rest: bool,
    settle: usize,
    cycles: f64,
) -> Demodulated {
    let fs = settings.sample_rate_hz;
    let figures = ModeFigures::new(params, mode);
    let drive = ideal_drive(params, mode, omega, fs);
    let (driven, sensed) = axes(mode);
    let mut r = Resonator::new(params, settings, 5).unwrap();
    r.set_mode(mode);
    r.set_rate(omega);
    if !from_rest {
        let q = drive.displacement;
        let v = q.map(|q| q * C::new(0.0, drive.w));
        r.set_state([q[0].re, q[1].re], [v[0].re, v[1].re]);
    }
    let length = (cycles * fs * 2.0 * PI / drive.w).round() as usize;
    let mut volts = [Vec::with_capacity(length), Vec::with_capacity(length)];
    for k in 0..settle + length {
        let phase = drive.w * k as f64 / fs;
        let mut force = [0.0; 2];
        force[driven] = (drive.force * C::new(libm::cos(phase), libm::sin(phase))).re;
        let v = r.step(force);
        if k >= settle {
            volts[0].push(v[0]);
            volts[1].push(v[1]);
        }
    }
    // Sample k of the step loop is taken at t = (k + 1) T.
    let gain = settings.pickoff_gain_v_per_m;
    let drive_phasor = phasor(&volts[driven], drive.w, fs, settle + 1) / gain[driven];
    let sense_phasor = phasor(&volts[sensed], drive.w, fs, settle + 1) / gain[sensed];
    // Reference: the Coriolis phase of the sense displacement, −i e^{−iψ} relative to the
    // drive displacement; the sense signal is normalised to the drive amplitude q0.
    let drive_unit = drive_phasor / drive_phasor.norm();
    let reference = C::new(0.0, -1.0) * C::from_polar(1.0, -figures.sense_phase) * drive_unit;
    let p = sense_phasor * reference.conj() * (params.drive_amplitude_m / drive_phasor.norm());
    Demodulated {
        drive: drive_phasor,
        in_phase: p.re,
        quadrature: -p.im,
    }
}

/// Measured scale factor (m per rad/s), bias (rad/s) and quadrature at Ω = 0 (m) of `mode`,
/// and the largest drive-phasor error relative to q0.
fn measure(
    params: &ResonatorParams,
    settings: &PhysicsSettings,
    mode: Mode,
    test_rate: f64,
) -> (f64, f64, f64, f64) {
    let sigma = ModeFigures::new(params, mode).sigma();
    let at_rest = run(params, settings, mode, 0.0, false, 0, 200.0);
    let turning = run(params, settings, mode, test_rate, false, 0, 200.0);
    let scale_factor = (turning.in_phase - at_rest.in_phase) / (sigma * test_rate);
    let q0 = C::new(params.drive_amplitude_m, 0.0);
    let drive_error =
        ((at_rest.drive - q0).norm() / q0.re).max((turning.drive - q0).norm() / q0.re);
    (
        scale_factor,
        at_rest.in_phase / scale_factor,
        at_rest.quadrature,
        drive_error,
    )
}

fn settings_for(params: &ResonatorParams, samples_per_cycle: f64) -> PhysicsSettings {
    PhysicsSettings {
        sample_rate_hz: samples_per_cycle
            * params.drive_frequency_hz.max(params.sense_frequency_hz),
        ..PhysicsSettings::example().noiseless()
    }
}

#[test]
fn simulation_reproduces_spec_1_6_numbers_from_rest() {
    // Paper 004 at 200 kHz, driven from rest for 20 ring-down times (e^-20 of the start-up
    // transient is left), then demodulated over 200 cycles.
    let params = ResonatorParams::paper_004();
    let settings = PhysicsSettings::example().noiseless();
    let settle = (20.0 * 7.15e-3 * settings.sample_rate_hz) as usize;
    let test_rate = 100.0 * DEG;
    let mut biases = Vec::new();
    let mut scale_factors = Vec::new();
    for mode in [Mode::Normal, Mode::Reverse] {
        let figures = ModeFigures::new(&params, mode);
        let at_rest = run(&params, &settings, mode, 0.0, true, settle, 200.0);
        let turning = run(&params, &settings, mode, test_rate, true, settle, 200.0);
        let sf = (turning.in_phase - at_rest.in_phase) / (figures.sigma() * test_rate);
        let bias = at_rest.in_phase / sf;
        // SPEC's printed figures: SF 97.80 / 96.37 pm per °/s, B 20.376 / 20.395 °/s.
        let (sf_spec, bias_spec) = match mode {
            Mode::Normal => (97.80e-12, 20.376),
            Mode::Reverse => (96.37e-12, 20.395),
        };
        assert!(
            (sf * DEG / sf_spec - 1.0).abs() < 1e-3,
            "{mode:?}: SF {} pm per °/s",
            sf * DEG * 1e12
        );
        assert!(
            (bias / DEG / bias_spec - 1.0).abs() < 1e-3,
            "{mode:?}: B {} °/s",
            bias / DEG
        );
        // Quadrature: about 166 °/s mechanical, k_xy/(2mw), less the damping coupling's leak
        // d_xy tan φ/(2m) = 0.305 °/s.
        let quadrature = at_rest.quadrature / sf / DEG;
        let quadrature_spec = match mode {
            Mode::Normal => 165.958 - 0.305,
            Mode::Reverse => 167.038 - 0.305,
        };
        assert!(
            (quadrature - quadrature_spec).abs() < 0.01,
            "{mode:?}: Q {quadrature} °/s"
        );
        biases.push(bias);
        scale_factors.push(sf);
    }
    // Mode reversal: (B − B′)/2 = −0.0094 °/s with each mode's own SF.
    let residual = (biases[0] - biases[1]) / 2.0 / DEG;
    assert!(
        (residual + 0.0094).abs() < 5e-4,
        "(B − B′)/2 = {residual} °/s"
    );
    let gain_error = (scale_factors[1] / scale_factors[0] - 1.0) / 2.0;
    assert!((gain_error * 100.0 + 0.73).abs() < 0.01, "{gain_error}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// SF, bias and quadrature of the simulation within 1 % of the closed forms, in both
    /// modes, across random structures; the simulated drive follows the continuous steady
    /// state (a check of the exact discretisation).
    #[test]
    fn simulation_follows_the_closed_forms(
        f1 in 5e3..30e3f64,
        split in 0.002..0.02f64,
        split_sign in prop::bool::ANY,
        log_q in (1.7..3.7f64, 1.7..3.7f64),
        angles in (-3.0..3.0f64, -3.0..3.0f64),
        phases in (-3.0..3.0f64, -3.0..3.0f64),
        q0 in 0.5e-6..10e-6f64,
        mass in 1e-7..1e-6f64,
        samples_per_cycle in 12.0..25.0f64,
    ) {
        let params = ResonatorParams {
            mass_kg: mass,
            drive_frequency_hz: f1,
            sense_frequency_hz: f1 * if split_sign { 1.0 + split } else { 1.0 - split },
            q_drive: libm::pow(10.0, log_q.0),
            q_sense: libm::pow(10.0, log_q.1),
            stiffness_angle_deg: angles.0,
            damping_angle_deg: angles.1,
            drive_amplitude_m: q0,
            phase_error_deg: phases.0,
            phase_error_reverse_deg: phases.1,
        };
        let settings = settings_for(&params, samples_per_cycle);
        for mode in [Mode::Normal, Mode::Reverse] {
            let figures = ModeFigures::new(&params, mode);
            let test_rate = 100.0 * DEG;
            let (sf, bias, quadrature, drive_error) = measure(&params, &settings, mode, test_rate);
            prop_assert!(drive_error < 1e-4, "{mode:?}: drive off the steady state by {drive_error}");
            prop_assert!(
                (sf / figures.scale_factor - 1.0).abs() < 0.01,
                "{mode:?}: SF {sf} vs {}", figures.scale_factor
            );
            // 1 % of B, or 1e-4 of the mechanical quadrature where B is near zero.
            let floor = 1e-4 * figures.mechanical_quadrature.abs();
            prop_assert!(
                (bias - figures.bias()).abs() <= 0.01 * figures.bias().abs() + floor,
                "{mode:?}: B {} vs {} °/s", bias / DEG, figures.bias_dps()
            );
            let want = figures.quadrature(0.0);
            prop_assert!(
                (quadrature - want).abs() <= 0.01 * want.abs() + floor * figures.scale_factor,
                "{mode:?}: Q {quadrature} vs {want} m"
            );
        }
    }
}
