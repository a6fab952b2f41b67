//! The loop closed around paper 004's resonator: SPEC §1.6's figures, fixed against float,
//! determinism.

use proptest::prelude::*;

use super::*;
use crate::gyro_loop::figures::{
    characterize, characterize_reporting, coupled_resonance_hz, Characterization, Procedure,
    AVERAGES,
};
use crate::gyro_loop::gyro::{LoopNode, ModePlan, Spec};

fn paper_004() -> (Spec, Plan) {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    (spec, plan)
}

/// The figures, through the reporting entry point: it reports each of its averages once.
fn characterized<L: LoopUnderTest>(spec: &Spec, plan: &Plan) -> Characterization {
    let procedure = Procedure::default();
    let reported = std::cell::Cell::new(0usize);
    let c = characterize_reporting::<L>(plan, &spec.resonator, &spec.front_end, &procedure, &|n| {
        reported.set(reported.get() + n)
    })
    .unwrap();
    assert_eq!(reported.get(), AVERAGES * procedure.average_samples);
    c
}

/// SPEC §1.6 with Table 1 and the defaults, for the fixed loop: each figure against its
/// closed form (the predictions come from `resonator::closed_form` and the coupled-resonance
/// solver, not from the loop).
#[test]
fn fixed_loop_reproduces_spec_1_6_with_paper_004() {
    let (spec, plan) = paper_004();
    let c = characterized::<FixedHarness>(&spec, &plan);
    let q0 = spec.resonator.drive_amplitude_m;
    for (m, sigma) in [(&c.normal, 1.0), (&c.reverse, -1.0)] {
        let what = m.mode;
        // The closed-form resonance is the predicted one: SPEC's "a few mHz" below sqrt(k/m).
        let f = m.drive_frequency_hz;
        assert!(
            (f.measured - f.predicted).abs() < 0.01,
            "{what}: drive at {} Hz, coupled resonance {} Hz",
            f.measured,
            f.predicted
        );
        let a = m.drive_amplitude_m;
        assert!(
            (a.measured / q0 - 1.0).abs() < 1e-3,
            "{what}: amplitude {} m",
            a.measured
        );
        let sf = m.scale_factor;
        assert!(
            (sf.measured - 1.0).abs() < 1e-3,
            "{what}: scale factor {}",
            sf.measured
        );
        // Sign per SPEC: +B normal, −B′ reverse, both about 20.4 °/s.
        let b = m.bias_dps;
        assert!(
            b.predicted * sigma > 20.0,
            "{what}: predicted bias {}",
            b.predicted
        );
        assert!(
            (b.measured - b.predicted).abs() < 0.01 * b.predicted.abs(),
            "{what}: bias {} vs {}",
            b.measured,
            b.predicted
        );
        // About 166 °/s, within 1 %.
        let q = m.quadrature_dps;
        assert!(
            (q.measured - q.predicted).abs() < 0.01 * q.predicted.abs(),
            "{what}: quadrature {} vs {}",
            q.measured,
            q.predicted
        );
        // SPEC: settled well within the 150 ms of blanking after a switch; the rate within
        // 0.01 °/s about 100 ms after it (plus the CIC's delay).
        assert!(
            m.settling_ms.measured > 0.0 && m.settling_ms.measured < 100.0,
            "{what}: lock and amplitude after {} ms",
            m.settling_ms.measured
        );
        let r = m.rate_settling_ms;
        assert!(
            r.measured > 80.0 && r.measured < 150.0 && (r.measured - r.predicted).abs() < 15.0,
            "{what}: rate settled after {} ms, predicted {}",
            r.measured,
            r.predicted
        );
    }
    // Nothing saturated while the figures were measured; after a switch the formerly driven
    // axis's ring-down (about 2e4 °/s) pins the outputs for a few chain samples, nothing else.
    for m in [&c.normal, &c.reverse] {
        assert_eq!(m.saturations.summary(), "none", "{}", m.mode);
        let t = m.transient_saturations;
        let outputs = t.get(LoopNode::RateOutput) + t.get(LoopNode::QuadratureOutput);
        assert!(
            outputs > 0 && outputs < 20 && outputs == t.total(),
            "{}: {}",
            m.mode,
            t.summary()
        );
    }
    // (B − B′)/2 = −0.0094 °/s: the bias errors above would allow 0.4 °/s; the measured
    // residual is within 0.01 °/s.
    let r = c.residual_bias_dps;
    assert!(
        (r.measured - r.predicted).abs() < 0.01,
        "residual {} vs {}",
        r.measured,
        r.predicted
    );
}

/// Fixed and float loops closed around the same physics agree on every steady-state figure.
///
/// Tolerances: the quantization errors enter as mean phase offsets of about one ROM LSB
/// (2^−17 rad) or one ADC LSB over the 0.2 FS drive (6e-7 rad), and the frequency follows a
/// phase offset with `f/(2Q)` = 22 Hz/rad: 1 mHz allows 45 µrad. The amplitude is held at a
/// setpoint rounded to 2^−30 FS, the references' amplitude is within 2^−18 relative of the
/// float twin's: 1e-5 relative. The rate output rests on a 24-bit ADC whose LSB is 0.012 °/s
/// at the sense channel's 9.8e-6 FS per °/s, averaged over 8000 samples per mean for a
/// signal that is not locked to `fs`, and on an output LSB of 6e-5 °/s: 0.005 °/s for bias
/// and quadrature, 1e-4 (0.01 °/s at 100 °/s) for the scale factor. Settling agrees to one
/// chain sample (5 ms).
#[test]
fn fixed_and_float_loops_agree_in_steady_state() {
    let (spec, plan) = paper_004();
    let fixed = characterized::<FixedHarness>(&spec, &plan);
    let float = characterized::<FloatHarness>(&spec, &plan);
    for (x, y) in [
        (&fixed.normal, &float.normal),
        (&fixed.reverse, &float.reverse),
    ] {
        let what = x.mode;
        let close = |a: f64, b: f64, tolerance: f64, name: &str| {
            assert!(
                (a - b).abs() <= tolerance,
                "{what} {name}: fixed {a} float {b} (± {tolerance})"
            );
        };
        close(
            x.drive_frequency_hz.measured,
            y.drive_frequency_hz.measured,
            1e-3,
            "Hz",
        );
        close(
            x.drive_amplitude_m.measured / y.drive_amplitude_m.measured,
            1.0,
            1e-5,
            "amplitude",
        );
        close(x.scale_factor.measured, y.scale_factor.measured, 1e-4, "SF");
        close(x.bias_dps.measured, y.bias_dps.measured, 5e-3, "bias");
        close(
            x.quadrature_dps.measured,
            y.quadrature_dps.measured,
            5e-3,
            "quadrature",
        );
        close(
            x.settling_ms.measured,
            y.settling_ms.measured,
            5.0,
            "settling",
        );
        close(
            x.rate_settling_ms.measured,
            y.rate_settling_ms.measured,
            5.0,
            "rate settling",
        );
    }
}

/// A run with every noise source and drift on, a rate that changes every chain sample and
/// a mode switch: the same seed gives the same records bit for bit, another seed others.
#[test]
fn same_seed_same_outputs() {
    let (spec, plan) = paper_004();
    let go = |seed| {
        run::<FixedHarness>(
            &plan,
            &spec.resonator,
            &spec.front_end,
            seed,
            50,
            |n| 10.0 * libm::sin(n as f64 / 7.0),
            |n| if n < 30 { Mode::Normal } else { Mode::Reverse },
        )
        .unwrap()
    };
    let (a, b, c) = (go(7), go(7), go(8));
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert_eq!(a[29].mode, Mode::Normal);
    assert_eq!(a[30].mode, Mode::Reverse);
    // The lock goes at the switch and the noisy loop locks again within the run.
    assert!(a[29].output.locked && !a[30].output.locked);
    assert!(a[49].output.locked);
}

/// The solver: without coupling (`ε = θ = 0`) the coupled resonance is `sqrt(k_aa/m)`
/// exactly; paper 004's coupling moves it by a few mHz (SPEC §1.6), below in normal mode
/// and above in reverse (the coupled modes repel).
#[test]
fn coupled_resonance_is_a_few_mhz_from_the_uncoupled_one() {
    let mut p = crate::resonator::ResonatorParams::paper_004();
    let coupled = [Mode::Normal, Mode::Reverse].map(|m| coupled_resonance_hz(&p, m));
    assert!(
        (-0.005..-0.0001).contains(&(coupled[0] - 8195.0)),
        "{}",
        coupled[0]
    );
    assert!(
        (0.0001..0.005).contains(&(coupled[1] - 8142.0)),
        "{}",
        coupled[1]
    );
    p.stiffness_angle_deg = 0.0;
    p.damping_angle_deg = 0.0;
    for (m, f) in [(Mode::Normal, 8195.0), (Mode::Reverse, 8142.0)] {
        assert!((coupled_resonance_hz(&p, m) - f).abs() < 1e-9);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    /// Across structures (coupling angles, phase errors) and loop latencies, the fixed loop
    /// locks on the coupled resonance and its bias and scale factor follow the closed forms.
    #[test]
    fn fixed_loop_follows_the_closed_forms(
        stiffness_angle in 0.1f64..1.5,
        damping_angle in -3.0f64..3.0,
        phase in -3.0f64..3.0,
        phase_reverse in -3.0f64..3.0,
        latency in 0u32..=3,
    ) {
        let mut spec = Spec::paper_004();
        spec.resonator.stiffness_angle_deg = stiffness_angle;
        spec.resonator.damping_angle_deg = damping_angle;
        spec.resonator.phase_error_deg = phase;
        spec.resonator.phase_error_reverse_deg = phase_reverse;
        spec.settings.adc_to_dac_latency_samples = latency;
        let plan = Plan::new(&spec).unwrap();
        let c = characterized::<FixedHarness>(&spec, &plan);
        for m in [&c.normal, &c.reverse] {
            let f = m.drive_frequency_hz;
            prop_assert!((f.measured - f.predicted).abs() < 0.01, "{}: {:?}", m.mode, f);
            prop_assert!((m.scale_factor.measured - 1.0).abs() < 1e-3, "{}: {:?}", m.mode, m.scale_factor);
            // 1 % of the bias plus 3e-4 of the quadrature: the closed form is first order in
            // the coupling (it drives at sqrt(k_aa/m), where the loop drives at the coupled
            // resonance, and leaves out the sense motion's reaction on the drive), so where
            // the damping and leak terms nearly cancel what is left is a small fraction of
            // the quadrature (1.9e-4 seen at ε = 1.4°, φ′ = −2.9°).
            let b = m.bias_dps;
            let tolerance = 0.01 * b.predicted.abs() + 3e-4 * m.quadrature_dps.predicted.abs();
            prop_assert!(
                (b.measured - b.predicted).abs() < tolerance,
                "{}: {:?} (± {})", m.mode, b, tolerance
            );
            prop_assert!(m.settling_ms.measured < 150.0, "{}: {:?}", m.mode, m.settling_ms);
        }
    }
}

/// The fixed loop of `spec` closed around its noiseless resonator, run `chain_samples` chain
/// samples at zero rate in normal mode: the loop's counts and the last rate output (°/s).
fn run_counted(spec: &Spec, chain_samples: usize) -> (crate::gyro_loop::gyro::LoopOverflows, f64) {
    let plan = Plan::new(spec).unwrap();
    let mut closed =
        FixedClosedLoop::new(&plan, &spec.resonator, &spec.front_end.noiseless(), 0).unwrap();
    let mut rate = 0.0;
    for _ in 0..chain_samples {
        rate = closed.step_chain(0.0, Mode::Normal).output.rate_dps;
    }
    (closed.gyro.overflows(), rate)
}

/// A mode-split bias (about 14 300 °/s) beyond the ±512 °/s output format pins the rate
/// output, and every pinned sample is counted there.
#[test]
fn a_bias_beyond_the_output_range_is_counted_at_the_rate_output() {
    let mut spec = Spec::paper_004();
    spec.resonator.damping_angle_deg = 45.0;
    spec.resonator.q_sense = 40.0;
    let chain_samples = 100;
    let (counts, rate) = run_counted(&spec, chain_samples);
    assert!(rate < -511.9, "pinned at the format's minimum: {rate}");
    // Pinned from the first output on (the CIC's first outputs still rise).
    let pinned = counts.get(LoopNode::RateOutput);
    assert!(pinned > 90 && pinned <= chain_samples as u64, "{counts:?}");
    assert!(
        counts.summary().contains("rate_output "),
        "{}",
        counts.summary()
    );
}

/// A PLL pull range (0.2 mHz) narrower than the coupled resonance's offset from the nominal
/// frequency (0.9 mHz) drives the PLL integrator into its limit again and again (about one
/// sample in five from rest, one in ten once settled, as `gyrofx loop` counts them), though
/// every output stays in range.
#[test]
fn a_pull_range_narrower_than_the_resonance_offset_is_counted_at_the_pll_integrator() {
    let mut spec = Spec::paper_004();
    spec.settings.pll_pull_range_hz = 0.0002;
    let (counts, _) = run_counted(&spec, 100);
    assert!(
        counts.get(LoopNode::PllIntegrator) > 5_000,
        "{}",
        counts.summary()
    );
    assert_eq!(counts.get(LoopNode::RateOutput), 0);
}

/// The default loop saturates nothing from rest to lock and on.
#[test]
fn the_default_loop_saturates_nothing() {
    let (counts, _) = run_counted(&Spec::paper_004(), 100);
    assert_eq!(counts.summary(), "none");
}

/// A random structure for the realized-phase property: coupling angles, phase errors,
/// frequencies, Qs and the loop's latency (the output widened to s32.16 so that large
/// quadratures do not clip it).
pub(crate) fn structure(
    (stiffness_angle, damping_angle): (f64, f64),
    (phase, phase_reverse): (f64, f64),
    (drive_hz, split_hz): (f64, f64),
    (q_drive, q_sense): (f64, f64),
    latency: u32,
) -> Spec {
    let mut spec = Spec::paper_004();
    let r = &mut spec.resonator;
    r.stiffness_angle_deg = stiffness_angle;
    r.damping_angle_deg = damping_angle;
    r.phase_error_deg = phase;
    r.phase_error_reverse_deg = phase_reverse;
    r.drive_frequency_hz = drive_hz;
    r.sense_frequency_hz = drive_hz - split_hz;
    r.q_drive = q_drive;
    r.q_sense = q_sense;
    spec.settings.adc_to_dac_latency_samples = latency;
    spec.settings.output_format = "s32.16".into();
    spec
}

/// Random structures for the properties of issue 32: coupling angles 0.05–2.5° (stiffness)
/// and ±5° (damping), phase errors ±3°, drive frequencies 6–12 kHz with splits of 20–100 Hz,
/// Qs 100–400 and latencies 0–3.
pub(crate) fn structures() -> impl Strategy<Value = Spec> {
    (
        (0.05f64..2.5, -5.0f64..5.0),
        (-3.0f64..3.0, -3.0f64..3.0),
        (6000.0f64..12000.0, 20.0f64..100.0),
        (100.0f64..400.0, 100.0f64..400.0),
        0u32..=3,
    )
        .prop_map(|(angles, phases, frequencies, qs, latency)| {
            structure(angles, phases, frequencies, qs, latency)
        })
}

/// How far a loop's residual is from the one predicted with the realized phases, as a
/// fraction of what issue 32 allows (5 % of the residual or 2 mdps, whichever is larger) plus
/// `phase_allowance_deg` of each mode's quadrature.
fn residual_gap(c: &Characterization, phase_allowance_deg: f64) -> f64 {
    let r = c.residual_bias_dps;
    let quadrature =
        (c.normal.quadrature_dps.measured.abs() + c.reverse.quadrature_dps.measured.abs()) / 2.0;
    let allowance = quadrature * phase_allowance_deg.to_radians();
    (r.measured - r.predicted).abs() / ((0.05 * r.measured.abs()).max(0.002) + allowance)
}

/// What the NCO's phase truncation, which the derivation leaves out, may move the fixed
/// loop's realized phase by, deg: 0.3 of a bin of the `A + 2`-bit phase. Where
/// `2^(A+2) f_L / fs` falls near a fraction of small denominator, the truncation errors stop
/// averaging out (0.29 bin, 0.0255°, seen at `2^12 f_L/fs` = 0.49997 mod 1).
fn truncation_allowance_deg(plan: &Plan) -> f64 {
    0.3 * 360.0 / crate::fx::pow2(plan.nco.address_bits as i32 + 2)
}

/// Cases of the realized-phase property: 24, or `GYROFX_REALIZED_PHASE_CASES` for the offline
/// sweep (`GYROFX_REALIZED_PHASE_CASES=400 cargo test --release -p gyrofx-model --lib
/// the_residual_follows`, 47 s; 400 passed on 2026-11-29).
fn realized_phase_cases() -> u32 {
    std::env::var("GYROFX_REALIZED_PHASE_CASES")
        .ok()
        .and_then(|cases| cases.parse().ok())
        .unwrap_or(24)
}

proptest! {
    // A fixed seed: with plain truncation (`nco_error_feedback` off, half the cases) the fixed
    // loop misses on about 1 structure in 200, where `2^(A+2) f_L/fs` sits near a small
    // fraction and the truncation errors stop averaging out (the DAC NCO's moves the locked
    // frequency, so the sense gain, by up to 3e-4; the references' move the phase by up to
    // 0.3 bin). A random seed would fail now and then for that known reason. With error
    // feedback 500 random structures of another seed passed the bare criterion.
    #![proptest_config(ProptestConfig {
        cases: realized_phase_cases(),
        rng_seed: proptest::test_runner::RngSeed::Fixed(32),
        ..ProptestConfig::default()
    })]

    /// Issue 32: over random structures, latencies, with or without `phase_trim` and NCO error
    /// feedback, the residual after reversal is the one predicted with the phases the loop
    /// realizes (the configured phases miss by 30 % at the defaults). The float twin, which has
    /// the fixed loop's design but no truncation, and the fixed loop with error feedback hold
    /// the 5 % or 2 mdps and each mode's phase within 5e-4°; with plain truncation the
    /// fixed loop is allowed [`truncation_allowance_deg`] of phase more.
    #[test]
    fn the_residual_follows_the_realized_phase(
        structure in structures(),
        phase_trim in any::<bool>(),
        nco_error_feedback in any::<bool>(),
    ) {
        let mut spec = structure;
        spec.settings.phase_trim = phase_trim;
        spec.settings.nco_error_feedback = nco_error_feedback;
        let plan = Plan::new(&spec).unwrap();
        let truncation = if nco_error_feedback { 0.0 } else { truncation_allowance_deg(&plan) };
        // The default second after a switch: some structures in this range have a
        // closed-loop pole of ~45 ms (ε 2.2°, split 20 Hz, Q 364 / 100).
        let procedure = Procedure::default();
        let [fixed, float] = [true, false].map(|fixed| {
            let (r, f) = (&spec.resonator, &spec.front_end);
            if fixed {
                characterize::<FixedHarness>(&plan, r, f, &procedure).unwrap()
            } else {
                characterize::<FloatHarness>(&plan, r, f, &procedure).unwrap()
            }
        });
        for (c, allowance) in [(&fixed, truncation), (&float, 0.0)] {
            prop_assert!(residual_gap(c, allowance) <= 1.0, "{:?} (phase allowance {allowance}°)", c.residual_bias_dps);
            for m in [&c.normal, &c.reverse] {
                prop_assert_eq!(m.saturations.total(), 0);
                // Where the coupling is weak the reading itself is uncertain: a bias of
                // 0.5 mdps is a phase of 0.5 mdps / Q rad.
                let reading = (5e-4 / m.quadrature_dps.measured.abs()).to_degrees();
                let bound = 5e-4 + allowance + reading;
                let phase = m.reference_phase_deg;
                prop_assert!(
                    (phase.measured - phase.predicted).abs() <= bound,
                    "{}: {:?} (configured {}, ± {bound})", m.mode, phase, m.configured_phase_deg
                );
            }
        }
    }
}

/// `[loop] phase_trim` (issue 32) on issue 32's second structure, where the loop realizes
/// 2.97968° / 3.02129° of a configured 3°: trimmed, the float twin realizes 3° within 1e-4°
/// and the fixed loop within 0.3 bin, the residual is the configured-phase
/// closed form's up to the sense gains, and only the sense offsets of the plan change.
#[test]
fn the_phase_trim_realizes_the_configured_phase() {
    let mut spec = structure((2.0, 0.5), (3.0, 3.0), (8195.0, 53.0), (184.0, 195.0), 1);
    spec.settings.phase_trim = false;
    let untrimmed = Plan::new(&spec).unwrap();
    spec.settings.phase_trim = true;
    let plan = Plan::new(&spec).unwrap();
    for mode in [Mode::Normal, Mode::Reverse] {
        let (m, u) = (plan.mode(mode), untrimmed.mode(mode));
        assert_ne!(m.sense_offset_word, u.sense_offset_word);
        let trim = m.sense_offset - u.sense_offset;
        assert!(
            (m.sense_offset_trim - trim).abs() < 1e-15 && trim.abs() > 1e-5,
            "{trim}"
        );
        let strip = |p: &ModePlan| ModePlan {
            sense_offset: 0.0,
            sense_offset_word: 0,
            sense_offset_trim: 0.0,
            ..*p
        };
        assert_eq!(strip(m), strip(u));
    }
    let float = characterized::<FloatHarness>(&spec, &plan);
    let fixed = characterized::<FixedHarness>(&spec, &plan);
    let untrimmed_float = characterized::<FloatHarness>(&spec, &untrimmed);
    for (c, bound) in [(&float, 1e-4), (&fixed, truncation_allowance_deg(&plan))] {
        for m in [&c.normal, &c.reverse] {
            let phase = m.reference_phase_deg.measured;
            assert!((phase - 3.0).abs() < bound, "{}: {phase}", m.mode);
        }
    }
    for m in [&untrimmed_float.normal, &untrimmed_float.reverse] {
        let phase = m.reference_phase_deg.measured;
        assert!((phase - 3.0).abs() > 0.015, "{}: {phase}", m.mode);
    }
    let residual = float.residual_bias_dps;
    assert!(residual_gap(&float, 0.0) <= 0.2, "{residual:?}");
    assert!(
        (residual.measured / float.residual_configured_phase_dps - 1.0).abs() < 0.01,
        "{residual:?} against {}",
        float.residual_configured_phase_dps
    );
}

/// Two structures whose locked frequency puts `2^12 f_L/fs` near a small fraction (0.49997 and
/// 0.99958 mod 1 in reverse mode), where the plain truncation moves the fixed loop's phase by
/// 0.026° and its gain by 3e-4 (a phase off by 0.026°, a residual off by 76 mdps on 41):
/// `nco_error_feedback` (the default) brings both within the 5 % or 2 mdps of the
/// prediction, and each phase within 2e-3° of it.
#[test]
fn nco_error_feedback_takes_the_truncations_static_error_away() {
    let structures = [
        structure(
            (0.05, 0.0),
            (0.0, 0.0),
            (10593.638240397779, 22.350705291363926),
            (100.0, 100.0),
            0,
        ),
        structure(
            (0.05, 4.40813367455242),
            (0.0, 0.0),
            (9837.512429938424, 71.90772520106682),
            (167.7771012092544, 100.0),
            0,
        ),
    ];
    let procedure = Procedure::default();
    for mut spec in structures {
        spec.settings.nco_error_feedback = false;
        let run = |spec: &Spec| {
            let plan = Plan::new(spec).unwrap();
            characterize::<FixedHarness>(&plan, &spec.resonator, &spec.front_end, &procedure)
                .unwrap()
        };
        let phase_gap = |c: &Characterization| {
            [&c.normal, &c.reverse]
                .map(|m| (m.reference_phase_deg.measured - m.reference_phase_deg.predicted).abs())
                .into_iter()
                .fold(0.0, f64::max)
        };
        let plain = run(&spec);
        assert!(
            residual_gap(&plain, 0.0) > 1.0 || phase_gap(&plain) > 0.01,
            "{:?}, phase {}",
            plain.residual_bias_dps,
            phase_gap(&plain)
        );
        spec.settings.nco_error_feedback = true;
        let fed_back = run(&spec);
        assert!(
            residual_gap(&fed_back, 0.0) <= 1.0,
            "{:?}",
            fed_back.residual_bias_dps
        );
        assert!(phase_gap(&fed_back) < 2e-3, "{}", phase_gap(&fed_back));
    }
}
