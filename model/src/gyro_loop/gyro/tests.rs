//! The plan: settings as the config writes them, and refusals that name the key.

use super::*;
use crate::gyro_loop::PlanError;

#[test]
fn settings_keys_round_trip_and_unknown_keys_are_refused() {
    let settings = LoopSettings::default();
    let text = serde_json::to_string(&settings).unwrap();
    assert!(!text.contains("scale_coefficient_format"), "{text}");
    let back: LoopSettings = serde_json::from_str(&text).unwrap();
    assert_eq!(back, settings);
    let unknown = text.replace("pll_bandwidth_hz", "pll_bandwith_hz");
    assert!(serde_json::from_str::<LoopSettings>(&unknown).is_err());
}

/// A package made before `nco_error_feedback` existed has no such key in its manifest's
/// config and was made with plain truncation: it reads as off, so the model rebuilt from it
/// reproduces its vectors, while the default is on.
#[test]
fn a_config_without_nco_error_feedback_is_plain_truncation() {
    let mut value = serde_json::to_value(LoopSettings::default()).unwrap();
    assert_eq!(value["nco_error_feedback"], true);
    value.as_object_mut().unwrap().remove("nco_error_feedback");
    let old: LoopSettings = serde_json::from_value(value).unwrap();
    assert!(!old.nco_error_feedback);
}

#[test]
fn design_follows_the_physics() {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    let n = plan.mode(crate::resonator::Mode::Normal);
    // a_set = g q0 / FS · A_nco = 1e5 · 2e-6 / 1 V, times A_nco ≈ 1.
    assert!((n.setpoint - 0.2).abs() < 1e-5, "{}", n.setpoint);
    // u_nom: the force k q0 / Q = 15.56 µN (SPEC's example: ~15 600 LSB of 1 nN), a little
    // more for the DAC hold's sinc.
    let force = n.nominal_amplitude * spec.front_end.dac_newton_per_lsb;
    let k = spec.resonator.principal_stiffness()[0];
    let want = k * 2e-6 / spec.resonator.q_drive;
    assert!((force / want - 1.0).abs() < 5e-3, "{force} vs {want}");
    // PLL crossover f = fs kp a_set (20 Hz), zero at 1/τ.
    let [kp, ki] = plan.design.pll_gains;
    assert!((200e3 * kp * n.setpoint - 20.0).abs() < 1e-9);
    assert!((kp / (ki * 200e3) - n.figures.ring_down_time_constant).abs() < 1e-12);
    // The two references differ by ψ − ψ′ = 135.7° (SPEC): the sense offsets differ by as much.
    let r = plan.mode(crate::resonator::Mode::Reverse);
    let difference = (r.sense_offset - n.sense_offset) * 360.0;
    assert!((difference - 135.7).abs() < 0.05, "{difference}");
    // Normal and reverse 1/SF have opposite signs; quadrature coefficients are both negative.
    assert!(n.rate_coefficient.code > 0 && r.rate_coefficient.code < 0);
    assert!(n.quadrature_coefficient.code < 0 && r.quadrature_coefficient.code < 0);
}

#[test]
fn refusals_name_the_key() {
    let refuse = |edit: &dyn Fn(&mut Spec)| {
        let mut spec = Spec::paper_004();
        edit(&mut spec);
        Plan::new(&spec).unwrap_err()
    };
    let err = refuse(&|s| s.settings.adc_rate_hz = 100e3);
    assert!(
        err.to_string().starts_with("loop.adc_rate_hz = 100000"),
        "{err}"
    );
    let err = refuse(&|s| s.settings.adc_format = "s20.19".into());
    assert!(err.to_string().contains("s24.23"), "{err}");
    let err = refuse(&|s| s.settings.rounding = "up".into());
    assert!(err.to_string().starts_with("loop.rounding"), "{err}");
    let err = refuse(&|s| s.settings.lock_filter_shift = 40);
    assert!(
        err.to_string().starts_with("loop.lock_filter_shift = 40"),
        "{err}"
    );
    let err = refuse(&|s| s.settings.output_format = "q8".into());
    assert!(
        err.to_string().starts_with("loop.output_format = \"q8\""),
        "{err}"
    );
    // 1/SF is about 1e5 °/s per FS unit: an explicit s16.8 cannot hold it.
    let err = refuse(&|s| s.settings.scale_coefficient_format = Some("s16.8".into()));
    assert!(
        matches!(
            err,
            PlanError::CoefficientOverflow {
                name: "scale_coefficients",
                ..
            }
        ),
        "{err}"
    );
    let err = refuse(&|s| s.settings.adc_to_dac_latency_samples = 9);
    assert!(err.to_string().contains("0..=8"), "{err}");
    let err = refuse(&|s| s.resonator.q_drive = 0.1);
    assert!(err.to_string().starts_with("resonator.q_drive"), "{err}");
}

/// The declared ADC-to-DAC latency: the loop starts as if just switched (AGC integrator and
/// delay line cleared), so its first DAC code is `(kp + ki) · a_set` times the reference (the
/// PI's output uses the integrator after this sample's update), and it
/// appears exactly `L` samples after the ADC sample it was computed from, in the fixed model
/// and the float twin alike.
#[test]
fn the_dac_follows_the_adc_by_the_declared_latency() {
    for latency in 0..=3u32 {
        let mut spec = Spec::paper_004();
        spec.settings.adc_to_dac_latency_samples = latency;
        let plan = Plan::new(&spec).unwrap();
        let mut fixed = FixedGyroLoop::new(&plan);
        let mut float = FloatGyroLoop::new(&plan);
        for k in 0..=latency {
            let x = fixed.step([0, 0], crate::resonator::Mode::Normal).dac;
            let y = float.step([0.0, 0.0], crate::resonator::Mode::Normal).dac;
            assert_eq!(x[1], 0, "the sense DAC stays at 0");
            assert_eq!(y[1], 0.0);
            if k < latency {
                assert_eq!((x[0], y[0]), (0, 0.0), "L = {latency}, sample {k}");
            } else {
                // (kp + ki) · a_set ≈ 10 500 LSB times cos(2π δ_T).
                let n = plan.mode(crate::resonator::Mode::Normal);
                let want = (plan.agc.kp.quantized() + plan.agc.ki.quantized())
                    * n.setpoint
                    * libm::cos(2.0 * std::f64::consts::PI * n.dac_offset);
                // The NCO's phase is within half a ROM bin, π/2^(A+2) rad, of the exact one;
                // plus the DAC's rounding.
                let u = want.abs() / libm::cos(2.0 * std::f64::consts::PI * n.dac_offset).abs();
                let tolerance = u * std::f64::consts::PI / 4096.0 + 1.0;
                assert!(
                    (x[0] as f64 - want).abs() < tolerance,
                    "L = {latency}: {} vs {want}",
                    x[0]
                );
                assert!(
                    (y[0] - want).abs() < 1.0,
                    "L = {latency}: {} vs {want}",
                    y[0]
                );
            }
        }
    }
}

/// `reset` returns to the state of `new`: the same ADC codes give the same DAC codes and
/// outputs, across a mode switch.
#[test]
fn reset_replays() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let mut gyro = FixedGyroLoop::new(&plan);
    let codes: Vec<[i64; 2]> = (0..3000i64)
        .map(|k| [(k * 7919) % 200_003 - 100_000, (k * 104_729) % 3001 - 1500])
        .collect();
    let mode = |k: usize| {
        if k < 1500 {
            crate::resonator::Mode::Normal
        } else {
            crate::resonator::Mode::Reverse
        }
    };
    let run = |gyro: &mut FixedGyroLoop| -> Vec<FixedStep> {
        codes
            .iter()
            .enumerate()
            .map(|(k, c)| gyro.step(*c, mode(k)))
            .collect()
    };
    let first = run(&mut gyro);
    assert!(first.iter().filter(|s| s.chain.is_some()).count() == 3);
    gyro.reset();
    assert_eq!(run(&mut gyro), first);
}
