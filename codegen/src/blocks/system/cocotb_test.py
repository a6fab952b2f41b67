"""cocotb test of gyrofx_system: the DUT closed around both gyros' simulated resonators (its own
DAC codes drive them, their ADC codes come back; each resonator's pick-offs follow the mode its
loop takes). Start-up with `enable` low, then mode reversal under the chain's sequencer through
an estimator window and a bandwidth change. The DAC codes, lock flags, the chain's modes, bias
ports and `estimated` are checked at the DUT's timing (`TIMING`: gyrofx_system's 9 clocks after
the edge that takes the sample, the loop's show after 3 and hold, the chain's after the loop's 4
stages and its own pipeline; gyrofx_system_serial's after the folded loops' schedule and a clock,
its chain's outputs `CHAIN_DELAY_SAMPLES` samples later, as `plan.system()` has them); `rate_out`
as a stream wherever `out_valid` is 1 (any latency)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=10, min_clocks_per_sample=10)
ADC_PORTS = ["adc_a_x", "adc_a_y", "adc_b_x", "adc_b_y"]
REGISTERED = ["dac_a_x", "dac_a_y", "dac_b_x", "dac_b_y", "locked_a", "locked_b", "mode_a", "mode_b",
              "bias_a", "bias_b", "estimated"]
SIGNED = {"dac_a_x", "dac_a_y", "dac_b_x", "dac_b_y", "bias_a", "bias_b"}


@cocotb.test()
async def closed_around_both_resonators(dut):
    plan = tb.plan()
    system = plan.system()
    resonators = [plan.resonator("a"), plan.resonator("b")]
    for resonator in resonators:
        resonator.set_rate_dps(10.0)
    depth = len(plan.bandwidths_hz)
    stream = tb.Scoreboard("rate_out")
    registered = tb.Scoreboard("(" + ", ".join(REGISTERED) + ")")
    await tb.start(dut, ["enable", "bw_sel"] + ADC_PORTS)
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate_out", True)], stream))
    startup = tb.samples(2000)
    window = system.window * system.decimation
    total = startup + window + 2 * system.decimation
    adc = [0, 0, 0, 0]
    taken = [1, 1]
    for k in range(total):
        enable = int(k >= startup)
        bw_sel = min(depth - 1, int(k >= startup + window // 2))
        modes = system.next_modes() if enable else (1, 1)
        for g in range(2):
            if modes[g] != taken[g]:
                resonators[g].set_mode(modes[g])
                taken[g] = modes[g]
        await tb.drive(dut, dict(zip(ADC_PORTS, adc), enable=enable, bw_sel=bw_sel))
        want = system.step(*adc, enable=enable, bw_sel=bw_sel)
        if want["out_valid"]:
            stream.expect([want["rate_out"]])
        await tb.take_and_wait(dut, TIMING.output_clocks)
        actual = {p: (tb.signed if p in SIGNED else tb.unsigned)(getattr(dut, p)) for p in REGISTERED}
        registered.check([want[p] for p in REGISTERED], [actual[p] for p in REGISTERED], f"sample {k}")
        read = [resonators[0].step(actual["dac_a_x"], actual["dac_a_y"]),
                resonators[1].step(actual["dac_b_x"], actual["dac_b_y"])]
        adc = [r[port] for r in read for port in ("adc_x", "adc_y")]
    assert want["estimated"] == 1, "the run covers a whole estimator window"
    await tb.reset(dut, [stream])
    tb.finish([stream, registered])
