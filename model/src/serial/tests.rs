use proptest::prelude::*;

use super::*;
use crate::chain::{self, FixedChain};
use crate::estimator;
use crate::fx::{CoefficientFormat, Format, Overflow, Rounding};
use crate::kf;
use crate::sequencer::{Pattern, Schedule};

/// Small deterministic generator (xorshift), so a failing case replays.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A code of `format`: mostly moderate, sometimes near full scale (to saturate).
    fn code(&mut self, format: Format, rate: i64) -> i64 {
        let r = self.next();
        let full = (1i64 << (format.width - 1)) - 1;
        match r % 16 {
            0 => full,
            1 => -full - 1,
            2..=4 => ((r >> 8) as i64 % (full + 1)) * if r & 0x10 != 0 { 1 } else { -1 },
            _ => (rate + ((r >> 8) % 2001) as i64 - 1000).clamp(-full - 1, full),
        }
    }
}

/// Runs the fixed chain and the engine side by side; returns the samples compared.
fn agree(plan: &chain::Plan, samples: usize, seed: u64, resets: &[usize]) -> usize {
    let program = compile(plan).expect("compiles");
    let mut engine = Engine::new(&program);
    let mut chain = FixedChain::new(plan);
    let mut sequencer = crate::sequencer::Sequencer::new(&plan.estimator.schedule);
    let mut noise = Noise(seed | 1);
    let input = plan.estimator.input;
    let rate = 1i64 << (input.frac + 2).min(input.width as i32 - 3);
    let selects = plan.kf.rom.len();
    for k in 0..samples {
        if resets.contains(&k) {
            chain.reset();
            engine.reset();
            sequencer.reset();
        }
        let y = [noise.code(input, rate), noise.code(input, -rate)];
        let bw_sel = (noise.next() % selects as u64) as usize;
        let slot = sequencer.advance();
        let expected = chain.step(y, bw_sel);
        assert_eq!(slot, expected.slot);
        let actual = engine.step(y, bw_sel, &slot);
        let bias = chain.estimator().bias().map(|b| b as i64);
        assert_eq!(
            (actual.rate, actual.bias, actual.estimated),
            (expected.rate, bias, chain.estimator().estimated()),
            "sample {k} (y {y:?}, bw_sel {bw_sel}, slot {slot:?})"
        );
    }
    samples
}

fn plan(
    interval_length: usize,
    formats: [&str; 6],
    smoothing: u32,
    rounding: Rounding,
    overflow: Overflow,
) -> chain::Plan {
    let f = |s: &str| s.parse::<Format>().expect("valid format");
    let [input, mean, bias, state, output, _] = formats;
    let estimator = estimator::Plan::new(&estimator::Spec {
        schedule: Schedule {
            interval_length,
            intervals: 4,
            pattern: Pattern::Alternating,
            blank: 3,
            stagger: 1,
        },
        rate_order: 0,
        input: f(input),
        mean: f(mean),
        bias: f(bias),
        calibrated: f(input),
        gain: CoefficientFormat::Auto { width: 18 },
        reciprocal: CoefficientFormat::Auto { width: 18 },
        smoothing_shift: smoothing,
        rounding,
        overflow,
    })
    .expect("plannable estimator");
    let mut spec = crate::examples::kf_spec();
    spec.input = f(input);
    spec.state = f(state);
    spec.output = f(output);
    spec.rounding = rounding;
    spec.overflow = overflow;
    chain::Plan::new(estimator, kf::Plan::new(&spec).expect("plannable KF")).expect("connects")
}

#[test]
fn the_default_chain_runs_bit_exact_in_every_rounding_mode() {
    for rounding in Rounding::ALL {
        let p = crate::examples::chain_plan(20, 3, 5, 0, rounding);
        agree(&p, 600, 7, &[250]);
    }
}

#[test]
fn smoothing_and_wrap_run_bit_exact() {
    for overflow in Overflow::ALL {
        for rounding in [Rounding::Zero, Rounding::Convergent, Rounding::Floor] {
            let p = plan(
                12,
                ["s24.14", "s20.12", "s22.13", "s30.22", "s16.8", ""],
                2,
                rounding,
                overflow,
            );
            agree(&p, 500, 11, &[]);
        }
    }
}

#[test]
fn the_default_program_is_small() {
    let p = crate::examples::chain_plan(150, 10, 0, 0, Rounding::Nearest);
    let program = compile(&p).expect("compiles");
    eprintln!(
        "{} instructions, {} RAM words ({} state), {} coefficients, {}-bit accumulator, {}-bit words",
        program.sample.len(),
        program.ram_words,
        program.state_words,
        program.coefficients.len(),
        program.accumulator_bits,
        program.layout.word_bits()
    );
    // The figures the docs quote; a change to the compiler shows here.
    assert!(program.sample.len() < 1000, "{}", program.sample.len());
    assert!(program.ram_words <= 256, "{}", program.ram_words);
    assert!(
        program.accumulator_bits <= 48,
        "{}",
        program.accumulator_bits
    );
    assert!(
        program.layout.word_bits() <= 32,
        "{}",
        program.layout.word_bits()
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn random_formats_run_bit_exact(
        in_width in 12u32..30,
        in_int in 6u32..11,
        mean_extra in 0u32..8,
        bias_frac_extra in 0i32..6,
        state_guard in 2u32..14,
        state_int in 8u32..14,
        out_width in 10u32..32,
        smoothing in 0u32..3,
        rounding in prop::sample::select(Rounding::ALL.to_vec()),
        overflow in prop::sample::select(Overflow::ALL.to_vec()),
        seed in 1u64..u64::MAX,
    ) {
        let in_frac = in_width - in_int;
        let input = format!("s{in_width}.{in_frac}");
        let mean = format!("s{}.{}", in_width + mean_extra, in_frac + mean_extra);
        let bias_frac = in_frac as i32 + bias_frac_extra;
        let bias = format!("s{}.{}", in_int as i32 + bias_frac, bias_frac);
        let state_frac = in_frac + state_guard;
        let state = format!("s{}.{}", state_int + state_frac, state_frac);
        let out_frac = in_frac.min(out_width - 4);
        let output = format!("s{out_width}.{out_frac}");
        let p = plan(10, [&input, &mean, &bias, &state, &output, ""], smoothing, rounding, overflow);
        agree(&p, 200, seed, &[120]);
    }
}
