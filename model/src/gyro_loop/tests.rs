//! The blocks together: what the loop relies on them for.

use super::*;
use crate::fx::from_f64;

/// An ADC sine of amplitude `a` leading the NCO's sine reference by `phi`: the demodulator
/// gives `I = a·A_nco·cos φ`, `Q = a·A_nco·sin φ` (averaged over the 2f ripple).
#[test]
fn the_nco_and_demodulator_measure_amplitude_and_phase() {
    let nco_plan = nco::Plan::new(&nco::Spec::default()).unwrap();
    let plan = demodulator::Plan::new(&demodulator::Spec::default()).unwrap();
    let freq = nco_plan.frequency_word(8195.0, 200_000.0).unwrap();
    for (amplitude, phi_deg) in [(0.5, 30.0), (0.9, -120.0), (0.01, 91.0)] {
        let mut nco = nco::FixedNco::new(&nco_plan);
        let mut demodulator = demodulator::FixedDemodulator::new(&plan);
        let phi = f64::to_radians(phi_deg);
        let (mut sum_i, mut sum_q) = (0.0, 0.0);
        let samples = 30_000;
        let averaged = 10_000;
        for n in 0..samples {
            let theta = 2.0 * std::f64::consts::PI * nco.accumulator() as f64 / 2f64.powi(32);
            let adc = from_f64(
                amplitude * (theta + phi).sin(),
                plan.input,
                Rounding::Nearest,
                Overflow::Saturate,
            )
            .unwrap()
            .code as i64;
            let out = demodulator.step(adc, nco.step(freq, 0));
            if n >= samples - averaged {
                sum_i += plan.output.to.to_f64(i128::from(out.i));
                sum_q += plan.output.to.to_f64(i128::from(out.q));
            }
        }
        let scale = amplitude * nco_plan.amplitude();
        let (i, q) = (sum_i / averaged as f64, sum_q / averaged as f64);
        // The ripple averages out; what is left is the NCO's truncation spurs and the ADC's
        // and the outputs' rounding.
        let tolerance = 2e-4 * amplitude + 1e-6;
        assert!(
            (i - scale * phi.cos()).abs() < tolerance,
            "I {i} for {phi_deg}°"
        );
        assert!(
            (q - scale * phi.sin()).abs() < tolerance,
            "Q {q} for {phi_deg}°"
        );
    }
}

/// The PI's output format `s P.P` drives the NCO's `u P.P` frequency word bit for bit: a
/// negative frequency is the same phase step mod one cycle.
#[test]
fn a_signed_pi_output_is_a_frequency_word() {
    let nco_plan = nco::Plan::new(&nco::Spec::default()).unwrap();
    let pi_plan = pi::Plan::new(&pi::Spec {
        integrator_limits: [-0.1, 0.1],
        ..pi::Spec::default()
    })
    .unwrap();
    let mut pi = pi::FixedPi::new(&pi_plan);
    pi.preset(pi_plan.integrator_code(-0.04).unwrap());
    let word = pi.step(0);
    assert!(word < 0);
    let as_frequency = pi_plan.output.to.to_bits(i128::from(word)) as u64;
    let expected = nco_plan
        .frequency_word(-0.04 * 200_000.0, 200_000.0)
        .unwrap();
    assert!(
        as_frequency.abs_diff(expected) <= 1,
        "{as_frequency} vs {expected}"
    );
}

#[test]
fn coefficient_errors_name_block_coefficient_value_and_bits() {
    let format: crate::fx::Format = "s8.6".parse().unwrap();
    let err = quantize_coefficients(
        "cic",
        "taps",
        &[0.5, -2.5],
        CoefficientFormat::Fixed(format),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "cic.taps = -2.5e0 does not fit s8.6: it needs 9 bits at 6 fraction bits (the largest value is 1.984375e0)"
    );
    let auto = quantize_coefficients(
        "cic",
        "taps",
        &[0.5, -2.5],
        CoefficientFormat::Auto { width: 8 },
    )
    .unwrap();
    assert_eq!(auto[1].format, "s8.5".parse().unwrap());
    assert_eq!(auto[1].code, -80);
    let err = quantize_coefficients(
        "pi",
        "kp",
        &[f64::NAN],
        CoefficientFormat::Auto { width: 8 },
    )
    .unwrap_err();
    assert!(err.to_string().contains("pi.kp = NaN"), "{err}");
}
