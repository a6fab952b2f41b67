"""cocotb test of the chain (gyrofx_top, or gyrofx_top_serial with architecture = "serial":
sequencer, estimator, calibration, KF): `rate_out` checked against the gyrofx chain model
wherever `out_valid` is 1 (any latency); the modes before each clock edge and the bias ports
`TIMING.output_clocks` clocks after the edge that takes each sample (the RTL's latency; `ce` one clock
later at the earliest)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=6, min_clocks_per_sample=6)


@cocotb.test()
async def two_gyros_under_mode_reversal(dut):
    """Both gyros' samples follow the chain's own modes (rate ± bias), with noise, a bandwidth
    change now and then, and full-scale bursts."""
    plan = tb.plan()
    chain = plan.chain()
    low, high = tb.code_range(plan.estimator().input_format)
    depth = len(plan.bandwidths_hz)
    rate_out = tb.Scoreboard("rate_out")
    registered = tb.Scoreboard("(bias_a, bias_b, estimated)")
    await tb.start(dut, ["bw_sel", "y_a", "y_b"])
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate_out", True)], rate_out))
    rng = tb.rng()
    bw_sel = 0
    bias = [high * 0.03, -high * 0.02]
    for k in range(tb.samples(2500)):
        if rng.random() < 0.005:
            bw_sel = rng.randrange(depth)
        modes = chain.next_modes()
        if rng.random() < 0.01:
            y = [rng.choice([low, high]) for _ in range(2)]
        else:
            y = [int((1 if m else -1) * high * 0.04 + b + rng.gauss(0, high * 0.002)) for m, b in zip(modes, bias)]
        y = [max(low, min(high, v)) for v in y]
        await tb.drive(dut, {"bw_sel": bw_sel, "y_a": y[0], "y_b": y[1]})
        want = chain.step(y[0], y[1], bw_sel)
        registered.compare(
            [want["mode_a"], want["mode_b"]],
            [tb.unsigned(dut.mode_a), tb.unsigned(dut.mode_b)],
            f"sample {k} modes",
        )
        if want["out_valid"]:
            rate_out.expect([want["rate_out"]])
        await tb.take_and_wait(dut, TIMING.output_clocks)
        registered.check(
            [want["bias_a"], want["bias_b"], want["estimated"]],
            [tb.signed(dut.bias_a), tb.signed(dut.bias_b), tb.unsigned(dut.estimated)],
            f"sample {k}",
        )
        await tb.idle(dut, rng.choice([0, 0, 0, 1]))
    await tb.reset(dut, [rate_out])
    tb.finish([rate_out, registered])
