use super::*;
use gyrofx_codegen::block::Signal;
use gyrofx_model::fx::Format;

fn block(clocked: bool) -> Block {
    let mut block = Block::new(
        "kf",
        "gyrofx_kf",
        "test",
        vec![
            Signal::index("bw_sel", 2),
            Signal::new("z", Format::new(true, 24, 14).unwrap()),
        ],
        vec![
            gyrofx_codegen::block::Output::registered(Signal::new(
                "rate_out",
                Format::new(true, 24, 14).unwrap(),
            )),
            gyrofx_codegen::block::Output::pulse(Signal::flag("out_valid")),
        ],
    );
    block.clocked = clocked;
    block
}

/// Every input register takes the next one's bits and the last takes the pin: the inputs,
/// read as one vector `{rst, ce, bw_sel, z}`, shift by one place each clock.
#[test]
fn the_harness_shifts_every_input_bit_and_captures_every_output() {
    let text = harness(&block(true));
    assert!(
        text.contains("{rst, ce, bw_sel, z} <= {ce, bw_sel, z, serial_in};"),
        "{text}"
    );
    assert!(
        text.contains("captured <= capture ? {rate_out, out_valid} : {1'b0, captured[24:1]};"),
        "{text}"
    );
    assert!(text.contains("reg [23:0] z = {24{1'b0}};"), "{text}");
    assert!(text.contains("gyrofx_kf_configured dut ("), "{text}");
    assert!(text.contains(".clk(clk)"), "{text}");

    // A combinational block has no clock, reset or enable to drive.
    let text = harness(&block(false));
    assert!(
        text.contains("{bw_sel, z} <= {bw_sel[0], z, serial_in};"),
        "{text}"
    );
    assert!(
        !text.contains(".clk(clk)") && !text.contains("rst"),
        "{text}"
    );
}

#[test]
fn the_shift_drops_the_top_bit_whatever_the_first_width() {
    let inputs = |w: &[u32]| -> Vec<(String, u32)> {
        w.iter()
            .enumerate()
            .map(|(i, w)| (format!("s{i}"), *w))
            .collect()
    };
    assert_eq!(shift_source(&inputs(&[1, 3])), "s1, ");
    assert_eq!(shift_source(&inputs(&[3, 3])), "s0[1:0], s1, ");
    assert_eq!(shift_source(&inputs(&[2, 3])), "s0[0], s1, ");
    assert_eq!(shift_source(&inputs(&[1])), "");
}

#[test]
fn target_and_block_lists_parse_and_name_what_is_wrong() {
    assert_eq!(
        Target::parse_list("xilinx,ice40-up5k,xilinx").unwrap(),
        vec![Target::Ice40Up5k, Target::Xilinx]
    );
    assert_eq!(Target::parse_list("all").unwrap(), Target::ALL.to_vec());
    let error = Target::parse_list("ice40-up5k,ecp5").unwrap_err();
    assert!(
        error.contains("\"ecp5\"") && error.contains("ice40-hx8k"),
        "{error}"
    );
    assert_eq!(parse_blocks("top, kf").unwrap(), vec!["kf", "top"]);
    assert_eq!(parse_blocks("all").unwrap(), placed_blocks());
    let error = parse_blocks("system").unwrap_err();
    assert!(
        error.contains("\"system\"") && error.contains("mean_filter"),
        "{error}"
    );
}

/// A report with a register-to-register path and an I/O path: the words sum the path's delays
/// and name its ends and the blocks it crosses.
#[test]
fn the_critical_path_is_told_from_its_segments() {
    let segment = |kind: &str, delay: f64, net: &str| serde_json::json!({"type": kind, "delay": delay, "net": net});
    let report = serde_json::json!({
        "critical_paths": [
            {"from": "<async>", "to": "posedge clk", "path": [segment("routing", 9.0, "capture")]},
            {"from": "posedge clk", "to": "posedge clk", "path": [
                segment("clk-to-q", 0.5, ""),
                segment("routing", 1.0, "bias_a[3]"),
                segment("logic", 0.25, ""),
                segment("routing", 2.0, "dut.configured.calibration.corrected_a_SB_LUT4_O_I2[0]"),
                segment("logic", 0.25, ""),
                segment("routing", 1.0, "dut.configured.kf.rate_next[23]"),
                segment("setup", 0.5, ""),
            ]}
        ]
    });
    assert_eq!(
        critical_path_words(&report).unwrap(),
        "5.5 ns from bias_a[3] to kf.rate_next[23] through calibration → kf: 2 logic cells \
         (1.5 ns) and 4.0 ns of routing"
    );
    assert_eq!(critical_path_words(&serde_json::json!({})), None);
}

#[test]
fn the_table_says_why_a_block_does_not_fit() {
    let placement = Placement {
        target: Target::Ice40Up5k,
        device: "iCE40UP5K",
        package: "sg48",
        block: "top",
        module: "gyrofx_top",
        lut4: Some(3387),
        lut6: None,
        ff: 462,
        dsp: 82,
        bram: 0,
        carry: 1372,
        logic_cells: None,
        fits: false,
        limit: Some("82 SB_MAC16, the iCE40UP5K has 8".into()),
        fmax_mhz: None,
        fmax_goal_mhz: Some(24.0),
        critical_path: None,
        clocks_per_sample: 1,
        max_sample_rate_hz: None,
        folder: "place_and_route/top/ice40-up5k".into(),
    };
    let fitting = Placement {
        target: Target::Ice40Hx8k,
        lut4: Some(100),
        logic_cells: Some(768),
        fits: true,
        limit: None,
        fmax_mhz: Some(50.0),
        fmax_goal_mhz: Some(40.0),
        max_sample_rate_hz: Some(50e6),
        ..placement.clone()
    };
    let table = table(&[placement, fitting]);
    assert!(
        table.contains("| ice40-up5k | top | 3387 LUT4 | 462 | 82 | 0 | — | no: 82 SB_MAC16, the iCE40UP5K has 8 | — | 1 | — |"),
        "{table}"
    );
    assert!(
        table.contains("| ice40-hx8k | top | 100 LUT4 | 462 | 82 | 0 | 768 of 7680 (10 %) | yes | 50.00 (≥ 40) | 1 | 50.0 MS/s |"),
        "{table}"
    );
}

#[test]
fn a_design_too_large_is_told_from_nextpnrs_utilisation() {
    let log = "Info: Device utilisation:\n\
               Info: \t         ICESTORM_LC:  8509/ 7680   110%\n\
               Info: \t        ICESTORM_RAM:     0/   32     0%\n\
               Info: Placed 0 cells based on constraints.\n\
               ERROR: Failed to expand region (0, 0) |_> (33, 33) of 8509 ICESTORM_LCs\n";
    assert_eq!(
        over_capacity(log),
        Some(("ICESTORM_LC".to_string(), 8509, 7680))
    );
    assert_eq!(
        over_capacity("Info: \t ICESTORM_LC:  6800/ 7680    88%\n"),
        None
    );
}

#[test]
fn net_names_lose_the_wrapper_and_yosys_suffixes() {
    assert_eq!(
        net_name("dut.configured.kf.x1_reg_SB_DFFESR_Q[3]"),
        "kf.x1_reg"
    );
    assert_eq!(net_name("dut.combined[2]"), "combined[2]");
    assert_eq!(net_name("bias_a[0]"), "bias_a[0]");
    // ECP5's, from nextpnr-ecp5's reports of the KF, the sequencer and the serial chain: yosys's
    // cell suffixes, then nextpnr's own after a `$`.
    for (net, name) in [
        (
            "dut.configured.p2_s_TRELLIS_FF_Q_DI_CCU2C_S0_A1_LUT4_Z_D_MULT18X18D_P19_P9_MULT18X18D_P27_P1[0]",
            "p2_s",
        ),
        (
            "dut.configured.p2_s_TRELLIS_FF_Q_4_DI_CCU2C_S1$CCU2_FCI_INT",
            "p2_s",
        ),
        ("dut.configured.e[12]", "e[12]"),
        ("dut.done_b_L6MUX21_Z_SD[1]", "done_b"),
        ("window_done_LUT4_C_Z", "window_done"),
        (
            "dut.configured.engine.product_wide_TRELLIS_FF_Q_DI_MULT18X18D_P15_P24",
            "engine.product_wide",
        ),
        ("capture$TRELLIS_IO_IN", "capture"),
        ("dut.configured.x_PFUMX_Z_ALUT", "x"),
        // A net yosys made itself is kept whole rather than cut to nothing.
        ("dut.configured.$abc$1234$new_n56", "$abc$1234$new_n56"),
    ] {
        assert_eq!(net_name(net), name, "{net}");
    }
}
