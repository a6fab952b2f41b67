//! The folded loop against the parallel model: the same DAC codes, lock flags and chain
//! outputs, sample for sample.

use super::*;
use crate::gyro_loop::closed::record;
use crate::gyro_loop::gyro::LoopSettings;
use crate::gyro_loop::gyro::{FixedGyroLoop, Spec};
use crate::resonator::Mode;
use proptest::prelude::*;

/// Runs `inputs` through both loops and returns the first sample where they differ.
fn first_difference(plan: &Plan, inputs: &[([i64; 2], Mode)]) -> Option<(usize, String)> {
    let mut parallel = FixedGyroLoop::new(plan);
    let mut folded = FoldedGyroLoop::new(plan);
    for (k, &(adc, mode)) in inputs.iter().enumerate() {
        let want = parallel.step(adc, mode);
        let got = folded.step(adc, mode);
        if want != got || parallel.locked() != folded.locked() {
            return Some((k, format!("parallel {want:?}, folded {got:?}")));
        }
    }
    None
}

/// The default plan and the ADC codes and modes of its closed loop at 10 °/s from reset,
/// `samples` long with the switch to reverse mode half way; whether the loop locked.
fn default_closed_loop(samples: usize) -> (Plan, Vec<([i64; 2], Mode)>, bool) {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    let run = record(
        &plan,
        &spec.resonator,
        &spec.front_end,
        7,
        10.0,
        samples,
        samples / 2,
    );
    let run = run.unwrap();
    let locked = run.iter().any(|s| s.locked);
    (plan, run.iter().map(|s| (s.adc, s.mode)).collect(), locked)
}

#[test]
fn the_default_loop_folds_bit_for_bit_through_lock_and_a_switch() {
    let (plan, inputs, locked) = default_closed_loop(40_000);
    assert!(locked, "the recording never locks");
    assert_eq!(first_difference(&plan, &inputs), None);
}

#[test]
fn the_default_schedule_fits_a_sample_at_24_mhz() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let schedule = Schedule::new(&plan).unwrap();
    println!("{schedule}");
    assert!(schedule.len() < 120, "{schedule}");
}

#[test]
fn a_schedule_missing_one_write_is_caught() {
    let (plan, inputs, _) = default_closed_loop(4_000);
    let schedule = Schedule::new(&plan).unwrap();
    // Drop the PLL integrator's write-back: the loop then never integrates its phase error.
    let mut broken = schedule.clone();
    let pll_word = schedule.words.pll;
    let clock = broken
        .controls
        .iter()
        .position(|c| c.write.is_some_and(|w| w.address == pll_word))
        .unwrap();
    broken.controls[clock].write = None;
    let mut parallel = FixedGyroLoop::new(&plan);
    let mut folded = FoldedGyroLoop::with_schedule(&plan, broken);
    let differs = inputs
        .iter()
        .any(|&(adc, mode)| parallel.step(adc, mode) != folded.step(adc, mode));
    assert!(
        differs,
        "a folded loop without the PLL's integrator matched"
    );
}

/// Formats and settings the folded loop must hold for: widths from narrow to 64 bits, every
/// rounding and overflow mode, latencies 0–8, 1–4 CIC stages, 1–7 taps, short decimations.
fn settings() -> impl Strategy<Value = LoopSettings> {
    let pick = |options: &'static [&'static str]| proptest::sample::select(options);
    let pick_n = |options: &'static [u32]| proptest::sample::select(options);
    (
        (
            pick(&["s24.23"]),
            pick(&["s24.22", "s32.30", "s36.34"]),
            pick(&["s44.42", "s56.54", "s64.62"]),
            pick(&["s24.22", "s32.30", "s40.38"]),
            4u32..=12,
        ),
        (
            pick(&["s40.38", "s48.46"]),
            pick_n(&[12u32, 18, 25]),
            pick(&["s40.20", "s48.24"]),
            pick(&["s24.6", "s20.4"]),
            pick_n(&[12u32, 18, 25]),
            pick(&["s18.0", "s16.0"]),
        ),
        (
            1u32..=4,
            pick_n(&[1u32, 3, 5, 7]),
            pick_n(&[12u32, 18, 24]),
            pick(&["s40.38", "s28.27"]),
            pick(&["s32.30", "s24.22"]),
            pick_n(&[16u32, 24, 31]),
            pick(&["s24.14", "s32.16", "s16.8"]),
            2u32..=30,
        ),
        (
            0u32..=8,
            4u32..=12,
            pick_n(&[24u32, 32, 40]),
            pick_n(&[8u32, 10, 12]),
            pick_n(&[16u32, 18, 24]),
            any::<bool>(),
            pick(&["floor", "ceil", "zero", "nearest", "round", "convergent"]),
            pick(&["wrap", "saturate"]),
        ),
    )
        .prop_map(|(demod, pi, cic, rest)| {
            let s = |text: &str| text.to_string();
            let mut l = LoopSettings::default();
            (l.adc_format, l.demod_product_format, l.demod_state_format) =
                (s(demod.0), s(demod.1), s(demod.2));
            (l.demod_output_format, l.demod_lowpass_shift) = (s(demod.3), demod.4);
            (l.pll_integrator_format, l.pll_gain_width) = (s(pi.0), pi.1);
            (l.agc_integrator_format, l.agc_output_format) = (s(pi.2), s(pi.3));
            (l.agc_gain_width, l.dac_format) = (pi.4, s(pi.5));
            (l.cic_stages, l.cic_taps, l.cic_tap_width) = (cic.0, cic.1, cic.2);
            (l.cic_internal_format, l.cic_output_format) = (s(cic.3), s(cic.4));
            (l.scale_coefficient_width, l.output_format) = (cic.5, s(cic.6));
            l.decimation = cic.7;
            (l.adc_to_dac_latency_samples, l.lock_filter_shift) = (rest.0, rest.1);
            (l.nco_phase_bits, l.nco_address_bits, l.nco_sine_width) = (rest.2, rest.3, rest.4);
            l.nco_error_feedback = rest.5;
            (l.rounding, l.overflow) = (s(rest.6), s(rest.7));
            l.lock_hold_ms = 0.05;
            l
        })
}

/// Cases of the random-format property: 64, or `GYROFX_FOLDED_CASES` for the offline sweep
/// (`GYROFX_FOLDED_CASES=2000 cargo test --release -p gyrofx-model --lib
/// the_folded_loop_matches`).
fn folded_cases() -> u32 {
    std::env::var("GYROFX_FOLDED_CASES")
        .ok()
        .and_then(|cases| cases.parse().ok())
        .unwrap_or(64)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: folded_cases(),
        max_global_rejects: 100_000,
        ..ProptestConfig::default()
    })]

    /// Over random formats and settings, random ADC codes (full scale: every point saturates
    /// or wraps now and then) and random mode switches, the folded loop gives the parallel
    /// model's DAC codes, lock flags and chain outputs.
    #[test]
    fn the_folded_loop_matches_the_parallel_one_over_random_formats(
        settings in settings(),
        codes in proptest::collection::vec((any::<i64>(), any::<i64>(), 0u8..40), 400),
    ) {
        let mut spec = Spec::paper_004();
        spec.settings = settings;
        let plan = Plan::new(&spec);
        prop_assume!(plan.is_ok());
        let plan = plan.unwrap();
        let width = plan.demodulator.input.width;
        let mut mode = Mode::Normal;
        let inputs: Vec<_> = codes
            .iter()
            .map(|&(x, y, switch)| {
                if switch == 0 {
                    mode = if mode == Mode::Normal { Mode::Reverse } else { Mode::Normal };
                }
                ([sign_extend(i128::from(x), width) as i64, sign_extend(i128::from(y), width) as i64], mode)
            })
            .collect();
        let difference = first_difference(&plan, &inputs);
        prop_assert!(difference.is_none(), "{:?} with {}", difference, Schedule::new(&plan).unwrap());
    }

    /// Over random formats and settings and two random input streams, the folded pair gives
    /// each gyro's parallel DAC codes and lock flags in every sample and its chain outputs
    /// `output_delay` samples after they decimate.
    #[test]
    fn the_folded_pair_matches_two_parallel_loops_over_random_formats(
        settings in settings(),
        codes in proptest::collection::vec(
            ((any::<i64>(), any::<i64>(), 0u8..40), (any::<i64>(), any::<i64>(), 0u8..40)),
            400,
        ),
    ) {
        let mut spec = Spec::paper_004();
        spec.settings = settings;
        let plan = Plan::new(&spec);
        prop_assume!(plan.is_ok());
        let plan = plan.unwrap();
        let schedule = Schedule::pair(&plan);
        prop_assume!(schedule.is_ok());
        let schedule = schedule.unwrap();
        let hazard = error_read_after_its_write(&schedule);
        prop_assert!(hazard.is_none(), "{:?} in {}", hazard, schedule);
        let width = plan.demodulator.input.width;
        let code = |x: i64| sign_extend(i128::from(x), width) as i64;
        let mut modes = [Mode::Normal; 2];
        let inputs: Vec<_> = codes
            .iter()
            .map(|&(a, b)| {
                let mut adc = [[0; 2]; 2];
                for (g, (x, y, switch)) in [a, b].into_iter().enumerate() {
                    if switch == 0 {
                        modes[g] = if modes[g] == Mode::Normal { Mode::Reverse } else { Mode::Normal };
                    }
                    adc[g] = [code(x), code(y)];
                }
                (adc, modes)
            })
            .collect();
        let difference = first_pair_difference([&plan, &plan], &inputs);
        prop_assert!(difference.is_none(), "{:?} with {}", difference, Schedule::pair(&plan).unwrap());
    }
}

/// Runs `inputs` (both gyros' codes and modes) through the pair and two parallel loops and
/// returns the first sample where they differ.
fn first_pair_difference(
    plans: [&Plan; 2],
    inputs: &[([[i64; 2]; 2], [Mode; 2])],
) -> Option<(usize, String)> {
    let mut parallel = plans.map(FixedGyroLoop::new);
    let mut pair = FoldedPair::new(plans);
    let delay = pair.output_delay();
    let mut expected = std::collections::VecDeque::new();
    for (k, &(adc, modes)) in inputs.iter().enumerate() {
        let want = [0, 1].map(|g| parallel[g].step(adc[g], modes[g]));
        let got = pair.step(adc, modes);
        let dac = want.map(|w| w.dac);
        let locked = [parallel[0].locked(), parallel[1].locked()];
        if got.dac != dac || got.locked != locked || got.decimating != want[0].chain.is_some() {
            return Some((k, format!("parallel {want:?} {locked:?}, pair {got:?}")));
        }
        if let (Some(a), Some(b)) = (want[0].chain, want[1].chain) {
            expected.push_back((k + delay, [a, b]));
        }
        let due = expected.front().filter(|(at, _)| *at == k).map(|(_, c)| *c);
        if due.is_some() {
            expected.pop_front();
        }
        if got.chain != due {
            return Some((k, format!("chain: expected {due:?}, pair {:?}", got.chain)));
        }
    }
    None
}

/// The default plan's pair, through two closed-loop recordings (different seeds, one gyro's
/// switch at a third, the other's at two thirds): every DAC code, lock flag and chain output.
#[test]
fn the_default_pair_folds_both_loops_bit_for_bit_through_lock_and_switches() {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    let samples = 40_000;
    let run = |seed, switch| {
        record(
            &plan,
            &spec.resonator,
            &spec.front_end,
            seed,
            10.0,
            samples,
            switch,
        )
        .unwrap()
    };
    let (a, b) = (run(7, samples / 3), run(8, 2 * samples / 3));
    assert!(a.iter().any(|s| s.locked) && b.iter().any(|s| s.locked));
    let inputs: Vec<_> = a
        .iter()
        .zip(&b)
        .map(|(a, b)| ([a.adc, b.adc], [a.mode, b.mode]))
        .collect();
    assert_eq!(first_pair_difference([&plan, &plan], &inputs), None);
}

/// Where `schedule` reads an NCO reference's truncation error in the clock right after a
/// cosine wrote it (`gyrofx_gyro_pair_serial` keeps the errors in a block RAM whose read that
/// clock would return the old word): the clock and the two reads. Runs checked: the regular
/// part, and the regular part followed by each deferred segment.
fn error_read_after_its_write(schedule: &Schedule) -> Option<String> {
    let reference = |c: &Control| -> Option<(u8, u8)> {
        match c.rom {
            RomRead::None => None,
            RomRead::DriveSin | RomRead::DriveCos => Some((c.rom_gyro, 0)),
            RomRead::TransmitCos => Some((c.rom_gyro, 1)),
            RomRead::SenseSin | RomRead::SenseCos => Some((c.rom_gyro, 2)),
        }
    };
    let writes = |c: &Control| {
        matches!(
            c.rom,
            RomRead::DriveCos | RomRead::TransmitCos | RomRead::SenseCos
        )
    };
    let regular = &schedule.controls[..schedule.regular];
    let runs = std::iter::once(regular.to_vec()).chain(
        schedule
            .segments()
            .map(|segment| [regular, segment].concat()),
    );
    for run in runs {
        for (t, pair) in run.windows(2).enumerate() {
            if writes(&pair[0]) && reference(&pair[1]) == reference(&pair[0]) {
                return Some(format!(
                    "clock {t}: {:?} of gyro {}, then {:?}",
                    pair[0].rom, pair[0].rom_gyro, pair[1].rom
                ));
            }
        }
    }
    None
}

/// A cosine's write of its truncation error and the next read of that error are never in
/// adjacent clocks in the default pair; a schedule where they are is caught.
#[test]
fn the_pair_never_reads_a_truncation_error_the_clock_after_writing_it() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let mut schedule = Schedule::pair(&plan).unwrap();
    assert_eq!(error_read_after_its_write(&schedule), None, "{schedule}");
    let cosine = schedule.controls[..schedule.regular]
        .iter()
        .position(|c| c.rom == RomRead::TransmitCos)
        .expect("a transmit cosine");
    schedule.controls[cosine + 1].rom = RomRead::TransmitCos;
    schedule.controls[cosine + 1].rom_gyro = schedule.controls[cosine].rom_gyro;
    assert!(error_read_after_its_write(&schedule).is_some());
}

/// The default pair's schedule: every sample within the 120 clocks of a 200 kHz ADC at
/// 24 MHz (two of them the fetch and decode), its deferred work well inside a decimation.
#[test]
fn the_default_pair_fits_a_sample_at_24_mhz() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let schedule = Schedule::pair(&plan).unwrap();
    println!("{schedule}");
    assert!(schedule.len() <= PAIR_SAMPLE_WORDS, "{schedule}");
    assert!(
        schedule.deferred.len() < plan.cic.decimation as usize / 10,
        "{schedule}"
    );
}

/// The fields fill the 64-bit word, and a word's bits are its fields at their offsets (the
/// RTL's slices of them: `tests/loop_blocks.rs`).
#[test]
fn a_control_word_packs_its_fields_at_their_offsets() {
    assert_eq!(FIELDS.iter().map(|(_, w)| w).sum::<u32>(), CONTROL_BITS);
    let control = Control {
        write: Some(Write {
            address: 5,
            data: WriteData::Cic,
            decimating: true,
        }),
        quantize: Quantize::LockA,
        quantize_gyro: 1,
        ..Control::default()
    };
    assert_eq!(
        control.encode(),
        1 << 42 | 5 << 43 | 5 << 50 | 15 << 53 | 1 << 62 | 1 << 63
    );
}

/// The schedule ROM's layout: the regular part, then each segment at
/// `regular + k·(len − regular)` (the RTL's addresses); one gyro's ROM is its controls.
#[test]
fn the_rom_holds_the_regular_part_then_each_segment_at_its_base() {
    let plan = Plan::new(&Spec::paper_004()).unwrap();
    let one = Schedule::new(&plan).unwrap();
    assert_eq!(one.rom_words(), one.controls);
    let pair = Schedule::pair(&plan).unwrap();
    let words = pair.rom_words();
    let segment = pair.len() - pair.regular;
    assert_eq!(words.len(), pair.regular + pair.deferred.len() * segment);
    assert_eq!(words[..pair.regular], pair.controls[..]);
    for (k, d) in pair.deferred.iter().enumerate() {
        let base = pair.regular + k * segment;
        assert_eq!(words[base..base + d.len()], d[..], "segment {k}");
        assert!(words[base + d.len()..base + segment]
            .iter()
            .all(|w| *w == Control::default()));
    }
}
