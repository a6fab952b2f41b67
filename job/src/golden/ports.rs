//! Each block's ports as its vector files carry them (after `rst`; `clk` and `ce` are not
//! data): name, format and direction, from the block's plan. The Python classes and the C API
//! give them to a testbench of the user's own; `tests/blocks.rs` holds every list to the
//! package's (the generated testbenches' and vector files').

use gyrofx_model::fx::Format;
use gyrofx_model::gyro_loop::gyro as gyro_loop;
use gyrofx_model::{chain, estimator, kf, mean_filter};

/// One port: its name, its format (flags `u1.0`, indices `u<n>.0`) and whether it is an
/// output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Port {
    /// The RTL port's name.
    pub name: &'static str,
    /// Its format.
    pub format: Format,
    /// An output (else an input).
    pub output: bool,
}

impl Port {
    fn input(name: &'static str, format: Format) -> Port {
        Port {
            name,
            format,
            output: false,
        }
    }

    fn output(name: &'static str, format: Format) -> Port {
        Port {
            name,
            format,
            output: true,
        }
    }

    /// `in` or `out`.
    pub fn direction(&self) -> &'static str {
        if self.output {
            "out"
        } else {
            "in"
        }
    }
}

/// A 1-bit flag's format.
fn flag() -> Format {
    Format::new(false, 1, 0).expect("1 bit")
}

/// An index of `bits` bits (at least one).
fn index(bits: u32) -> Format {
    Format::new(false, bits.max(1), 0).expect("a small width")
}

/// The sequencer's slot as the estimator takes it.
fn slot_inputs(interval_bits: u32) -> [Port; 7] {
    [
        Port::input("blank_a", flag()),
        Port::input("blank_b", flag()),
        Port::input("done_a", flag()),
        Port::input("done_b", flag()),
        Port::input("interval_a", index(interval_bits)),
        Port::input("interval_b", index(interval_bits)),
        Port::input("window_done", flag()),
    ]
}

/// `gyrofx_sequencer`'s ports for a schedule of `interval_bits`-bit interval indices.
pub fn sequencer(interval_bits: u32) -> Vec<Port> {
    vec![
        Port::output("mode_a", flag()),
        Port::output("mode_b", flag()),
        Port::output("blank_a", flag()),
        Port::output("blank_b", flag()),
        Port::output("interval_a", index(interval_bits)),
        Port::output("interval_b", index(interval_bits)),
        Port::output("done_a", flag()),
        Port::output("done_b", flag()),
        Port::output("window_done", flag()),
    ]
}

/// `gyrofx_bias_estimator`'s ports.
pub fn estimator(plan: &estimator::Plan) -> Vec<Port> {
    let mut ports = vec![
        Port::input("y_a", plan.input),
        Port::input("y_b", plan.input),
    ];
    ports.extend(slot_inputs(plan.schedule.interval_bits()));
    ports.extend([
        Port::output("bias_a", plan.bias),
        Port::output("bias_b", plan.bias),
        Port::output("estimated", flag()),
    ]);
    ports
}

/// `gyrofx_kf`'s ports.
pub fn kf(plan: &kf::Plan) -> Vec<Port> {
    vec![
        Port::input("bw_sel", index(plan.select_width())),
        Port::input("z", plan.input),
        Port::output("out_valid", flag()),
        Port::output("rate_out", plan.output),
    ]
}

/// `gyrofx_top`'s (and `gyrofx_top_serial`'s) ports.
pub fn chain(plan: &chain::Plan) -> Vec<Port> {
    vec![
        Port::input("bw_sel", index(plan.kf.select_width())),
        Port::input("y_a", plan.estimator.input),
        Port::input("y_b", plan.estimator.input),
        Port::output("mode_a", flag()),
        Port::output("mode_b", flag()),
        Port::output("out_valid", flag()),
        Port::output("rate_out", plan.kf.output),
        Port::output("bias_a", plan.estimator.bias),
        Port::output("bias_b", plan.estimator.bias),
        Port::output("estimated", flag()),
    ]
}

/// `gyrofx_mean_filter`'s (and `gyrofx_mean_filter_serial`'s) ports.
pub fn mean_filter(plan: &mean_filter::Plan) -> Vec<Port> {
    vec![
        Port::input("x", plan.input),
        Port::output("y_valid", flag()),
        Port::output("y", plan.output),
        Port::output("kept", index(plan.count_bits)),
    ]
}

/// `gyrofx_gyro_loop`'s ports.
pub fn gyro_loop(plan: &gyro_loop::Plan) -> Vec<Port> {
    vec![
        Port::input("mode", flag()),
        Port::input("adc_x", plan.adc),
        Port::input("adc_y", plan.adc),
        Port::output("dac_x", plan.dac.to),
        Port::output("dac_y", plan.dac.to),
        Port::output("locked", flag()),
        Port::output("out_valid", flag()),
        Port::output("rate", plan.output.to),
        Port::output("quadrature", plan.output.to),
    ]
}

/// `gyrofx_system`'s ports: gyro A's loop formats (both gyros share them) and the system's
/// chain.
pub fn system(loop_a: &gyro_loop::Plan, plan: &chain::Plan) -> Vec<Port> {
    let (adc, dac) = (loop_a.adc, loop_a.dac.to);
    vec![
        Port::input("enable", flag()),
        Port::input("bw_sel", index(plan.kf.select_width())),
        Port::input("adc_a_x", adc),
        Port::input("adc_a_y", adc),
        Port::input("adc_b_x", adc),
        Port::input("adc_b_y", adc),
        Port::output("dac_a_x", dac),
        Port::output("dac_a_y", dac),
        Port::output("dac_b_x", dac),
        Port::output("dac_b_y", dac),
        Port::output("locked_a", flag()),
        Port::output("locked_b", flag()),
        Port::output("mode_a", flag()),
        Port::output("mode_b", flag()),
        Port::output("out_valid", flag()),
        Port::output("rate_out", plan.kf.output),
        Port::output("bias_a", plan.estimator.bias),
        Port::output("bias_b", plan.estimator.bias),
        Port::output("estimated", flag()),
    ]
}
