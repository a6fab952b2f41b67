"""cocotb test of gyrofx_kf: random and directed stimulus, `rate_out` checked against the gyrofx
model wherever `out_valid` is 1 (any latency)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=4, min_clocks_per_sample=3)


async def run(dut, stimulus):
    """Drives (z, bw_sel, reset-before) samples; returns the scoreboard."""
    kf = tb.plan().kf()
    scoreboard = tb.Scoreboard("rate_out")
    await tb.start(dut, ["z", "bw_sel"])
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate_out", True)], scoreboard))
    rng = tb.rng()
    for z, bw_sel, reset_first in stimulus:
        if reset_first:
            await tb.reset(dut, [scoreboard])
            kf.reset()
        await tb.drive(dut, {"z": z, "bw_sel": bw_sel})
        scoreboard.expect([kf.step(z, bw_sel)["rate_out"]])
        await tb.take(dut, TIMING.idle_clocks + rng.choice([0, 0, 0, 1, 2]))
    await tb.reset(dut, [scoreboard])
    tb.finish([scoreboard])


@cocotb.test()
async def random_stimulus(dut):
    """Gaussian rates around a random offset, bandwidth changes in runs, resets now and then."""
    plan = tb.plan()
    low, high = tb.code_range(plan.kf().input_format)
    depth = len(plan.bandwidths_hz)
    rng = tb.rng()
    stimulus = []
    bw_sel = 0
    for k in range(tb.samples(3000)):
        if rng.random() < 0.01:
            bw_sel = rng.randrange(depth)
        z = int(rng.gauss(high * 0.05, high * 0.02))
        stimulus.append((max(low, min(high, z)), bw_sel, rng.random() < 0.002))
    await run(dut, stimulus)


@cocotb.test()
async def directed_full_scale(dut):
    """Full-scale steps both ways at every bandwidth, from reset: the saturating corners."""
    plan = tb.plan()
    low, high = tb.code_range(plan.kf().input_format)
    stimulus = []
    for bw_sel in range(len(plan.bandwidths_hz)):
        for i, z in enumerate([high] * 150 + [low] * 150 + [0] * 20 + [1, -1, high, low]):
            stimulus.append((z, bw_sel, i == 0))
    await run(dut, stimulus)
