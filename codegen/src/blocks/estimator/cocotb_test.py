"""cocotb test of gyrofx_bias_estimator: the slot from the gyrofx sequencer model, random rates
with a bias per gyro; `(bias_a, bias_b, estimated)` checked `TIMING.output_clocks` clocks after the
edge that takes each sample (the reference RTL's 5; `ce` every 6th clock at most)."""

import cocotb

import gyrofx.cocotb as tb

# The DUT's pipeline: the reference RTL's (gyrofx writes this package's values), or your RTL's
# through GYROFX_COCOTB_LATENCY_CLOCKS / GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE.
TIMING = tb.Timing(latency_clocks=6, min_clocks_per_sample=6)
SLOT = ["blank_a", "blank_b", "done_a", "done_b", "interval_a", "interval_b", "window_done"]


async def run(dut, rates):
    plan = tb.plan()
    estimator, sequencer = plan.estimator(), plan.sequencer()
    scoreboard = tb.Scoreboard("(bias_a, bias_b, estimated)")
    await tb.start(dut, ["y_a", "y_b"] + SLOT)
    rng = tb.rng()
    for k, (y_a, y_b) in enumerate(rates):
        slot = sequencer.step()
        inputs = {"y_a": y_a, "y_b": y_b, **{p: slot[p] for p in SLOT}}
        await tb.drive(dut, inputs)
        want = estimator.step(*(inputs[p] for p in ["y_a", "y_b"] + SLOT))
        expected = [want["bias_a"], want["bias_b"], want["estimated"]]
        await tb.take_and_wait(dut, TIMING.output_clocks)
        actual = [tb.signed(dut.bias_a), tb.signed(dut.bias_b), tb.unsigned(dut.estimated)]
        scoreboard.check(expected, actual, f"sample {k}")
        await tb.idle(dut, rng.choice([0, 0, 0, 1]))
    tb.finish([scoreboard])


@cocotb.test()
async def mode_reversed_rates(dut):
    """A constant rate plus each gyro's bias, sign-flipped with its mode, with noise."""
    plan = tb.plan()
    low, high = tb.code_range(plan.estimator().input_format)
    modes = plan.sequencer()
    rng = tb.rng()
    rates = []
    bias = [high * 0.02, -high * 0.01]
    for _ in range(tb.samples(2000)):
        slot = modes.step()
        signs = [1 if slot["mode_a"] else -1, 1 if slot["mode_b"] else -1]
        y = [int(s * high * 0.05 + b + rng.gauss(0, high * 0.001)) for s, b in zip(signs, bias)]
        rates.append(tuple(max(low, min(high, v)) for v in y))
    await run(dut, rates)


@cocotb.test()
async def full_scale(dut):
    """Full-scale and opposite full-scale inputs: the estimator's saturating corners."""
    plan = tb.plan()
    low, high = tb.code_range(plan.estimator().input_format)
    rng = tb.rng()
    rates = [(rng.choice([low, high]), rng.choice([low, high])) for _ in range(tb.samples(1500))]
    await run(dut, rates)
