//! The package's DPI-C testbenches (`dpi/`): per block with a golden model, a SystemVerilog
//! testbench that imports the model's step from gyrofx's C ABI (`capi/`, `libgyrofx_capi`)
//! and scoreboards the DUT against it in Verilator, with random stimulus over the whole input
//! range and a small-signal half.
//!
//! Outputs qualified by a valid flag are compared as a stream (a queue of expected values),
//! whatever the latency; combinational outputs before the clock edge that takes the sample,
//! registered outputs without a valid flag after the block's pipeline. Each testbench prints
//! `PASS n=<N>` or `FAIL mismatches=<M> n=<N>` and exits non-zero on a mismatch or a refused
//! model call. Plusargs: `+samples=<n>`, `+seed=<n>`, `+flip=<k>` (flip bit 0 of the k-th
//! expected value: the testbench must then fail).

use crate::block::{Block, Signal};
use crate::testbench::verilog::instance;
use crate::text::{fill, Provenance};

/// Folder of the DPI-C testbenches in a package.
pub const FOLDER: &str = "dpi";

/// The blocks of `blocks` that have a DPI-C testbench (those with a golden model), in the
/// package's order.
pub fn tested(blocks: &[Block]) -> Vec<&Block> {
    blocks
        .iter()
        .filter(|b| gyrofx_job::golden::BLOCKS.contains(&b.name))
        .collect()
}

/// Every file of the package's `dpi/` folder: `(path, text)`.
pub fn files(blocks: &[Block], provenance: &Provenance) -> Vec<(String, String)> {
    tested(blocks)
        .into_iter()
        .map(|block| {
            (
                format!("{FOLDER}/tb_dpi_{}.sv", block.module),
                testbench(block, provenance),
            )
        })
        .collect()
}

fn declaration(signal: &Signal, kind: &str) -> String {
    let signed = if signal.format.signed { " signed" } else { "" };
    let range = if signal.format.width > 1 {
        format!(" [{}:0]", signal.format.width - 1)
    } else {
        String::new()
    };
    format!("{kind}{signed}{range} {};", signal.name)
}

/// Imports every block's model functions need (the plan's and the error's, then the block's).
fn imports(block: &str) -> &'static str {
    match block {
        "kf" => {
            "import \"DPI-C\" function chandle gyrofx_kf_new(input chandle plan);
import \"DPI-C\" function int gyrofx_kf_reset(input chandle kf);
import \"DPI-C\" function int gyrofx_kf_step(input chandle kf, input longint z, input int bw_sel, output longint rate_out);"
        }
        "mean_filter" => {
            "import \"DPI-C\" function chandle gyrofx_mean_filter_new(input chandle plan);
import \"DPI-C\" function int gyrofx_mean_filter_reset(input chandle filter);
import \"DPI-C\" function int gyrofx_mean_filter_step(input chandle filter, input longint x, output int y_valid, output longint y, output longint kept);"
        }
        "top" => {
            "import \"DPI-C\" function chandle gyrofx_chain_new(input chandle plan);
import \"DPI-C\" function int gyrofx_chain_reset(input chandle chain);
import \"DPI-C\" function int gyrofx_chain_step(input chandle chain, input longint y_a, input longint y_b, input int bw_sel,
    output int mode_a, output int mode_b, output int out_valid, output longint rate_out,
    output longint bias_a, output longint bias_b, output int estimated);"
        }
        "gyro_loop" => {
            "import \"DPI-C\" function chandle gyrofx_gyro_loop_new(input chandle plan, input int gyro);
import \"DPI-C\" function int gyrofx_gyro_loop_reset(input chandle gyro_loop);
import \"DPI-C\" function int gyrofx_gyro_loop_step(input chandle gyro_loop, input longint adc_x, input longint adc_y,
    input int mode, output longint dac_x, output longint dac_y, output int locked, output int out_valid,
    output longint rate, output longint quadrature);"
        }
        "system" => {
            "import \"DPI-C\" function chandle gyrofx_system_new(input chandle plan);
import \"DPI-C\" function int gyrofx_system_reset(input chandle system);
import \"DPI-C\" function int gyrofx_system_step(input chandle system, input int enable, input int bw_sel,
    input longint adc_a_x, input longint adc_a_y, input longint adc_b_x, input longint adc_b_y,
    output longint dac_a_x, output longint dac_a_y, output longint dac_b_x, output longint dac_b_y,
    output int locked_a, output int locked_b, output int mode_a, output int mode_b, output int out_valid,
    output longint rate_out, output longint bias_a, output longint bias_b, output int estimated);"
        }
        _ => {
            "import \"DPI-C\" function chandle gyrofx_sequencer_new(input chandle plan);
import \"DPI-C\" function int gyrofx_sequencer_reset(input chandle sequencer);
import \"DPI-C\" function int gyrofx_sequencer_step(input chandle sequencer, output int mode_a, output int mode_b,
    output int blank_a, output int blank_b, output int interval_a, output int interval_b,
    output int done_a, output int done_b, output int window_done);
import \"DPI-C\" function chandle gyrofx_estimator_new(input chandle plan);
import \"DPI-C\" function int gyrofx_estimator_reset(input chandle estimator);
import \"DPI-C\" function int gyrofx_estimator_step(input chandle estimator, input longint y_a, input longint y_b,
    input int blank_a, input int blank_b, input int done_a, input int done_b,
    input int interval_a, input int interval_b, input int window_done,
    output longint bias_a, output longint bias_b, output int estimated);"
        }
    }
}

/// The per-sample body of the block's stimulus loop (after the driver set `ce`; `k` counts
/// samples) and the names of its model handles.
fn body(block: &Block) -> (&'static str, String) {
    match block.name {
        "kf" => (
            "kf = gyrofx_kf_new(plan);",
            "            bw_sel = (k % 97 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            z = random_code(P_IN_W, k);
            check_call(gyrofx_kf_step(kf, longint'(z), int'(bw_sel), stream_model));
            expect_stream(stream_model, 0);
            // The next sample after the pipeline's {idle} clocks more (ce every {every}th clock).
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat ({idle}) @(posedge clk);"
                .replace("{idle}", &(crate::blocks::kf::SETTLE_CLOCKS - 1).to_string())
                .replace("{every}", &crate::blocks::kf::SETTLE_CLOCKS.to_string()),
        ),
        "mean_filter" => (
            "filter = gyrofx_mean_filter_new(plan);",
            "            x = random_code(P_IN_W, k);
            check_call(gyrofx_mean_filter_step(filter, longint'(x), valid, stream_model, model_kept));
            if (valid == 1) expect_stream(stream_model, model_kept);
            @(posedge clk);"
                .to_string()
                + &if block.settle_clocks > 0 {
                    // The sequential filter: the next sample once a block's mean is out.
                    format!(
                        "
            @(negedge clk);
            ce = 1'b0;
            repeat ({}) @(posedge clk);",
                        block.settle_clocks
                    )
                } else {
                    String::new()
                },
        ),
        "top" => (
            "chain = gyrofx_chain_new(plan);",
            "            bw_sel = (k % 97 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            y_a = random_code(P_IN_W, k);
            y_b = random_code(P_IN_W, k + 1);
            check_call(gyrofx_chain_step(chain, longint'(y_a), longint'(y_b), int'(bw_sel),
                model_mode_a, model_mode_b, valid, stream_model, bias_a_model, bias_b_model, estimated_model));
            #1;
            compare(longint'(mode_a), longint'(model_mode_a), \"mode_a\");
            compare(longint'(mode_b), longint'(model_mode_b), \"mode_b\");
            if (valid == 1) expect_stream(stream_model, 0);
            // The estimates show {settle} clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat ({settle}) @(posedge clk);
            #1;
            compare(longint'(bias_a), flip_next(bias_a_model), \"bias_a\");
            compare(longint'(bias_b), bias_b_model, \"bias_b\");
            compare(longint'(estimated), longint'(estimated_model), \"estimated\");"
                .replace("{settle}", &block.settle_clocks.to_string()),
        ),
        "sequencer" => (
            "sequencer = gyrofx_sequencer_new(plan);",
            "            check_call(gyrofx_sequencer_step(sequencer, model_mode_a, model_mode_b, model_blank_a,
                model_blank_b, model_interval_a, model_interval_b, model_done_a, model_done_b,
                model_window_done));
            #1;
            compare(longint'(mode_a), flip_next(longint'(model_mode_a)), \"mode_a\");
            compare(longint'(mode_b), longint'(model_mode_b), \"mode_b\");
            compare(longint'(blank_a), longint'(model_blank_a), \"blank_a\");
            compare(longint'(blank_b), longint'(model_blank_b), \"blank_b\");
            compare(longint'(interval_a), longint'(model_interval_a), \"interval_a\");
            compare(longint'(interval_b), longint'(model_interval_b), \"interval_b\");
            compare(longint'(done_a), longint'(model_done_a), \"done_a\");
            compare(longint'(done_b), longint'(model_done_b), \"done_b\");
            compare(longint'(window_done), longint'(model_window_done), \"window_done\");
            @(posedge clk);"
                .to_string(),
        ),
        "gyro_loop" => (
            "gyro_loop = gyrofx_gyro_loop_new(plan, 0);",
            "            // A mode switch every 701 samples: the loop's presets and re-acquisition.
            if (k == 0) mode = 1'b1;
            else if (k % 701 == 0) mode = ~mode;
            adc_x = random_code(P_DEMOD_ADC_W, k);
            adc_y = random_code(P_DEMOD_ADC_W, k + 1);
            check_call(gyrofx_gyro_loop_step(gyro_loop, longint'(adc_x), longint'(adc_y), int'(mode),
                dac_x_model, dac_y_model, locked_model, valid, stream_model, quadrature_model));
            if (valid == 1) expect_stream(stream_model, quadrature_model);
            // The outputs show 3 clocks after the edge that takes the sample (ce every 4th clock).
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (3) @(posedge clk);
            #1;
            compare(longint'(dac_x), flip_next(dac_x_model), \"dac_x\");
            compare(longint'(dac_y), dac_y_model, \"dac_y\");
            compare(longint'(locked), longint'(locked_model), \"locked\");"
                .to_string(),
        ),
        "system" => (
            "system = gyrofx_system_new(plan);",
            "            // enable low for the first 500 samples (the start-up), then high.
            enable = (k >= 500) ? 1'b1 : 1'b0;
            bw_sel = (k % 997 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            adc_a_x = random_code(P_DEMOD_ADC_W, k);
            adc_a_y = random_code(P_DEMOD_ADC_W, k + 1);
            adc_b_x = random_code(P_DEMOD_ADC_W, k + 2);
            adc_b_y = random_code(P_DEMOD_ADC_W, k + 3);
            check_call(gyrofx_system_step(system, int'(enable), int'(bw_sel), longint'(adc_a_x),
                longint'(adc_a_y), longint'(adc_b_x), longint'(adc_b_y), dac_a_x_model, dac_a_y_model,
                dac_b_x_model, dac_b_y_model, locked_a_model, locked_b_model, model_mode_a, model_mode_b,
                valid, stream_model, bias_a_model, bias_b_model, estimated_model));
            if (valid == 1) expect_stream(stream_model, 0);
            // Every output shows {settle} clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat ({settle}) @(posedge clk);
            #1;
            compare(longint'(dac_a_x), flip_next(dac_a_x_model), \"dac_a_x\");
            compare(longint'(dac_a_y), dac_a_y_model, \"dac_a_y\");
            compare(longint'(dac_b_x), dac_b_x_model, \"dac_b_x\");
            compare(longint'(dac_b_y), dac_b_y_model, \"dac_b_y\");
            compare(longint'(locked_a), longint'(locked_a_model), \"locked_a\");
            compare(longint'(locked_b), longint'(locked_b_model), \"locked_b\");
            compare(longint'(mode_a), longint'(model_mode_a), \"mode_a\");
            compare(longint'(mode_b), longint'(model_mode_b), \"mode_b\");
            compare(longint'(bias_a), bias_a_model, \"bias_a\");
            compare(longint'(bias_b), bias_b_model, \"bias_b\");
            compare(longint'(estimated), longint'(estimated_model), \"estimated\");"
                .replace("{settle}", &crate::blocks::system::SETTLE_CLOCKS.to_string()),
        ),
        _ => (
            "sequencer = gyrofx_sequencer_new(plan);\n        estimator = gyrofx_estimator_new(plan);",
            "            // The slot comes from the sequencer's own model: the estimator's protocol.
            check_call(gyrofx_sequencer_step(sequencer, model_mode_a, model_mode_b, model_blank_a,
                model_blank_b, model_interval_a, model_interval_b, model_done_a, model_done_b,
                model_window_done));
            y_a = random_code(P_IN_W, k);
            y_b = random_code(P_IN_W, k + 1);
            blank_a = model_blank_a[0];
            blank_b = model_blank_b[0];
            done_a = model_done_a[0];
            done_b = model_done_b[0];
            interval_a = model_interval_a[TB_INTERVAL_W - 1:0];
            interval_b = model_interval_b[TB_INTERVAL_W - 1:0];
            window_done = model_window_done[0];
            check_call(gyrofx_estimator_step(estimator, longint'(y_a), longint'(y_b), model_blank_a,
                model_blank_b, model_done_a, model_done_b, model_interval_a, model_interval_b,
                model_window_done, bias_a_model, bias_b_model, estimated_model));
            // The estimates show {settle} clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat ({settle}) @(posedge clk);
            #1;
            compare(longint'(bias_a), flip_next(bias_a_model), \"bias_a\");
            compare(longint'(bias_b), bias_b_model, \"bias_b\");
            compare(longint'(estimated), longint'(estimated_model), \"estimated\");"
                .replace("{settle}", &crate::blocks::estimator::SETTLE_CLOCKS.to_string()),
        ),
    }
}

/// The valid flag and the ports of the block's stream outputs (`None`: no stream).
fn stream(block: &str) -> Option<(&'static str, &'static str, Option<&'static str>)> {
    match block {
        "kf" | "top" | "system" => Some(("out_valid", "rate_out", None)),
        "gyro_loop" => Some(("out_valid", "rate", Some("quadrature"))),
        "mean_filter" => Some(("y_valid", "y", Some("kept"))),
        _ => None,
    }
}

/// The DPI-C testbench of `block`.
pub fn testbench(block: &Block, provenance: &Provenance) -> String {
    let tb = format!("tb_dpi_{}", block.module);
    let (handles, step) = body(block);
    let mut declarations: Vec<String> = block
        .inputs
        .iter()
        .map(|s| declaration(s, "logic"))
        .collect();
    declarations.extend(block.outputs.iter().map(|o| declaration(&o.signal, "wire")));
    let interval_width = block
        .inputs
        .iter()
        .chain(block.outputs.iter().map(|o| &o.signal))
        .find(|s| s.name == "interval_a")
        .map_or(1, |s| s.format.width);
    let monitor = match stream(block.name) {
        Some((valid, value, second)) => fill(
            STREAM_MONITOR,
            &[
                ("valid", valid),
                ("value", value),
                (
                    "second",
                    &match second {
                        Some(name) => format!(
                            "compare(longint'({name}), expected_second.pop_front(), \"{name}\");"
                        ),
                        None => "void'(expected_second.pop_front());".to_string(),
                    },
                ),
            ],
        ),
        None => String::new(),
    };
    fill(
        TESTBENCH,
        &[
            ("provenance", &provenance.line("//")),
            ("tb", &tb),
            ("module", block.module),
            ("title", block.title),
            ("params_file", &block.file("params.vh")),
            ("interval_width", &interval_width.to_string()),
            ("imports", imports(block.name)),
            ("declarations", &declarations.join("\n")),
            ("instance", &instance(block)),
            ("samples", &default_samples(block.name).to_string()),
            ("monitor", &monitor),
            ("handles", handles),
            ("step", &step),
        ],
    )
}

/// The DPI-C testbench's frame and, for a block whose outputs come as a valid-qualified
/// stream, its monitor (`codegen/templates/dpi/`), filled by [`fill`].
const TESTBENCH: &str = include_str!("../templates/dpi/testbench.sv");
const STREAM_MONITOR: &str = include_str!("../templates/dpi/stream_monitor.sv");

/// Samples a testbench runs by default: enough for the system's chain to finish an estimator
/// window (`enable` high from sample 500 on; a window of the system's short schedule is 12
/// chain samples of 1000 ADC samples each by default) and for the loop to give a dozen rates.
fn default_samples(block: &str) -> usize {
    match block {
        "gyro_loop" => 12_000,
        "system" => 14_000,
        _ => 4000,
    }
}
