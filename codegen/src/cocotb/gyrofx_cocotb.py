"""Shared by the package's cocotb tests: clock, reset, the clock-enable protocol, and a
scoreboard that checks the DUT against the gyrofx Python model live.

The model is `gyrofx` (pip install the gyrofx repository's python/ folder): the same Rust code
that wrote this package's vectors, built from this package's manifest, so a passing test means
bit-exact agreement with the vectors' model. Outputs qualified by a valid flag (`out_valid`,
`y_valid`) are compared as a stream, whatever the latency; a DUT that keeps the reference RTL's
timing is also checked on its combinational outputs (before the clock edge that takes the
sample) and its registered outputs without a valid flag (as many clocks after the sample as the
RTL's pipeline takes).

Environment: GYROFX_PACKAGE (the package folder; default ..), GYROFX_COCOTB_SAMPLES (random
samples per test; default per block), GYROFX_COCOTB_FLIP_EXPECTED=<n> flips bit 0 of the n-th
expected value (0-based) to show the scoreboard catches one wrong bit.
"""

import collections
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge, Timer

import gyrofx

CLOCK_PERIOD_NS = 10
# Idle clocks before a reset, so outputs still in a DUT's pipeline come out first.
DRAIN_CLOCKS = 16


def plan():
    """The plan this package was generated from."""
    return gyrofx.Plan.from_package(os.environ.get("GYROFX_PACKAGE", ".."))


def samples(default):
    return int(os.environ.get("GYROFX_COCOTB_SAMPLES", default))


def rng():
    """Random stimulus, reproducible from cocotb's seed (RANDOM_SEED=<n> repeats a run)."""
    return random.Random(cocotb.RANDOM_SEED)


def code_range(fmt):
    """(min, max) codes of a format string such as s24.14."""
    width = int(fmt[1:].split(".")[0])
    if fmt[0] in "sS":
        return -(1 << (width - 1)), (1 << (width - 1)) - 1
    return 0, (1 << width) - 1


def signed(handle):
    """A port's value as a signed integer (two's complement by its width)."""
    value = handle.value
    return value.to_signed() if hasattr(value, "to_signed") else int(value)


def unsigned(handle):
    """A port's value as an unsigned integer (a 1-bit port is a Logic)."""
    value = handle.value
    return value.to_unsigned() if hasattr(value, "to_unsigned") else int(value)


class Scoreboard:
    """Expected values in order, compared as the DUT produces them."""

    def __init__(self, name):
        self.name = name
        self.pending = collections.deque()
        self.expected_count = 0
        self.compared = 0
        self.mismatches = []
        self.flip = int(os.environ.get("GYROFX_COCOTB_FLIP_EXPECTED", "-1"))

    def _next(self, values):
        """The next expected value, bit 0 of its first field flipped when it is the
        GYROFX_COCOTB_FLIP_EXPECTED-th."""
        values = tuple(values)
        if self.expected_count == self.flip:
            values = (values[0] ^ 1,) + values[1:]
        self.expected_count += 1
        return values

    def expect(self, values):
        """An output the DUT will give under its valid flag, in order."""
        self.pending.append(self._next(values))

    def check(self, expected, actual, where):
        """An output the DUT gives at a known clock (no valid flag): compared at once."""
        self.compare(self._next(expected), actual, where)

    def compare(self, expected, actual, where):
        self.compared += 1
        if tuple(expected) != tuple(actual):
            self.mismatches.append(f"{self.name} {where}: expected {tuple(expected)} actual {tuple(actual)}")
            if len(self.mismatches) <= 10:
                cocotb.log.error("MISMATCH %s", self.mismatches[-1])

    def actual(self, values, where):
        """A valid-qualified output of the DUT: compared with the oldest expected one."""
        if not self.pending:
            self.mismatches.append(f"{self.name} {where}: output {tuple(values)} with none expected")
            return
        self.compare(self.pending.popleft(), values, where)

    def check_drained(self, where):
        if self.pending:
            self.mismatches.append(f"{self.name} {where}: {len(self.pending)} expected outputs never came")
            self.pending.clear()


async def monitor(dut, valid, ports, scoreboard):
    """After every rising edge, a valid-qualified output goes to the scoreboard. `ports` are
    `(name, is_signed)`: a signed port is two's complement, an index or count is not."""
    edge = 0
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        edge += 1
        if unsigned(getattr(dut, valid)) == 1:
            values = [(signed if is_signed else unsigned)(getattr(dut, p)) for p, is_signed in ports]
            scoreboard.actual(values, f"clock {edge}")


async def start(dut, inputs):
    """Starts the clock and holds reset for 4 clocks with every input 0."""
    cocotb.start_soon(Clock(dut.clk, CLOCK_PERIOD_NS, unit="ns").start())
    dut.rst.value = 1
    dut.ce.value = 0
    for name in inputs:
        getattr(dut, name).value = 0
    for _ in range(4):
        await RisingEdge(dut.clk)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


async def reset(dut, scoreboards):
    """Drains, then one reset clock; every scoreboard must have seen all it expected."""
    await FallingEdge(dut.clk)
    dut.ce.value = 0
    for _ in range(DRAIN_CLOCKS):
        await RisingEdge(dut.clk)
    for scoreboard in scoreboards:
        scoreboard.check_drained("before a reset")
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    await RisingEdge(dut.clk)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


async def drive(dut, values):
    """Sets the inputs and ce for one sample (after a falling edge) and lets them settle."""
    await FallingEdge(dut.clk)
    for name, value in values.items():
        getattr(dut, name).value = value
    dut.ce.value = 1
    await ReadOnly()


async def take(dut, idle_clocks):
    """The clock edge that takes the sample, then `idle_clocks` clocks with ce low."""
    await RisingEdge(dut.clk)
    await ReadOnly()
    await idle(dut, idle_clocks)


async def take_and_wait(dut, clocks):
    """The clock edge that takes the sample, then `clocks` more with ce low, settled: where a
    block whose registered outputs come `clocks` clocks after that edge (the gyro loop's 3, the
    system's 4) shows the sample's outputs."""
    await RisingEdge(dut.clk)
    await idle(dut, clocks)
    await ReadOnly()


async def idle(dut, clocks):
    """`clocks` clocks with ce low: it ends after the `clocks`-th rising edge (a long wait, as the
    serial chain's, passes most of them in one timer)."""
    if clocks > 4:
        await FallingEdge(dut.clk)
        dut.ce.value = 0
        # To a quarter period before the last falling edge (no edge to race with), then the
        # last rising edge.
        await Timer((clocks - 1) * CLOCK_PERIOD_NS - CLOCK_PERIOD_NS // 4, unit="ns")
        await RisingEdge(dut.clk)
        return
    for _ in range(clocks):
        await FallingEdge(dut.clk)
        dut.ce.value = 0
        await RisingEdge(dut.clk)


def finish(scoreboards):
    """Prints PASS n=<N> or FAIL mismatches=<M> n=<N> (as every gyrofx testbench does) and
    fails the test on a mismatch."""
    compared = sum(s.compared for s in scoreboards)
    mismatches = [m for s in scoreboards for m in s.mismatches]
    if mismatches:
        print(f"FAIL mismatches={len(mismatches)} n={compared}", flush=True)
        raise AssertionError(f"{len(mismatches)} mismatches, first: {mismatches[0]}")
    assert compared > 0, "nothing was compared"
    print(f"PASS n={compared}", flush=True)
