"""cocotb test of gyrofx_mean_filter: `(y, kept)` checked against the gyrofx model wherever
`y_valid` is 1 (any latency)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline (gyrofx writes the block's: every clock for gyrofx_mean_filter, its latency
# for the sequential gyrofx_mean_filter_serial), or your RTL's through
# GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=1, min_clocks_per_sample=1)


async def run(dut, stimulus):
    model = tb.plan().mean_filter()
    scoreboard = tb.Scoreboard("(y, kept)")
    await tb.start(dut, ["x"])
    cocotb.start_soon(tb.monitor(dut, "y_valid", [("y", True), ("kept", False)], scoreboard))
    rng = tb.rng()
    for x, reset_first in stimulus:
        if reset_first:
            await tb.reset(dut, [scoreboard])
            model.reset()
        await tb.drive(dut, {"x": x})
        out = model.step(x)
        if out["y_valid"]:
            scoreboard.expect([out["y"], out["kept"]])
        await tb.take(dut, TIMING.idle_clocks + rng.choice([0, 0, 1, 3]))
    await tb.reset(dut, [scoreboard])
    tb.finish([scoreboard])


@cocotb.test()
async def random_with_gross_errors(dut):
    """Noisy samples with occasional gross errors (rejected), resets mid-block."""
    plan = tb.plan()
    low, high = tb.code_range(plan.mean_filter().input_format)
    rng = tb.rng()
    stimulus = []
    for _ in range(tb.samples(3000)):
        x = int(rng.gauss(high * 0.01, high * 0.002))
        if rng.random() < 0.03:
            x += rng.choice([-1, 1]) * high // 4
        stimulus.append((max(low, min(high, x)), rng.random() < 0.002))
    await run(dut, stimulus)


@cocotb.test()
async def directed_extremes(dut):
    """Blocks of full scale, alternating extremes (everything rejected) and zeros."""
    plan = tb.plan()
    window = plan.mean_filter().window
    low, high = tb.code_range(plan.mean_filter().input_format)
    stimulus = [(high, True)] + [(high, False)] * (window - 1)
    stimulus += [(low, False)] * window
    stimulus += [(high if i % 2 else low, False) for i in range(window)]
    stimulus += [(0, False)] * window
    await run(dut, stimulus)
