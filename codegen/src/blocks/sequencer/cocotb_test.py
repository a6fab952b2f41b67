"""cocotb test of gyrofx_sequencer: its combinational slot outputs checked against the gyrofx
model on every clock that takes a sample (before the edge), over several cycles with resets."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=1, min_clocks_per_sample=1)
PORTS = ["mode_a", "mode_b", "blank_a", "blank_b", "interval_a", "interval_b", "done_a", "done_b", "window_done"]


@cocotb.test()
async def cycles_with_idle_clocks_and_resets(dut):
    sequencer = tb.plan().sequencer()
    scoreboard = tb.Scoreboard("slot")
    await tb.start(dut, [])
    rng = tb.rng()
    for k in range(tb.samples(2500)):
        if k and rng.random() < 0.001:
            await tb.reset(dut, [scoreboard])
            sequencer.reset()
        await tb.drive(dut, {})
        want = sequencer.step()
        scoreboard.check([want[p] for p in PORTS], [tb.unsigned(getattr(dut, p)) for p in PORTS], f"sample {k}")
        await tb.take(dut, TIMING.idle_clocks + rng.choice([0, 0, 0, 1]))
    tb.finish([scoreboard])
