"""cocotb helpers for testing RTL against the gyrofx model: clock and reset, the clock-enable
protocol of every gyrofx block, a DUT's timing, and a scoreboard that compares the DUT with the
model live.

Every generated package's cocotb tests (``cocotb/test_<block>.py``) are written on this module,
and a test of your own can be too::

    import cocotb
    import gyrofx
    import gyrofx.cocotb as tb

    TIMING = tb.Timing(latency_clocks=4, min_clocks_per_sample=3)   # the KF's, from its manifest

    @cocotb.test()
    async def steps(dut):
        kf = gyrofx.Plan.default().kf()
        scoreboard = tb.Scoreboard("rate_out")
        await tb.start(dut, ["z", "bw_sel"])
        cocotb.start_soon(tb.monitor(dut, "out_valid", [("rate_out", True)], scoreboard))
        for z in [1000, -1000, 0]:
            await tb.drive(dut, {"z": z, "bw_sel": 0})
            scoreboard.expect([kf.step(z, 0)])
            await tb.take(dut, TIMING.idle_clocks)
        await tb.reset(dut, [scoreboard])
        tb.finish([scoreboard])

The protocol: inputs and ``ce`` change after a falling edge of ``clk``; the rising edge with
``ce`` high takes the sample; ``rst`` is synchronous and active high.

Two ways to compare, chosen per output:

- **a valid-qualified stream** (``monitor`` + ``Scoreboard.expect``): outputs under a valid flag
  (``out_valid``, ``y_valid``) are compared in order whenever the flag is 1, so any latency
  passes, as long as the stream matches;
- **at a known clock** (``Scoreboard.check``): registered outputs without a valid flag are
  compared ``Timing.output_clocks`` clocks after the edge that takes the sample, and
  combinational ones before that edge.

Environment: ``GYROFX_PACKAGE`` (the package folder; default ``..``), ``GYROFX_COCOTB_SAMPLES``
(random samples per test; default per test), ``GYROFX_COCOTB_LATENCY_CLOCKS`` and
``GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE`` (a DUT whose pipeline differs from the reference RTL's;
see ``Timing``), ``GYROFX_COCOTB_FLIP_EXPECTED=<n>`` (flips bit 0 of the n-th expected value,
0-based, to show that the scoreboard catches one wrong bit).
"""

from __future__ import annotations

import collections
import os
import random
from typing import Any, Iterable, Mapping, Sequence

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, Timer

import gyrofx

#: The clock period of every gyrofx cocotb test, in ns.
CLOCK_PERIOD_NS = 10
#: Idle clocks before a reset, so that outputs still in a DUT's pipeline come out first.
DRAIN_CLOCKS = 16


def plan() -> gyrofx.Plan:
    """The plan the package was generated from (``$GYROFX_PACKAGE``, default ``..``: the block's
    folder is a test's working directory)."""
    return gyrofx.Plan.from_package(os.environ.get("GYROFX_PACKAGE", ".."))


def _environment_int(name: str, default: int) -> int:
    text = os.environ.get(name)
    if text is None or text == "":
        return default
    try:
        value = int(text)
    except ValueError:
        raise ValueError(f"{name}={text!r}: expected a whole number") from None
    if value < 0:
        raise ValueError(f"{name}={value}: expected 0 or more")
    return value


def samples(default: int) -> int:
    """Random samples a test drives: ``$GYROFX_COCOTB_SAMPLES``, else ``default``."""
    return _environment_int("GYROFX_COCOTB_SAMPLES", default)


def rng() -> random.Random:
    """Random stimulus, reproducible from cocotb's seed (``COCOTB_RANDOM_SEED=<n>`` repeats a
    run)."""
    return random.Random(cocotb.RANDOM_SEED)


def code_range(fmt: gyrofx.Format | str) -> tuple[int, int]:
    """The (min, max) codes of a ``gyrofx.Format`` or a format string such as ``s24.14``
    (signed, 24 bits) or ``u8.0`` (unsigned)."""
    if isinstance(fmt, gyrofx.Format):
        return fmt.min_code, fmt.max_code
    kind = fmt[:1]
    try:
        width = int(fmt[1:].split(".")[0])
    except ValueError:
        width = 0
    if width < 1:
        raise ValueError(f"format {fmt!r}: expected s<width>.<fraction> or u<width>.<fraction>")
    if kind in ("s", "S"):
        return -(1 << (width - 1)), (1 << (width - 1)) - 1
    if kind in ("u", "U"):
        return 0, (1 << width) - 1
    raise ValueError(f"format {fmt!r}: expected s<width>.<fraction> or u<width>.<fraction>")


class Timing:
    """A DUT's pipeline in clocks, in the manifest's terms: registered outputs show a sample
    ``latency_clocks`` clocks after the clock whose edge takes it (1: the next clock), and the
    next sample may come ``min_clocks_per_sample`` clocks after it (1: every clock).

    The package's tests are written with the reference RTL's values;
    ``$GYROFX_COCOTB_LATENCY_CLOCKS`` and ``$GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE`` (pytest's
    ``--latency-clocks`` and ``--min-clocks-per-sample``) replace them for RTL of your own whose
    pipeline differs. Outputs under a valid flag do not depend on either.
    """

    def __init__(self, latency_clocks: int, min_clocks_per_sample: int) -> None:
        self.latency_clocks = _environment_int("GYROFX_COCOTB_LATENCY_CLOCKS", latency_clocks)
        self.min_clocks_per_sample = _environment_int(
            "GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE", min_clocks_per_sample
        )
        if self.latency_clocks < 1 or self.min_clocks_per_sample < 1:
            raise ValueError(
                f"latency_clocks={self.latency_clocks}, min_clocks_per_sample="
                f"{self.min_clocks_per_sample}: both must be 1 or more"
            )

    @property
    def output_clocks(self) -> int:
        """Clocks after the edge that takes a sample until its registered outputs show."""
        return self.latency_clocks - 1

    @property
    def idle_clocks(self) -> int:
        """Clocks with ``ce`` low between samples at the fastest spacing."""
        return self.min_clocks_per_sample - 1

    def __repr__(self) -> str:
        return f"Timing(latency_clocks={self.latency_clocks}, min_clocks_per_sample={self.min_clocks_per_sample})"


def signed(handle: Any) -> int:
    """A port's value as a signed integer (two's complement by its width)."""
    return int(handle.value.to_signed())


def unsigned(handle: Any) -> int:
    """A port's value as an unsigned integer (a 1-bit port is a ``Logic``)."""
    return int(handle.value)


class Scoreboard:
    """Expected values in order, compared as the DUT produces them. A value is a tuple of ports'
    codes; mismatches are collected (the first ten logged) and reported by ``finish``."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.pending: collections.deque[tuple[int, ...]] = collections.deque()
        self.expected_count = 0
        self.compared = 0
        self.mismatches: list[str] = []
        self.flip = int(os.environ.get("GYROFX_COCOTB_FLIP_EXPECTED", "-1"))

    def _next(self, values: Iterable[int]) -> tuple[int, ...]:
        """The next expected value, bit 0 of its first field flipped when it is the
        ``$GYROFX_COCOTB_FLIP_EXPECTED``-th."""
        value = tuple(values)
        if self.expected_count == self.flip:
            value = (value[0] ^ 1,) + value[1:]
        self.expected_count += 1
        return value

    def expect(self, values: Iterable[int]) -> None:
        """An output the DUT will give under its valid flag, in order (see ``monitor``)."""
        self.pending.append(self._next(values))

    def check(self, expected: Iterable[int], actual: Iterable[int], where: str) -> None:
        """An output the DUT gives at a known clock (no valid flag): compared at once."""
        self.compare(self._next(expected), actual, where)

    def compare(self, expected: Iterable[int], actual: Iterable[int], where: str) -> None:
        """Compares without counting an expected value (not subject to the flip)."""
        self.compared += 1
        expected, actual = tuple(expected), tuple(actual)
        if expected != actual:
            self.mismatches.append(f"{self.name} {where}: expected {expected} actual {actual}")
            if len(self.mismatches) <= 10:
                cocotb.log.error("MISMATCH %s", self.mismatches[-1])

    def actual(self, values: Iterable[int], where: str) -> None:
        """A valid-qualified output of the DUT: compared with the oldest expected one."""
        if not self.pending:
            self.mismatches.append(f"{self.name} {where}: output {tuple(values)} with none expected")
            return
        self.compare(self.pending.popleft(), values, where)

    def check_drained(self, where: str) -> None:
        """Every expected value has come out."""
        if self.pending:
            self.mismatches.append(f"{self.name} {where}: {len(self.pending)} expected outputs never came")
            self.pending.clear()


async def monitor(dut: Any, valid: str, ports: Sequence[tuple[str, bool]], scoreboard: Scoreboard) -> None:
    """After every rising edge, a valid-qualified output goes to ``scoreboard``. ``ports`` are
    ``(name, is_signed)``: a signed port is two's complement, an index or a count is not.
    Start it with ``cocotb.start_soon``."""
    edge = 0
    while True:
        await RisingEdge(dut.clk)
        await ReadOnly()
        edge += 1
        if unsigned(getattr(dut, valid)) == 1:
            values = [(signed if is_signed else unsigned)(getattr(dut, port)) for port, is_signed in ports]
            scoreboard.actual(values, f"clock {edge}")


async def start(dut: Any, inputs: Iterable[str]) -> None:
    """Starts the clock and holds reset for 4 clocks with ``ce`` and every input 0."""
    # cocotb 2: start() schedules the clock's own task.
    Clock(dut.clk, CLOCK_PERIOD_NS, unit="ns").start()
    dut.rst.value = 1
    dut.ce.value = 0
    for name in inputs:
        getattr(dut, name).value = 0
    await ClockCycles(dut.clk, 4)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


async def reset(dut: Any, scoreboards: Iterable[Scoreboard]) -> None:
    """Drains the pipeline, then one reset clock; every scoreboard must have seen all that it
    expected."""
    await FallingEdge(dut.clk)
    dut.ce.value = 0
    await ClockCycles(dut.clk, DRAIN_CLOCKS)
    for scoreboard in scoreboards:
        scoreboard.check_drained("before a reset")
    await FallingEdge(dut.clk)
    dut.rst.value = 1
    await RisingEdge(dut.clk)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


async def drive(dut: Any, values: Mapping[str, int]) -> None:
    """Sets the inputs and ``ce`` for one sample (after a falling edge) and lets them settle:
    combinational outputs can be read when it returns."""
    await FallingEdge(dut.clk)
    for name, value in values.items():
        getattr(dut, name).value = value
    dut.ce.value = 1
    await ReadOnly()


async def take(dut: Any, idle_clocks: int) -> None:
    """The clock edge that takes the sample, then ``idle_clocks`` clocks with ``ce`` low."""
    await RisingEdge(dut.clk)
    await ReadOnly()
    await idle(dut, idle_clocks)


async def take_and_wait(dut: Any, clocks: int) -> None:
    """The clock edge that takes the sample, then ``clocks`` more with ``ce`` low, settled: where
    a DUT whose registered outputs come ``clocks`` clocks after that edge
    (``Timing.output_clocks``) shows the sample's outputs."""
    await RisingEdge(dut.clk)
    await idle(dut, clocks)
    await ReadOnly()


async def idle(dut: Any, clocks: int) -> None:
    """``clocks`` clocks with ``ce`` low: it ends after the ``clocks``-th rising edge. A long wait
    (a serial chain's thousand clocks a sample) passes in one timer instead of waking Python on
    every edge."""
    if clocks == 0:
        return
    await FallingEdge(dut.clk)
    dut.ce.value = 0
    if clocks > 4:
        # To a quarter period before the last falling edge (no edge to race with), then the
        # last rising edge.
        await Timer((clocks - 1) * CLOCK_PERIOD_NS - CLOCK_PERIOD_NS // 4, unit="ns")
        await RisingEdge(dut.clk)
    else:
        await ClockCycles(dut.clk, clocks)


def finish(scoreboards: Sequence[Scoreboard]) -> None:
    """Prints ``PASS n=<N>`` or ``FAIL mismatches=<M> n=<N>`` (as every gyrofx testbench does)
    and fails the test on a mismatch or when nothing was compared."""
    compared = sum(s.compared for s in scoreboards)
    mismatches = [m for s in scoreboards for m in s.mismatches]
    if mismatches:
        print(f"FAIL mismatches={len(mismatches)} n={compared}", flush=True)
        raise AssertionError(f"{len(mismatches)} mismatches, first: {mismatches[0]}")
    assert compared > 0, "nothing was compared"
    print(f"PASS n={compared}", flush=True)
