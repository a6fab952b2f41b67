//! The system's wiring: which mode each period is taken in, and that it computes what the
//! chain run over the two closed loops computes.

use super::*;
use crate::examples::chain_plan;
use crate::fx::Rounding;
use crate::gyro_loop::gyro::Spec;
use crate::sequencer::Sequencer;

/// Gyro A is paper 004's; gyro B has another anisoelasticity angle and damping, so the two
/// loops differ.
fn plans() -> ([LoopPlan; 2], [ResonatorParams; 2], PhysicsSettings) {
    let a = Spec::paper_004();
    let mut b = Spec::paper_004();
    b.resonator.stiffness_angle_deg += 2.0;
    b.resonator.q_sense *= 0.9;
    let physics = a.front_end;
    (
        [LoopPlan::new(&a).unwrap(), LoopPlan::new(&b).unwrap()],
        [a.resonator, b.resonator],
        physics,
    )
}

const STARTUP_PERIODS: usize = 3;
const PERIODS: usize = STARTUP_PERIODS + 2 * 4 * 3;

fn run(chain: &ChainPlan) -> Vec<RecordedSample> {
    let (loops, params, physics) = plans();
    let decimation = loops[0].cic.decimation as usize;
    let mut out = Vec::new();
    record(
        [&loops[0], &loops[1]],
        chain,
        [0, 1].map(|g| GyroPhysics {
            params: &params[g],
            front_end: &physics,
            seed: 7 + g as u64,
        }),
        10.0,
        PERIODS * decimation,
        STARTUP_PERIODS * decimation,
        |_| 1,
        |s| out.push(*s),
    )
    .unwrap();
    out
}

/// Every ADC sample of a chain period is taken in the mode the sequencer gives that chain
/// sample; while `enable` is low both loops run in normal mode and the chain does not step.
#[test]
fn every_period_is_taken_in_the_mode_of_its_chain_sample() {
    let chain = chain_plan(3, 1, 1, 0, Rounding::Nearest);
    let samples = run(&chain);
    let mut period_modes: Vec<[Mode; 2]> = Vec::new();
    let mut chain_samples = 0;
    let mut previous_upcoming = [Mode::Normal; 2];
    for s in &samples {
        period_modes.push(s.step.modes);
        if !s.enable {
            assert_eq!(s.step.modes, [Mode::Normal; 2]);
            assert!(s.step.chain.is_none());
        } else {
            assert_eq!(
                s.step.modes, previous_upcoming,
                "the loops take the chain's modes"
            );
        }
        previous_upcoming = s.upcoming;
        if s.step.rates.is_some() {
            if let Some(c) = s.step.chain {
                chain_samples += 1;
                let slot = [loop_mode(c.slot.mode_a), loop_mode(c.slot.mode_b)];
                assert!(
                    period_modes.iter().all(|m| *m == slot),
                    "chain sample {chain_samples}: {slot:?}"
                );
            }
            period_modes.clear();
        }
    }
    assert_eq!(chain_samples, PERIODS - STARTUP_PERIODS);
    // Both gyros went through both modes (B a sample behind A).
    let modes: Vec<[Mode; 2]> = samples.iter().map(|s| s.step.modes).collect();
    for g in 0..2 {
        assert!(modes.iter().any(|m| m[g] == Mode::Reverse), "gyro {g}");
    }
}

/// The system computes what `generate`'s chain run computes from the two closed loops whose
/// modes follow the sequencer's schedule: the same loop outputs and the same chain outputs.
#[test]
fn the_system_is_the_chain_over_the_two_closed_loops() {
    let chain = chain_plan(3, 1, 0, 1, Rounding::Convergent);
    let samples = run(&chain);
    let (loops, params, physics) = plans();
    let decimation = loops[0].cic.decimation as usize;
    // The schedule alone, as the chain run takes it.
    let mut sequencer = Sequencer::new(&chain.estimator.schedule);
    let schedule: Vec<[i8; 2]> = (0..PERIODS - STARTUP_PERIODS)
        .map(|_| {
            let slot = sequencer.advance();
            [slot.mode_a, slot.mode_b]
        })
        .collect();
    let mut rates: Vec<[i64; 2]> = vec![[0; 2]; schedule.len()];
    for g in 0..2 {
        let mut resonator = Resonator::new(&params[g], &physics, 7 + g as u64).unwrap();
        resonator.set_rate(10f64.to_radians());
        let mut gyro = FixedGyroLoop::new(&loops[g]);
        let mut adc = [0i64; 2];
        let mut mode = Mode::Normal;
        let mut n = 0;
        for k in 0..PERIODS * decimation {
            let period = k / decimation;
            let want = if period < STARTUP_PERIODS {
                Mode::Normal
            } else {
                loop_mode(schedule[period - STARTUP_PERIODS][g])
            };
            if want != mode {
                mode = want;
                resonator.set_mode(mode);
            }
            let step = gyro.step(adc, mode);
            if let Some(c) = step.chain {
                if period >= STARTUP_PERIODS {
                    rates[n][g] = c.rate;
                    n += 1;
                }
            }
            adc = resonator.step_codes(step.dac);
        }
    }
    let mut reference = FixedChain::new(&chain);
    let expected: Vec<ChainSample> = rates.iter().map(|y| reference.step(*y, 1)).collect();
    let got: Vec<ChainSample> = samples.iter().filter_map(|s| s.step.chain).collect();
    assert_eq!(got, expected);
    assert!(got.iter().any(|c| c.rate.is_some()));
}

/// The float twin fed the fixed system's ADC record takes the same modes at every sample and
/// steps the chain at the same samples. Its loops' rates follow the fixed ones within 0.01 °/s
/// (the loop's settling criterion) plus 10⁻⁴ of the rate (the re-acquisition after a switch,
/// where the two PLLs' phase errors differ by the fixed one's quantization) wherever the fixed
/// rate is not saturated, and its chain output within the same until the first saturated loop
/// rate (which the chain then carries in its state; this short schedule blanks too little).
#[test]
fn the_float_twin_follows_the_fixed_system_on_its_record() {
    let chain = chain_plan(3, 1, 1, 0, Rounding::Nearest);
    let samples = run(&chain);
    let (loops, _, _) = plans();
    let mut twin = FloatSystem::new([&loops[0], &loops[1]], &chain);
    let adc = loops[0].adc;
    let output = chain.kf.output;
    let close = |fixed: f64, float: f64| (fixed - float).abs() < 0.01 + 1e-4 * fixed.abs();
    let unsaturated =
        |code: i64| i128::from(code) > output.min_code() && i128::from(code) < output.max_code();
    let (mut loop_rates, mut chain_rates, mut saturated) = (0, 0, false);
    for (k, s) in samples.iter().enumerate() {
        let real = s.adc.map(|g| g.map(|c| adc.to_f64(i128::from(c))));
        let t = twin.step(real, s.enable, 1);
        assert_eq!(t.modes, s.step.modes, "sample {k}");
        assert_eq!(t.rates.is_some(), s.step.rates.is_some(), "sample {k}");
        assert_eq!(t.chain.is_some(), s.step.chain.is_some(), "sample {k}");
        if let (Some(fixed), Some(float)) = (s.step.rates, t.rates) {
            for g in 0..2 {
                if unsaturated(fixed[g]) {
                    let fixed_dps = output.to_f64(i128::from(fixed[g]));
                    assert!(
                        close(fixed_dps, float[g]),
                        "sample {k} gyro {g}: {fixed_dps} {}",
                        float[g]
                    );
                    loop_rates += 1;
                } else {
                    saturated = true;
                }
            }
        }
        if let (Some(fixed), Some(float), false) = (s.step.chain, t.chain, saturated) {
            assert_eq!(fixed.rate.is_some(), float.rate.is_some(), "sample {k}");
            if let (Some(code), Some(rate)) = (fixed.rate, float.rate) {
                let fixed_dps = output.to_f64(i128::from(code));
                assert!(close(fixed_dps, rate), "sample {k}: {fixed_dps} {rate}");
                chain_rates += 1;
            }
        }
    }
    assert!(
        loop_rates >= 10 && chain_rates >= 3,
        "{loop_rates} {chain_rates}"
    );
}
