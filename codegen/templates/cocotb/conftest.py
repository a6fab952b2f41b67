"""pytest's side of the package's cocotb tests (test_package.py): the options that pick the
simulator, the seed, and RTL of your own in place of the package's reference RTL.

    pytest cocotb                                    # every block's cocotb tests, reference RTL
    pytest cocotb -k kf                              # the KF's tests only
    pytest cocotb -k kf --rtl my_kf.v hdl/gyrofx_quantize.v hdl/gyrofx_spacing_check.v
    pytest cocotb -k kf --rtl hdl/*.v my_top.v --toplevel my_top --latency-clocks 5
    pytest cocotb --junitxml=cocotb.xml              # JUnit XML, one testcase per cocotb test

Put the folder first: --rtl takes every path after it.
"""

import json
import pathlib

FOLDER = pathlib.Path(__file__).resolve().parent
TESTS = json.loads((FOLDER / "tests.json").read_text())

# The blocks' test modules are cocotb's (run inside the simulator), not pytest's.
collect_ignore = [block["module"] + ".py" for block in TESTS["blocks"]]


def pytest_addoption(parser):
    group = parser.getgroup("gyrofx", "gyrofx cocotb tests")
    group.addoption("--sim", default=None,
                    help="cocotb's simulator (default: $SIM, else icarus; Verilator needs 5.036 or later)")
    group.addoption("--rtl", action="append", nargs="+", default=None, metavar="FILE",
                    help="Verilog files to test instead of the package's hdl/ (your RTL: the same "
                         "module names and ports, or your own top with --toplevel)")
    group.addoption("--toplevel", default=None,
                    help="the top module in your --rtl files (default: the package's wrapper "
                         "cocotb_<module>.v, compiled with your files)")
    group.addoption("--parameter", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the top module (repeat it for more)")
    group.addoption("--latency-clocks", type=int, default=None,
                    help="your RTL's latency if not the reference's (clocks from a sample's ce to its "
                         "registered outputs, as in manifest.json)")
    group.addoption("--min-clocks-per-sample", type=int, default=None,
                    help="your RTL's fastest sample spacing if not the reference's")
    group.addoption("--samples", type=int, default=None,
                    help="random samples per test (default: each test's own)")
    group.addoption("--seed", type=int, default=1, help="cocotb's random seed (default 1)")
    group.addoption("--waves", action="store_true", help="dump waveforms (Icarus: an FST)")
