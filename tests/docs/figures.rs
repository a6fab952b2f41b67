//! The design figures the guide quotes (pipeline clocks, proven formats and error budgets, the
//! loop table, the golden package's bounds and sizes, the first tutorial's output) are what the
//! code gives now; run times and memory live on the benchmarks page, not here.

use super::manifest_schema::golden_manifest;
use super::{guide, repository};
use crate::common::*;

/// `text` with every run of whitespace made one space, so that a phrase a page wraps over two
/// lines is found whole.
fn flattened(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Whether `text` holds `phrase`, however either is wrapped.
fn quotes(text: &str, phrase: &str) -> bool {
    flattened(text).contains(&flattened(phrase))
}

/// Asserts that `page` (below `docs/guide/src`, or `README.md`) says `phrase`, whose figures
/// the caller made from what the code gives now.
fn assert_quotes(page: &str, phrase: &str) {
    let path = if page == "README.md" {
        repository().join(page)
    } else {
        guide().join(page)
    };
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{page}: {e}"));
    assert!(
        quotes(&text, phrase),
        "{page} should say `{phrase}`: that is what the code gives now (correct the page, or \
         the code)"
    );
}

/// The figure check finds a phrase wrapped over lines, and misses it when one digit differs.
#[test]
fn a_changed_figure_is_caught() {
    let page = "takes\n1 641 clocks:   20.8 kS/s";
    assert!(quotes(page, "takes 1 641 clocks: 20.8"));
    assert!(!quotes(page, "takes 1 642 clocks"));
    assert_eq!(grouped(1641), "1 641");
    assert_eq!(grouped(-94_602), "−94 602");
    assert_eq!(grouped(269_974), "269 974");
    assert_eq!(
        (ordinal(3), ordinal(11), ordinal_word(4)),
        ("3rd".into(), "11th".into(), "fourth".into())
    );
    assert_eq!(power_of_ten(0.000_539_87, 1), "5.4·10⁻⁴");
    assert_eq!(power_of_ten(1_999_984_741.2, 0), "2·10⁹");
    assert_eq!(trimmed(2.000_000_3, 6), "2");
    assert_eq!(trimmed(2.000_009, 6), "2.000009");
    assert_eq!(decimals(18.003, 1), "18.0");
    assert_eq!(decimals(-20.397_502, 4), "−20.3975");
}

/// `n` as the guide writes it: digits in groups of three from 1 000 on, `−` for minus.
fn grouped(n: i64) -> String {
    let digits = n.unsigned_abs().to_string();
    let groups: Vec<&str> = digits
        .as_bytes()
        .rchunks(3)
        .rev()
        .map(|group| std::str::from_utf8(group).unwrap())
        .collect();
    let out = groups.join(" ");
    if n < 0 {
        format!("−{out}")
    } else {
        out
    }
}

/// `x` to `places` decimals as the guide writes it, `−` for minus.
fn decimals(x: f64, places: usize) -> String {
    format!("{x:.places$}").replace('-', "−")
}

/// [`decimals`], but a whole number without its zero decimals (a table's exact predictions).
fn trimmed(x: f64, places: usize) -> String {
    let text = decimals(x, places);
    match text.split_once('.') {
        Some((whole, fraction)) if fraction.chars().all(|c| c == '0') => whole.to_string(),
        _ => text,
    }
}

/// `x` as `m·10ⁿ` with `places` decimals in `m`.
fn power_of_ten(x: f64, places: usize) -> String {
    let exponent = x.abs().log10().floor() as i32;
    let mantissa = x / 10f64.powi(exponent);
    let superscript: String = exponent
        .to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => "⁰¹²³⁴⁵⁶⁷⁸⁹"
                .chars()
                .nth(d.to_digit(10).unwrap() as usize)
                .unwrap(),
        })
        .collect();
    format!("{mantissa:.places$}·10{superscript}")
}

const WORDS: [&str; 11] = [
    "zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
];

/// `n` in words, as the guide writes small counts (digits from 11 on).
fn word(n: u32) -> String {
    WORDS
        .get(n as usize)
        .map_or_else(|| n.to_string(), |w| w.to_string())
}

/// `n` as an ordinal in words (`fourth`), as the guide writes "every fourth clock".
fn ordinal_word(n: u32) -> String {
    match n {
        1 => "first".into(),
        2 => "second".into(),
        3 => "third".into(),
        5 => "fifth".into(),
        8 => "eighth".into(),
        9 => "ninth".into(),
        12 => "twelfth".into(),
        _ => format!("{}th", word(n)),
    }
}

/// `n` as an ordinal in digits (`3rd`).
fn ordinal(n: u32) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// The fraction bits of a format such as `s24.14`.
fn fraction_bits(format: &str) -> i64 {
    format.split_once('.').unwrap().1.parse().unwrap()
}

/// Runs gyrofx with `args` (which include `--json`) and parses its standard output.
fn json(args: &[&str]) -> serde_json::Value {
    let output = gyrofx(args);
    assert!(
        output.status.success(),
        "gyrofx {args:?}:\n{}",
        text(&output)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

/// The pipeline figures the guide quotes (each block's latency and sample spacing, the clocks
/// the testbenches wait, the serial chain's and serial mean filter's clocks, the clocks/sample
/// column of the place-and-route table, the latency a one-stage-longer estimator needs) are
/// `gyrofx_job::pipeline`'s for the default config and its serial variant.
#[test]
fn the_pipeline_clocks_the_guide_quotes_are_the_codes() {
    use gyrofx_codegen::blocks::{placed, RomImages};
    use gyrofx_codegen::text::Provenance;
    use gyrofx_job::config::Config;
    use gyrofx_job::job::Job;
    use gyrofx_job::pipeline;
    use gyrofx_lab::place_route::{placed_blocks, whole_system};

    let job = Job::new(Config::embedded()).unwrap();
    let serial = job.serial_variant().unwrap();
    let (kf, estimator, gyro_loop, system) = (
        pipeline::KF,
        pipeline::ESTIMATOR,
        pipeline::GYRO_LOOP,
        pipeline::system(&job),
    );
    let top = pipeline::top(&job);
    let top_serial = pipeline::top(&serial);
    let mean_filter_serial = pipeline::mean_filter(&serial);
    assert_eq!(
        estimator.settle_clocks(),
        top.settle_clocks(),
        "python-c.md and package.md give the estimator and the chain one figure"
    );
    assert_quotes(
        "reference/python-c.md",
        &format!(
            "the estimator's and the chain's {} clocks after the edge that takes it, the gyro \
             loop's {}, the system's {}; the KF's samples come every {} clock",
            estimator.settle_clocks(),
            gyro_loop.settle_clocks(),
            system.settle_clocks(),
            ordinal(kf.min_clocks_per_sample)
        ),
    );
    assert_quotes(
        "reference/package.md",
        &format!(
            "(`settle_clocks`: the KF {} clocks more, the estimator and the chain {}, the loop {}, \
             the system {};",
            kf.settle_clocks(),
            estimator.settle_clocks(),
            gyro_loop.settle_clocks(),
            system.settle_clocks()
        ),
    );
    let config = "reference/config.md";
    assert_quotes(
        config,
        &format!("a sample every {} clocks)", top.min_clocks_per_sample),
    );
    assert_quotes(
        config,
        &format!(
            "a sample every {} clocks by default",
            grouped(top_serial.min_clocks_per_sample.into())
        ),
    );
    assert_quotes(
        config,
        &format!(
            "a block's mean {} clocks after its last sample by default",
            mean_filter_serial.latency_clocks
        ),
    );
    assert_quotes(
        config,
        &format!(
            "the loop's ADC samples every {} clocks by default",
            pipeline::gyro_loop(&serial).min_clocks_per_sample
        ),
    );
    let place = "how-to/place-and-route.md";
    assert_quotes(
        place,
        &format!(
            "A sample takes {} clocks",
            grouped(top_serial.min_clocks_per_sample.into())
        ),
    );
    assert_quotes(
        place,
        &format!(
            "a block's mean comes {} clocks after its last sample",
            mean_filter_serial.latency_clocks
        ),
    );
    assert_quotes(
        place,
        &format!("then rounds the output ({} clocks)", kf.latency_clocks),
    );
    assert_quotes(
        place,
        &format!(
            "before the estimates load ({} clocks)",
            estimator.latency_clocks
        ),
    );
    assert_quotes(
        place,
        &format!("Clocks per sample: {}", top.min_clocks_per_sample),
    );
    assert_eq!(gyro_loop.latency_clocks, gyro_loop.min_clocks_per_sample);
    assert_quotes(
        "explanation/gyro-loop.md",
        &format!(
            "({} register stages, an ADC sample at most every {} clock)",
            word(gyro_loop.latency_clocks),
            ordinal_word(gyro_loop.min_clocks_per_sample)
        ),
    );
    let longer = format!(
        "passes with `--latency-clocks {}`",
        estimator.latency_clocks + 1
    );
    assert_quotes("reference/python-c.md", &longer);
    assert_quotes(
        "how-to/verify-your-rtl.md",
        &longer.replace("passes", "pass"),
    );

    // The table's clocks/sample column: each placed block's, per target, every placed block.
    let provenance = Provenance::for_tests();
    let roms = RomImages::new(&job, &provenance);
    let serial_roms = RomImages::new(&serial, &provenance);
    let page = std::fs::read_to_string(guide().join(place)).unwrap();
    let targets: Vec<&str> = gyrofx_lab::place_route::Target::ALL
        .iter()
        .map(|t| t.name())
        .collect();
    let mut rows: Vec<(String, String)> = Vec::new();
    for line in page
        .lines()
        .filter(|l| targets.iter().any(|t| l.starts_with(&format!("| {t} |"))))
    {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (target, block, clocks) = (cells[1], cells[2], cells[10]);
        // The whole system takes its samples at the folded system's spacing.
        let timed = if block == whole_system::NAME {
            whole_system::SYSTEM
        } else {
            block
        };
        let (registered, is_serial) =
            placed(timed).unwrap_or_else(|| panic!("{place}: {block} is not a placed block"));
        let want = if is_serial {
            registered.block(&serial, &serial_roms)
        } else {
            registered.block(&job, &roms)
        }
        .clocks_per_sample();
        assert_eq!(
            clocks,
            want.to_string(),
            "{place}: {block} on {target} should say {want} clocks/sample"
        );
        rows.push((target.into(), block.into()));
    }
    // Every target's rows, ECP5's among them.
    assert!(targets.contains(&"ecp5-12f") && targets.contains(&"ecp5-25f"));
    for target in targets {
        let listed: Vec<&str> = rows
            .iter()
            .filter(|(t, _)| t == target)
            .map(|(_, b)| b.as_str())
            .collect();
        assert_eq!(listed, placed_blocks(), "{place}: the {target} rows");
    }
}

/// The figures the guide quotes of the default package are its golden manifest's: the mean
/// filter's bound and measured error and ROM word, the raw and calibrated bias errors, the
/// package's size and the system's share, the loop and system vector counts, the KF's guard
/// bits, and how many blocks have cocotb tests and DPI-C testbenches.
#[test]
fn the_default_packages_figures_the_guide_quotes_are_the_golden_manifests() {
    let golden = golden_manifest();
    let mean_filter = &golden["mean_filter"];
    let bound = mean_filter["fixed_vs_float"]["bound_lsb"].as_f64().unwrap();
    let measured = mean_filter["fixed_vs_float"]["max_lsb"].as_f64().unwrap();
    assert_quotes(
        "explanation/papers.md",
        &format!(
            "The fixed-vs-float bound is {bound:.1} LSB for the default, measured {measured:.1} \
             on its full-scale blocks"
        ),
    );
    assert_quotes(
        "explanation/fixed-point.md",
        &format!(
            "the default's {}-bit word allows {bound:.1} LSB",
            mean_filter["rom"]["word_bits"]
        ),
    );
    let bias = |signal: &str| -> String {
        let line = golden["report"]["lines"]
            .as_array()
            .unwrap()
            .iter()
            .find(|l| l["signal"].as_str().unwrap().starts_with(signal))
            .unwrap_or_else(|| panic!("no report line {signal}"));
        let error = line["bias_error_dps"].as_f64().unwrap();
        decimals(error, if error.abs() < 1.0 { 3 } else { 1 })
    };
    let gyro_loop = "explanation/gyro-loop.md";
    assert_quotes(
        gyro_loop,
        &format!(
            "the raw gyros' physical bias ({} and {} °/s, with the front end's drift) is {} °/s \
             after reversal",
            bias("raw gyro A"),
            bias("raw gyro B"),
            bias("calibrated")
        ),
    );
    let files = golden["files"].as_array().unwrap();
    let bytes = |prefix: &str| -> f64 {
        files
            .iter()
            .filter(|f| f["path"].as_str().unwrap().starts_with(prefix))
            .map(|f| f["bytes"].as_f64().unwrap())
            .sum()
    };
    assert_quotes(
        gyro_loop,
        &format!(
            "writes {:.0} MB, {:.0} MB of it the system's vectors",
            bytes("") / 1e6,
            bytes("system/") / 1e6
        ),
    );
    let vectors = |block: &str| grouped(golden["blocks"][block]["vectors"].as_i64().unwrap());
    assert_quotes(
        gyro_loop,
        &format!("(re-lock), {} ADC samples", vectors("gyro_loop")),
    );
    assert_quotes(
        gyro_loop,
        &format!("fits in {} ADC samples", vectors("system")),
    );
    assert_quotes(
        gyro_loop,
        &format!("the system's {}-sample closed run", vectors("system")),
    );
    let guard_bits = golden["kf"]["guard_bits"].as_u64().unwrap();
    assert_quotes(
        "reference/testbenches.md",
        &format!("the default's {guard_bits} guard bits"),
    );
    assert_quotes(
        "reference/config.md",
        &format!("| {guard_bits} guard bits |"),
    );
    let count = |prefix: &str| -> u32 {
        files
            .iter()
            .filter(|f| f["path"].as_str().unwrap().starts_with(prefix))
            .count() as u32
    };
    let cocotb = word(count("cocotb/cocotb_gyrofx_"));
    assert_quotes("README.md", &format!("such tests for {cocotb} blocks"));
    assert_quotes(
        "tutorials/first-cocotb-test.md",
        &format!("the same way for {cocotb} blocks"),
    );
    assert_quotes(
        "reference/python-c.md",
        &format!("`python/tests/test_cocotb.py` runs all {cocotb}"),
    );
    assert_quotes(
        "reference/python-c.md",
        &format!("runs all {} DPI-C testbenches", word(count("dpi/tb_dpi_"))),
    );
}

/// The ranges, formats and budgets the fixed-point page quotes are what `gyrofx formats`
/// proves for the default config: the KF state's record length, drift and switch terms, the
/// chain's and the loop's worked-through nodes, and the fraction bits and mean-filter words
/// each error budget gives.
#[test]
fn the_formats_figures_the_guide_quotes_are_what_formats_proves() {
    let budgets = ["2.6", "2", "1.6", "10", "3"];
    let (no_switches, default, by_budget) = std::thread::scope(|scope| {
        let no_switches = scope.spawn(|| json(&["formats", "--switches", "0", "--json"]));
        let default = scope.spawn(|| json(&["formats", "--json"]));
        let by_budget: Vec<_> = budgets
            .iter()
            .map(|b| scope.spawn(move || json(&["formats", "--output-error", b, "--json"])))
            .collect();
        (
            no_switches.join().unwrap(),
            default.join().unwrap(),
            by_budget
                .into_iter()
                .map(|h| h.join().unwrap()["output_error"].clone())
                .collect::<Vec<_>>(),
        )
    });
    let node = |run: &serde_json::Value, name: &str| -> serde_json::Value {
        run["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|n| n["node"] == name)
            .unwrap_or_else(|| panic!("formats has no node {name}"))
            .clone()
    };
    let s = |v: &serde_json::Value| v.as_str().unwrap().to_string();
    let low = |n: &serde_json::Value| n["range_dps"][0].as_f64().unwrap();
    let high = |n: &serde_json::Value| n["range_dps"][1].as_f64().unwrap();
    let spare = |n: &serde_json::Value| {
        n["integer_bits"].as_i64().unwrap() - n["needed_integer_bits"].as_i64().unwrap()
    };
    let page = "explanation/fixed-point.md";

    // The chain, worked through (`--switches 0`, then the default 100 switches).
    let state = node(&no_switches, "kf.state");
    assert_quotes(
        page,
        &format!(
            "its state {} is proven for records up to {} samples without switches",
            s(&state["format"]),
            grouped(
                no_switches["kf"]["state_proven_up_to_samples"]
                    .as_i64()
                    .unwrap()
            )
        ),
    );
    let drift = 2f64.powi(-(fraction_bits(&s(&state["format"])) as i32 + 1));
    assert_quotes(
        page,
        &format!(
            "the worst-case rounding drift, {} °/s a sample all one way",
            power_of_ten(drift, 1)
        ),
    );
    let per_switch = default["kf"]["per_switch_dps"].as_f64().unwrap();
    assert_quotes(
        page,
        &format!("{} °/s in the default", power_of_ten(per_switch, 1)),
    );
    let switches = default["switches"].as_f64().unwrap();
    assert_quotes(
        page,
        &format!(
            "With the default {switches} switches (±{:.3} °/s more) neither is proven, and \
             `--write` gives {} and {}",
            switches * per_switch,
            s(&node(&default, "kf.state")["proven_format"]),
            s(&node(&default, "kf.output")["proven_format"])
        ),
    );
    let mean = node(&no_switches, "estimator.mean");
    assert_eq!(spare(&mean), 0, "{page}: the interval means are tight");
    assert_quotes(
        page,
        &format!(
            "the interval means and bias estimates ({}) are proven and tight (±{:.4} °/s;",
            s(&mean["format"]),
            high(&mean)
        ),
    );
    assert_quotes(
        page,
        &format!(
            "can reach ±{:.0} °/s when a full-scale sample",
            high(&node(&no_switches, "estimator.calibrated"))
        ),
    );
    let (dot, sum_x2) = (
        node(&no_switches, "estimator.dot"),
        node(&no_switches, "kf.sum_x2"),
    );
    assert_quotes(
        page,
        &format!(
            "(`estimator.dot`: {} where {} would do; `kf.sum_x2`: {} where {} would)",
            s(&dot["format"]),
            s(&dot["proven_format"]),
            s(&sum_x2["format"]),
            s(&sum_x2["proven_format"])
        ),
    );
    let output = node(&no_switches, "mean_filter.output");
    let full_scale = no_switches["input_range_dps"][1].as_f64().unwrap();
    let lsb = 2f64.powi(-(fraction_bits(&s(&output["format"])) as i32));
    assert_quotes(
        page,
        &format!(
            "mean filter's output can pass full scale by {:.0} LSB",
            (high(&output) - full_scale) / lsb
        ),
    );
    assert_quotes(
        page,
        &format!("`--write` gives it {}.", s(&output["proven_format"])),
    );

    // The loop, worked through.
    let loop_node = |name: &str| node(&no_switches, &format!("loop.{name}"));
    let demod = ["demod_product", "demod_state", "demod_output"].map(loop_node);
    assert_quotes(
        page,
        &format!("the product `2·x·ref` reaches ±{:.6} FS", high(&demod[0])),
    );
    assert_quotes(
        page,
        &format!(
            "{}, {} and {} are proven and tight",
            s(&demod[0]["format"]),
            s(&demod[1]["format"]),
            s(&demod[2]["format"])
        ),
    );
    let agc_error = loop_node("agc_error");
    assert_quotes(
        page,
        &format!(
            "`e_A = a_set − I` spans [{}, {}] FS",
            decimals(low(&agc_error), 1),
            decimals(high(&agc_error), 1)
        ),
    );
    assert_quotes(
        page,
        &format!("`--write` widens to {}", s(&agc_error["proven_format"])),
    );
    let pll = loop_node("pll_integrator");
    assert_quotes(
        page,
        &format!(
            "(its pull range, {:.4} cycles per sample at most) has {} integer bits to spare in {} \
             (`--write`: {})",
            high(&pll),
            spare(&pll),
            s(&pll["format"]),
            s(&pll["proven_format"])
        ),
    );
    let pll_output = loop_node("pll_output");
    assert_quotes(
        page,
        &format!(
            "the NCO's {} frequency word, {};",
            s(&pll_output["format"]),
            spare(&pll_output)
        ),
    );
    let agc = loop_node("agc_integrator");
    assert_quotes(
        page,
        &format!(
            "the AGC's integrator ([0, {}] DAC LSB) {} in {} (`--write`: {})",
            grouped(high(&agc) as i64),
            spare(&agc),
            s(&agc["format"]),
            s(&agc["proven_format"])
        ),
    );
    let agc_output = loop_node("agc_output");
    assert_quotes(
        page,
        &format!(
            "spans [{}, {}] DAC LSB: {} saturates it",
            grouped(low(&agc_output).round() as i64),
            grouped(high(&agc_output).round() as i64),
            s(&agc_output["format"])
        ),
    );
    assert_quotes(
        page,
        &format!(
            "is proven and tight at ±{} LSB",
            grouped(high(&loop_node("dac")) as i64)
        ),
    );
    let comb = loop_node("cic_comb");
    assert_quotes(
        page,
        &format!(
            "(exact, ±{} FS in its {} register)",
            power_of_ten(high(&comb), 0),
            s(&comb["format"])
        ),
    );
    let internal = loop_node("cic_internal");
    assert_quotes(
        page,
        &format!(
            "(±{:.4} FS, {}) are tight",
            high(&internal),
            s(&internal["format"])
        ),
    );
    let cic_output = loop_node("cic_output");
    assert_quotes(
        page,
        &format!(
            "the compensator's output reaches ±{:.2} FS",
            high(&cic_output)
        ),
    );
    assert_quotes(
        page,
        &format!(
            "{} integer bit more than {} (`--write`: {})",
            word(-spare(&cic_output) as u32),
            s(&cic_output["format"]),
            s(&cic_output["proven_format"])
        ),
    );
    let rate = loop_node("output");
    assert_quotes(
        page,
        &format!(
            "The rate output can reach ±{} °/s",
            grouped(high(&rate).round() as i64)
        ),
    );
    assert_quotes(
        page,
        &format!(
            "{} integer bits more than {}",
            word(-spare(&rate) as u32),
            s(&rate["format"])
        ),
    );

    // Error budgets.
    let [b26, b2, b16, b10, b3] = &by_budget[..] else {
        unreachable!()
    };
    for (budget, result) in budgets.iter().zip(&by_budget) {
        assert_eq!(
            result["estimator.mean_format"], result["estimator.bias_format"],
            "{page}: one format for the means and biases at {budget} LSB"
        );
    }
    assert_quotes(
        page,
        &format!(
            "set a floor, {:.1} LSB in the default",
            b26["floor_lsb"].as_f64().unwrap()
        ),
    );
    let input_fraction = fraction_bits(&s(&node(&default, "kf.output")["format"]));
    let guard_bits =
        |means: &str, state: &str| fraction_bits(means) + fraction_bits(state) - 2 * input_fraction;
    let golden = golden_manifest();
    assert_quotes(
        page,
        &format!(
            "2.6 LSB gives {} means and biases and an {} state (bound {:.2} LSB, {} guard bits \
             where the default spends {} for {:.2}), 2 LSB {} and {}, 1.6 LSB {} and {}.",
            s(&b26["estimator.mean_format"]),
            s(&b26["kf.state_format"]),
            b26["bound_lsb"].as_f64().unwrap(),
            guard_bits(
                &s(&b26["estimator.mean_format"]),
                &s(&b26["kf.state_format"])
            ),
            guard_bits(
                &s(&node(&default, "estimator.mean")["format"]),
                &s(&node(&default, "kf.state")["format"])
            ),
            golden["chain"]["fixed_vs_float"]["bound_lsb"]
                .as_f64()
                .unwrap(),
            s(&b2["estimator.mean_format"]),
            s(&b2["kf.state_format"]),
            s(&b16["estimator.mean_format"]),
            s(&b16["kf.state_format"])
        ),
    );
    assert_quotes(
        page,
        &format!(
            "10 LSB takes {} bits, 3 LSB {}, 2 LSB {}, 1.6 LSB {} (bound {:.1} LSB)",
            b10["mean_filter.reciprocal_width"],
            b3["mean_filter.reciprocal_width"],
            b2["mean_filter.reciprocal_width"],
            b16["mean_filter.reciprocal_width"],
            b16["mean_filter_bound_lsb"].as_f64().unwrap()
        ),
    );
}

/// The gyro-loop page's table (gyro A's loop in both modes, measured and predicted), its
/// residual bias and settling, and the blanking the config needs for it, are what `gyrofx
/// loop` gives on the default config.
#[test]
fn the_loop_table_the_guide_quotes_is_what_loop_measures() {
    let figures = json(&["loop", "--json"]);
    let gyro_a = figures
        .as_array()
        .unwrap()
        .iter()
        .find(|g| g["gyro"] == "a")
        .unwrap();
    let page = "explanation/gyro-loop.md";
    let rows = [
        ("drive frequency, Hz", "drive_frequency_hz", 1.0, 5, false),
        ("drive amplitude, µm", "drive_amplitude_m", 1e6, 6, false),
        ("scale factor", "scale_factor", 1.0, 5, false),
        ("bias, °/s", "bias_dps", 1.0, 4, true),
        ("quadrature, °/s", "quadrature_dps", 1.0, 3, false),
        (
            "lock and amplitude within 0.1 %, ms",
            "settling_ms",
            1.0,
            0,
            false,
        ),
        (
            "rate within 0.01 °/s after a switch, ms",
            "rate_settling_ms",
            1.0,
            0,
            false,
        ),
    ];
    for (label, key, scale, places, plus) in rows {
        let mut row = format!("| {label} |");
        for mode in ["normal", "reverse"] {
            for which in ["measured", "predicted"] {
                let value = gyro_a[mode][key][which].as_f64().unwrap() * scale;
                let sign = if plus && value >= 0.0 { "+" } else { "" };
                row.push_str(&format!(" {sign}{} |", trimmed(value, places)));
            }
        }
        assert_quotes(page, &row);
    }
    let residual = &gyro_a["residual_bias_dps"];
    assert_quotes(
        page,
        &format!(
            "`(S + S′)/2`: {} °/s measured, {} °/s predicted",
            decimals(residual["measured"].as_f64().unwrap(), 4),
            decimals(residual["predicted"].as_f64().unwrap(), 4)
        ),
    );
    let settling = |mode: &str| {
        gyro_a[mode]["rate_settling_ms"]["measured"]
            .as_f64()
            .unwrap()
    };
    assert_quotes(
        page,
        &format!(
            "The rate settles about {} ms after a switch",
            decimals(settling("normal"), 0)
        ),
    );
    let golden = golden_manifest();
    let fs_hz = golden["config"]["stimulus"]["fs_hz"].as_f64().unwrap();
    let blank = golden["config"]["sequencer"]["blank"].as_f64().unwrap();
    assert_quotes(
        page,
        &format!(
            "at least {} samples at {fs_hz} Hz for paper 004's gyro; the default blanks {blank} \
             samples, {} ms",
            (settling("normal").max(settling("reverse")) * fs_hz / 1e3).ceil(),
            blank * 1e3 / fs_hz
        ),
    );
}

/// The residual budget's table in the gyro-loop explanation is what `formats
/// --residual-budget 1mdps` gives for gyro A: each part as configured and as chosen, the worst
/// cases, the measured departures and the choice.
#[test]
fn the_residual_budget_the_guide_quotes_is_what_formats_gives() {
    let report = &json(&["formats", "--residual-budget", "1mdps", "--json"])["residual_budget"];
    let gyro = &report["gyros"][0];
    let cost = |budget: &str, name: &str| {
        let parts = gyro[budget]["parts"].as_array().unwrap();
        let part = parts.iter().find(|p| p["name"] == name).unwrap();
        let cost = &part["cost"];
        if let Some(bound) = cost["bound"].as_f64() {
            format!("≤ {}", decimals(1e3 * bound, 3))
        } else {
            let value = 1e3
                * cost["derived"]
                    .as_f64()
                    .or(cost["measured"].as_f64())
                    .unwrap();
            let sign = if value >= 0.0 { "+" } else { "" };
            format!("{sign}{}", decimals(value, 3))
        }
    };
    let page = "explanation/gyro-loop.md";
    for (label, settings, name) in [
        ("locked frequency", "the structure", "locked frequency"),
        (
            "PLL `2f` modulation",
            "`pll_bandwidth_hz`, `demod_lowpass_shift`",
            "PLL 2f modulation",
        ),
        ("phase trim", "`phase_trim`", "phase trim"),
        ("sense gain", "the structure, the PLL", "sense gain"),
        (
            "PLL frequency step",
            "`nco_phase_bits`, `pll_bandwidth_hz`",
            "PLL frequency step",
        ),
        (
            "NCO truncation",
            "`nco_address_bits`, `nco_error_feedback`",
            "NCO truncation",
        ),
        ("float twin leftover", "—", "float twin leftover"),
    ] {
        let row = format!(
            "| {label} | {settings} | {} | {} |",
            cost("configured", name),
            cost("chosen", name)
        );
        assert_quotes(page, &row);
    }
    let worst = |budget: &str| {
        let parts = gyro[budget]["parts"].as_array().unwrap();
        let (mut derived, mut bounds) = (0.0, 0.0);
        for part in parts {
            let c = &part["cost"];
            match c["bound"].as_f64() {
                Some(b) => bounds += b,
                None => derived += c["derived"].as_f64().or(c["measured"].as_f64()).unwrap(),
            }
        }
        decimals(1e3 * (f64::abs(derived) + bounds), 3)
    };
    assert_quotes(
        page,
        &format!(
            "| worst case | | {} | {} |",
            worst("configured"),
            worst("chosen")
        ),
    );
    let measured = |key: &str| decimals(1e3 * gyro[key]["departure_dps"].as_f64().unwrap(), 3);
    assert_quotes(
        page,
        &format!(
            "| measured (closed fixed loop) | | +{} | +{} |",
            measured("configured_measured"),
            measured("chosen_measured")
        ),
    );
    let chosen = &report["chosen"];
    assert_quotes(
        page,
        &format!(
            "1 mdps needs `nco_address_bits = {}` and `nco_phase_bits = {}`",
            chosen["nco_address_bits"], chosen["nco_phase_bits"]
        ),
    );
}

/// The first-package tutorial shows what its commands give: `generate`'s first lines, the
/// testbenches' sample counts, and the expected value it flips (the hex word on line 3 of
/// the KF's expected file, and its real value in the mismatch line).
#[test]
fn the_first_package_tutorial_shows_what_generate_prints() {
    let dir = tempfile::tempdir().unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_gyrofx"))
        .args([
            "generate",
            "--out",
            "pkg",
            "--samples",
            "2000",
            "--blocks",
            "kf,top",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", text(&output));
    let printed = String::from_utf8_lossy(&output.stdout).into_owned();
    let page_name = "tutorials/first-package.md";
    let page = std::fs::read_to_string(guide().join(page_name)).unwrap();
    let shown: Vec<&str> = page
        .split("```text\n")
        .nth(1)
        .and_then(|block| block.split("```").next())
        .unwrap()
        .lines()
        .collect();
    assert_eq!(shown.len(), 3, "{page_name}: generate's output block");
    for line in shown {
        let (whole, start) = match line.strip_suffix("; ...") {
            Some(start) => (false, start),
            None => (true, line),
        };
        assert!(
            printed.lines().any(|l| if whole {
                l == start
            } else {
                l.starts_with(start)
            }),
            "{page_name} shows `{line}`; generate printed:\n{printed}"
        );
    }
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("pkg/manifest.json")).unwrap(),
    )
    .unwrap();
    let vectors = |block: &str| manifest["blocks"][block]["vectors"].as_u64().unwrap();
    assert_quotes(
        page_name,
        &format!(
            "== kf\nPASS n={}\n== top\nPASS n={}",
            vectors("kf"),
            vectors("top")
        ),
    );
    let expected = std::fs::read_to_string(dir.path().join("pkg/kf/kf_expected.hex")).unwrap();
    // Line 3 is the first sample's `out_valid rate_out`.
    let word = expected
        .lines()
        .nth(2)
        .unwrap()
        .split_whitespace()
        .last()
        .unwrap();
    let last = word.chars().last().unwrap().to_digit(16).unwrap();
    let flipped = format!("{}{:x}", &word[..word.len() - 1], last ^ 1);
    let (short, short_flipped) = (&word[word.len() - 6..], &flipped[flipped.len() - 6..]);
    assert_quotes(
        page_name,
        &format!("sed -i '3s/{short}$/{short_flipped}/' pkg/kf/kf_expected.hex"),
    );
    let fraction = fraction_bits(manifest["kf"]["formats"]["output"].as_str().unwrap());
    let real = |hex: &str| {
        let bits = 4 * hex.len() as u32;
        let code = i64::from_str_radix(hex, 16).unwrap();
        let code = if code >> (bits - 1) == 1 {
            code - (1 << bits)
        } else {
            code
        };
        code as f64 / 2f64.powi(fraction as i32)
    };
    assert_quotes(
        page_name,
        &format!(
            "MISMATCH sample 0 signal rate_out expected {short_flipped} ({:.8}) actual {short} \
             ({:.8})\nFAIL mismatches=1 n={}",
            real(&flipped),
            real(word),
            vectors("kf")
        ),
    );
}

/// `reproduce --paper 002`'s report cites the benchmarks page's DAVAR figure.
#[test]
fn the_reproduce_report_cites_the_benchmarks_pages_davar_figure() {
    let source =
        std::fs::read_to_string(repository().join("lab/src/reproduce/paper_002.rs")).unwrap();
    let cited = source
        .split("measured ")
        .nth(1)
        .and_then(|rest| rest.split(" for L = 3001").next())
        .expect("paper_002.rs cites `measured <t> for L = 3001`");
    assert_quotes(
        "reference/benchmarks.md",
        &format!("over 60 000 samples: {cited}"),
    );
}

/// The README's Rust version is the workspace's `rust-version`.
#[test]
fn the_readme_states_the_rust_version_the_workspace_needs() {
    let manifest = std::fs::read_to_string(repository().join("Cargo.toml")).unwrap();
    let version = manifest
        .lines()
        .find_map(|l| l.strip_prefix("rust-version = \""))
        .and_then(|rest| rest.strip_suffix('"'))
        .expect("Cargo.toml has a rust-version");
    assert_quotes("README.md", &format!("(Rust {version} or later)"));
}

/// The folded gyro loop's page quotes the default config's schedule (each template's clocks, the
/// regular and decimating lengths) and pipeline as the model derives them.
#[test]
fn the_folded_loop_schedule_the_page_quotes_is_the_models() {
    use gyrofx_job::config::Config;
    use gyrofx_job::job::Job;
    use gyrofx_job::pipeline;

    let serial = Job::new(Config::embedded())
        .unwrap()
        .serial_variant()
        .unwrap();
    let schedule = serial.loop_schedule.as_ref().unwrap();
    let page =
        std::fs::read_to_string(super::repository().join("docs/blocks/gyro_loop.md")).unwrap();
    for p in &schedule.placements {
        let row = format!("| {} | {}–{} |", p.name, p.first, p.last);
        assert!(
            page.contains(&row),
            "docs/blocks/gyro_loop.md should have the row {row}"
        );
    }
    let pipeline = pipeline::gyro_loop(&serial);
    for quote in [
        format!("Every sample runs the first {} clocks", schedule.regular),
        format!("all\n{} clocks.", schedule.len()).replace('\n', " "),
        format!(
            "`latency_clocks` = `min_clocks_per_sample` = {} on the default",
            pipeline.latency_clocks
        ),
    ] {
        let flat = page.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(
            flat.contains(&quote),
            "docs/blocks/gyro_loop.md should say {quote:?}"
        );
    }
}
