//! Every parser of user input gets arbitrary bytes and arbitrary-but-plausible text (issue 13,
//! item 6): the config (TOML, then validation and the job's design), the CSV reader, the ROM
//! readers of every format, and the format, rounding, overflow, method, grid and simulator
//! names. None may panic; each either parses or returns an error.

use std::io::Write as _;
use std::str::FromStr;

use gyrofx_codegen::rom::{self, RomFormat};
use gyrofx_job::config::Config;
use gyrofx_job::input::{read_column, read_column_with_gaps};
use gyrofx_job::job::Job;
use gyrofx_lab::simulate::Simulator;
use gyrofx_model::analysis::allan::Grid;
use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::kf::design::Method;
use proptest::prelude::*;

/// The embedded default as `gyrofx init` prints it: the seed of the plausible configs.
const DEFAULT: &str = include_str!("../job/src/default.toml");

/// Tokens that plausible mutations put in place of a value.
const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "1.5",
    "\"s24.14\"",
    "\"u8.0\"",
    "\"s0.0\"",
    "\"s200.3\"",
    "\"s24.-3\"",
    "\"\"",
    "[]",
    "[1.0, -2.0]",
    "{}",
    "true",
    "\"resonator\"",
    "\"rate\"",
    "\"abba\"",
    "4294967296",
    "18446744073709551616",
    "0.0",
    "1e-300",
    "\"x\"",
];

/// The default with one line's value replaced, one line dropped, or one line duplicated.
fn mutated_default() -> impl Strategy<Value = String> {
    let lines: Vec<&'static str> = DEFAULT.lines().collect();
    let count = lines.len();
    (0..count, 0..TOKENS.len(), 0..4u8).prop_map(move |(line, token, action)| {
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        match action {
            0 => {
                if let Some((key, _)) = out[line].split_once('=') {
                    out[line] = format!("{key}= {}", TOKENS[token]);
                }
            }
            1 => {
                out.remove(line);
            }
            2 => {
                let copy = out[line].clone();
                out.insert(line, copy);
            }
            _ => {
                out[line] = out[line].chars().rev().collect();
            }
        }
        let mut text = out.join("\n");
        text.push('\n');
        text
    })
}

/// Parses a config and, if it parses, validates it and designs its job: must not panic.
fn config_never_panics(text: &str) {
    if let Ok(mut config) = Config::from_toml(text, "fuzz.toml") {
        // The resonator plant's settling check simulates both loops: keep most cases on the
        // fast plant, but not all.
        if config.samples % 4 != 0 {
            config.plant.model = "rate".into();
        }
        config.samples = config.samples.min(2_000);
        let _ = Job::new(config);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn configs_from_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        config_never_panics(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn configs_from_the_mutated_default(text in mutated_default()) {
        config_never_panics(&text);
    }

    #[test]
    fn config_sections_with_arbitrary_values(
        section in prop::sample::select(vec!["", "[kf]\n", "[loop]\n", "[front_end]\n", "[sequencer]\n", "[estimator]\n", "[stimulus]\n", "[resonator_a]\n", "[mean_filter]\n"]),
        key in "[a-z_]{1,30}",
        token in prop::sample::select(TOKENS.to_vec()),
    ) {
        config_never_panics(&format!("{section}{key} = {token}\n"));
    }

    #[test]
    fn names_and_formats(text in "\\PC{0,12}", plausible in "[su]-?[0-9]{0,4}\\.-?[0-9]{0,4}") {
        for t in [&text, &plausible] {
            let _ = Format::from_str(t);
            let _ = Rounding::from_str(t);
            let _ = Overflow::from_str(t);
            let _ = Method::from_str(t);
            let _ = Grid::from_str(t);
            let _ = Simulator::from_str(t);
        }
    }

    #[test]
    fn rom_files(bytes in proptest::collection::vec(any::<u8>(), 0..300), hexish in "([0-9a-fA-Fxz@:;= ,_#/\\-]{0,20}\n){0,12}") {
        for format in RomFormat::ALL {
            let _ = rom::parse(&String::from_utf8_lossy(&bytes), format);
            let _ = rom::parse(&hexish, format);
        }
    }

    #[test]
    fn csv_files(bytes in proptest::collection::vec(any::<u8>(), 0..300), rows in "(rate_dps|t|[a-z]{0,3})(,[a-z_]{0,8}){0,2}\n([-0-9.eE+naif,\" ]{0,16}\n){0,10}") {
        for content in [bytes.clone(), rows.into_bytes()] {
            let mut file = tempfile::NamedTempFile::new().unwrap();
            file.write_all(&content).unwrap();
            let _ = read_column(file.path(), "rate_dps");
            let _ = read_column_with_gaps(file.path(), "rate_dps");
        }
    }
}
