//! Bit-exactness over breadth: random configs (formats, rounding and overflow modes, sequencer
//! pattern, window and stagger, smoothing, KF bandwidths, rate scenario, mean-filter window,
//! threshold and formats), each run through every block's testbench in Icarus.
//!
//! CI runs 8 configs of 2.5·10⁴ samples (four tests of two, so the test runner spreads them
//! over the cores): a sample of the space, kept small for CI's time; the sweep below draws
//! the same configs first and then new ones. The gyro loop's testbench is 4·10⁴ samples
//! whatever the config, and of what the configs vary only the rounding and overflow reach its
//! datapath (the seed changes just the noise it sees): it runs once for each pair the run
//! draws (in the first config that draws it), not once per config.
//! The wide sweep, offline (the guide's benchmarks page gives the figures of the last one):
//! `GYROFX_RANDOM_CONFIGS=<per test> GYROFX_RANDOM_SAMPLES=100000
//! GYROFX_RANDOM_SIMULATORS=iverilog,verilator,ghdl cargo test --release --test main random_configs::`

use crate::common::*;

/// splitmix64: a deterministic stream for the test's own choices (not the model's noise).
struct Choices(u64);

impl Choices {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `low..=high`.
    fn int(&mut self, low: i64, high: i64) -> i64 {
        low + (self.next() % (high - low + 1) as u64) as i64
    }

    /// Uniform in `[low, high)`, rounded to 3 significant decimals so the TOML is readable.
    fn real(&mut self, low: f64, high: f64) -> f64 {
        let x = low + (high - low) * (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        format!("{x:.3e}").parse().unwrap()
    }

    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.int(0, items.len() as i64 - 1) as usize]
    }
}

/// The config overlay of random config number `index`.
fn random_config(index: u64, samples: usize) -> String {
    let mut c = Choices(0x6779_726f_6678 ^ index.wrapping_mul(0x1000_0001));
    let fs = [50.0, 100.0, 200.0, 400.0, 1000.0][c.int(0, 4) as usize];
    let intervals = [2, 4, 6, 8][c.int(0, 3) as usize];
    let pattern = if intervals % 4 == 0 {
        c.pick(&["alternating", "abba"])
    } else {
        "alternating"
    };
    let rate_order = if pattern == "abba" { c.int(0, 1) } else { 0 };
    let interval_length = c.int(8, 200);
    let blank = c.int(0, interval_length / 4);
    let stagger = if c.int(0, 1) == 0 {
        0
    } else {
        c.int(blank, interval_length - 1)
    };
    // Formats: integer bits (sign included) of the input set the full scale, ±64..±1024 °/s.
    let input_integer = c.int(7, 11);
    let input_width = c.int(14, 28);
    let input_frac = input_width - input_integer;
    let guard = c.int(0, 14);
    let state_frac = input_frac + guard;
    let state_width = (input_integer + c.int(0, 3) + state_frac).min(64);
    let output_frac = state_frac - c.int(0, guard);
    let output_width = input_integer + c.int(0, 1) + output_frac;
    let mean_frac = input_frac + c.int(0, 6);
    let mean_width = input_integer + c.int(0, 3) + mean_frac;
    let bias_frac = input_frac + c.int(0, 6);
    let bias_width = input_integer + c.int(0, 3) + bias_frac;
    // The paper's discretisation saturates near 0.17·fs; the direct one reaches fs/2.
    let method = c.pick(&["direct", "paper"]);
    let highest = if method == "paper" { 0.15 } else { 0.3 };
    let bandwidths: Vec<String> = (0..c.int(1, 4))
        .map(|_| format!("{}", c.real(0.02 * fs, highest * fs)))
        .collect();
    let scenario = c.pick(&["static", "constant", "sine", "steps", "ramp"]);
    let mean_filter_frac = input_frac + c.int(-2, 4);
    let mean_filter_width = input_integer + c.int(0, 2) + mean_filter_frac;
    format!(
        "# random config {index}
samples = {samples}
seed = {seed}
rounding = \"{rounding}\"
overflow = \"{overflow}\"

[plant]
model = \"rate\"

[stimulus]
fs_hz = {fs:?}
scenario = \"{scenario}\"
rate_dps = {rate:?}
frequency_hz = {frequency:?}
period_s = {period:?}
slope_dps_per_s = {slope:?}

[gyro_a]
bias_dps = {bias_a:?}
arw_deg_per_sqrt_h = {arw_a:?}

[gyro_b]
bias_dps = {bias_b:?}
arw_deg_per_sqrt_h = {arw_b:?}

[sequencer]
interval_length = {interval_length}
intervals = {intervals}
pattern = \"{pattern}\"
blank = {blank}
stagger = {stagger}

[estimator]
rate_order = {rate_order}
mean_format = \"s{mean_width}.{mean_frac}\"
bias_format = \"s{bias_width}.{bias_frac}\"
gain_width = {gain_width}
reciprocal_width = {reciprocal_width}
smoothing_shift = {smoothing}

[kf]
method = \"{method}\"
bandwidths_hz = [{bandwidths}]
input_format = \"s{input_width}.{input_frac}\"
state_format = \"s{state_width}.{state_frac}\"
output_format = \"s{output_width}.{output_frac}\"
coefficient_width = {coefficient_width}

[mean_filter]
window = {window}
threshold_dps = {threshold:?}
output_format = \"s{mean_filter_width}.{mean_filter_frac}\"
reciprocal_width = {mean_filter_reciprocal}
",
        seed = c.int(1, 1 << 40),
        rounding = c.pick(&["floor", "ceil", "zero", "nearest", "round", "convergent"]),
        overflow = c.pick(&["wrap", "saturate"]),
        rate = c.real(-50.0, 50.0),
        frequency = c.real(0.01, 1.0),
        period = c.real(0.5, 20.0),
        slope = c.real(-0.05, 0.05),
        bias_a = c.real(-1.0, 1.0),
        arw_a = c.real(1.0, 10.0),
        bias_b = c.real(-1.0, 1.0),
        arw_b = c.real(1.0, 10.0),
        gain_width = c.int(10, 20),
        reciprocal_width = c.int(10, 20),
        smoothing = c.int(0, 3),
        bandwidths = bandwidths.join(", "),
        coefficient_width = c.int(14, 25),
        window = c.int(2, 64),
        threshold = c.real(0.0, 4.0),
        mean_filter_reciprocal = c.int(12, 30),
    )
}

fn count_from_env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name}={v:?} is not a count"))
        })
        .unwrap_or(default)
}

/// The config's `rounding` and `overflow` lines: all of a random config that reaches the gyro
/// loop's datapath.
fn loop_modes(toml: &str) -> Vec<&str> {
    toml.lines()
        .filter(|line| line.starts_with("rounding =") || line.starts_with("overflow ="))
        .collect()
}

/// Generates and verifies configs `first..first + count` (count from the environment).
fn generate_and_verify(first: u64) {
    let count = count_from_env("GYROFX_RANDOM_CONFIGS", 2) as u64;
    let samples = count_from_env("GYROFX_RANDOM_SAMPLES", 25_000);
    let simulators =
        std::env::var("GYROFX_RANDOM_SIMULATORS").unwrap_or_else(|_| "iverilog".into());
    let runs = simulators.split(',').count();
    // Blocks of `count` configs per test, so a longer run covers new configs, not the same ones.
    let start = first * count;
    for index in start..start + count {
        let dir = tempfile::tempdir().unwrap();
        let toml = random_config(index, samples);
        let config = write_config(dir.path(), "random.toml", &toml);
        let out = dir.path().join("pkg");
        let out = out.to_str().unwrap();
        let loop_is_new = !(0..index)
            .any(|earlier| loop_modes(&random_config(earlier, samples)) == loop_modes(&toml));
        let (blocks, block_count) = if loop_is_new {
            (format!("{CHAIN_BLOCKS},gyro_loop"), CHAIN_BLOCK_COUNT + 1)
        } else {
            (CHAIN_BLOCKS.to_string(), CHAIN_BLOCK_COUNT)
        };
        // Only the blocks verified: the system's vectors are two closed loops over 44 000
        // samples that no simulator here runs.
        let generated = gyrofx(&[
            "generate", "--out", out, "--config", &config, "--blocks", &blocks,
        ]);
        assert!(
            generated.status.success(),
            "random config {index} is refused or fails:\n{toml}\n{}",
            text(&generated)
        );
        let verified = gyrofx(&[
            "verify",
            "--out",
            out,
            "--sim",
            &simulators,
            "--blocks",
            &blocks,
        ]);
        let log = text(&verified);
        assert!(
            verified.status.success() && log.matches("PASS n=").count() == block_count * runs,
            "random config {index} is not bit-exact in {simulators}:\n{toml}\n{log}"
        );
    }
}

#[test]
fn random_configs_0_are_bit_exact() {
    generate_and_verify(0);
}

#[test]
fn random_configs_1_are_bit_exact() {
    generate_and_verify(1);
}

#[test]
fn random_configs_2_are_bit_exact() {
    generate_and_verify(2);
}

#[test]
fn random_configs_3_are_bit_exact() {
    generate_and_verify(3);
}

/// The configs really differ: every knob the matrix claims to vary takes several values.
#[test]
fn the_random_configs_vary_every_knob() {
    let configs: Vec<String> = (0..20).map(|i| random_config(i, 100_000)).collect();
    for key in [
        "rounding",
        "overflow",
        "pattern",
        "intervals",
        "interval_length",
        "stagger",
        "smoothing_shift",
        "bandwidths_hz",
        "input_format",
        "state_format",
        "output_format",
        "mean_format",
        "coefficient_width",
        "scenario",
        "window",
        "threshold_dps",
        "reciprocal_width",
    ] {
        let mut values: Vec<&str> = configs
            .iter()
            .filter_map(|c| c.lines().find(|l| l.starts_with(&format!("{key} ="))))
            .collect();
        values.sort_unstable();
        values.dedup();
        assert!(values.len() >= 2, "{key} takes one value only: {values:?}");
    }
}
