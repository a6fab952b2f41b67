"""cocotb test of gyrofx_gyro_loop: the DUT closed around gyrofx's simulated resonator (its own
DAC codes drive the resonator, whose ADC codes come back), then open-loop random codes with mode
switches and resets. `dac_x`, `dac_y`, `locked` are checked at the DUT's timing (`TIMING`: the
parallel loop's outputs 3 clocks after the edge that takes the sample, `ce` every 4th clock at
most; the folded loop's after its schedule); `rate` and `quadrature` as a stream wherever
`out_valid` is 1 (any latency)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=4, min_clocks_per_sample=4)
INPUTS = ["adc_x", "adc_y", "mode"]


async def step(dut, loop, stream, registered, k, adc, mode):
    """One sample through the DUT and the model; returns the model's outputs and the DUT's DAC
    codes."""
    await tb.drive(dut, {"adc_x": adc[0], "adc_y": adc[1], "mode": mode})
    want = loop.step(adc[0], adc[1], mode)
    if want["out_valid"]:
        stream.expect([want["rate"], want["quadrature"]])
    await tb.take_and_wait(dut, TIMING.output_clocks)
    dac = [tb.signed(dut.dac_x), tb.signed(dut.dac_y)]
    registered.check(
        [want["dac_x"], want["dac_y"], want["locked"]],
        dac + [tb.unsigned(dut.locked)],
        f"sample {k}",
    )
    return want, dac


@cocotb.test()
async def closed_around_the_resonator(dut):
    """From reset in normal mode (the drive loop pulls in and the AGC builds the amplitude),
    then a switch to reverse mode: lock acquisition and mode reversal with the DUT in the loop."""
    plan = tb.plan()
    loop = plan.gyro_loop()
    resonator = plan.resonator("a")
    resonator.set_rate_dps(10.0)
    stream = tb.Scoreboard("(rate, quadrature)")
    registered = tb.Scoreboard("(dac_x, dac_y, locked)")
    await tb.start(dut, INPUTS)
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate", True), ("quadrature", True)], stream))
    # Long enough in normal mode for the default design to lock (the vectors' run: about
    # 15 500 samples), then the switch and the start of the re-acquisition (as long as the
    # normal part, for a short run).
    normal = tb.samples(17000)
    adc, mode = (0, 0), 1
    for k in range(normal + min(3000, normal)):
        if k == normal:
            cocotb.log.info("locked before the switch: %d", want["locked"])
            mode = 0
            resonator.set_mode(mode)
        want, dac = await step(dut, loop, stream, registered, k, adc, mode)
        read = resonator.step(dac[0], dac[1])
        adc = (read["adc_x"], read["adc_y"])
    await tb.reset(dut, [stream])
    tb.finish([stream, registered])


@cocotb.test()
async def random_codes_switches_and_resets(dut):
    """Random ADC codes (Gaussian, a fifth of full scale, and full-scale bursts), a mode switch
    every few hundred samples, a reset now and then, idle clocks between samples."""
    plan = tb.plan()
    loop = plan.gyro_loop()
    low, high = tb.code_range(loop.adc_format)
    stream = tb.Scoreboard("(rate, quadrature)")
    registered = tb.Scoreboard("(dac_x, dac_y, locked)")
    await tb.start(dut, INPUTS)
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate", True), ("quadrature", True)], stream))
    rng = tb.rng()
    mode = 1
    for k in range(tb.samples(3000)):
        if rng.random() < 0.003:
            await tb.reset(dut, [stream])
            loop.reset()
        if rng.random() < 0.004:
            mode ^= 1
        if rng.random() < 0.01:
            adc = [rng.choice([low, high]) for _ in range(2)]
        else:
            adc = [int(rng.gauss(0, high * 0.2)) for _ in range(2)]
        adc = [max(low, min(high, v)) for v in adc]
        await step(dut, loop, stream, registered, k, adc, mode)
        await tb.idle(dut, rng.choice([0, 0, 0, 1]))
    await tb.reset(dut, [stream])
    tb.finish([stream, registered])
