"""A cocotb test of your own with the gyrofx model as its scoreboard: the KF of a generated
package, driven with a few steps and a ramp, every `rate_out` under `out_valid` compared with
`gyrofx`'s model of the same plan.

Run it with `python -m pytest examples/cocotb_kf` and GYROFX_PACKAGE naming a package (see
test_runner.py); the user guide's "Your first cocotb test" walks through it.
"""

import os

import cocotb

import gyrofx
import gyrofx.cocotb as tb


@cocotb.test()
async def steps_and_a_ramp(dut):
    plan = gyrofx.Plan.from_package(os.environ["GYROFX_PACKAGE"])
    kf = plan.kf()
    # The RTL's timing from the model: outputs latency_clocks after a sample, a sample at most
    # every min_clocks_per_sample clocks.
    timing = tb.Timing(kf.latency_clocks, kf.min_clocks_per_sample)
    low, high = tb.code_range(gyrofx.Format(kf.input_format))
    scoreboard = tb.Scoreboard("rate_out")
    await tb.start(dut, ["z", "bw_sel"])
    cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate_out", True)], scoreboard))
    stimulus = [high // 100] * 200 + [-high // 50] * 200 + [low + k * (high // 100) for k in range(200)]
    for z in stimulus:
        await tb.drive(dut, {"z": z, "bw_sel": 1})
        scoreboard.expect([kf.step(z, 1)["rate_out"]])
        await tb.take(dut, timing.idle_clocks)
    await tb.reset(dut, [scoreboard])
    tb.finish([scoreboard])
