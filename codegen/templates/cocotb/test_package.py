"""The package's cocotb tests on cocotb's Python runner (cocotb_tools.runner), one pytest test
per cocotb test: `pytest cocotb` from the package folder (options: conftest.py, or
`pytest cocotb --help`). The same tests run through make: `make cocotb-<block>`.

Each block's RTL is built once per session (cocotb/sim_build/<simulator>/<block>/) and each of its
cocotb tests runs in the block's folder (its ROM files and parameters are there) with the
package's plan as the model (GYROFX_PACKAGE). Needs cocotb 2.x and the gyrofx Python package.
"""

import json
import os
import pathlib
import sys

import pytest
from cocotb_tools.runner import get_runner

FOLDER = pathlib.Path(__file__).resolve().parent
PACKAGE = FOLDER.parent
# Every block with a cocotb test: its wrapper, top, test module and tests, and the RTL sources.
TESTS = json.loads((FOLDER / "tests.json").read_text())
if str(FOLDER) not in sys.path:
    sys.path.insert(0, str(FOLDER))

CASES = [(block, test) for block in TESTS["blocks"] for test in block["tests"]]


def _option(config, name):
    return config.getoption(name)


def _sources(config, block):
    """Your --rtl files, or the package's RTL; the wrapper unless you name your own top."""
    groups = _option(config, "rtl")
    if groups:
        sources = [pathlib.Path(path).resolve() for group in groups for path in group]
        for path in sources:
            if not path.is_file():
                pytest.fail(f"--rtl {path}: no such file", pytrace=False)
    else:
        sources = [PACKAGE / path for path in TESTS["sources"]]
    if _option(config, "toplevel") is None:
        sources.append(PACKAGE / block["wrapper"])
    return sources


def _parameters(config):
    parameters = {}
    for item in _option(config, "parameter"):
        name, equals, value = item.partition("=")
        if not equals or not name:
            pytest.fail(f"--parameter {item!r}: expected NAME=VALUE", pytrace=False)
        parameters[name] = value
    return parameters


@pytest.fixture(scope="session")
def built(request):
    """Builds a block's RTL the first time one of its tests runs; returns (runner, top)."""
    config = request.config
    simulator = _option(config, "sim") or os.environ.get("SIM", "icarus")
    runners = {}

    def build(block):
        if block["name"] not in runners:
            top = _option(config, "toplevel") or block["toplevel"]
            runner = get_runner(simulator)
            runner.build(
                sources=_sources(config, block),
                includes=[PACKAGE / block["name"]],
                parameters=_parameters(config),
                hdl_toplevel=top,
                build_dir=FOLDER / "sim_build" / simulator / block["name"],
                always=True,
                waves=_option(config, "waves"),
            )
            runners[block["name"]] = (runner, top)
        return runners[block["name"]]

    return build


def _environment(config):
    environment = {"GYROFX_PACKAGE": str(PACKAGE)}
    for option, variable in [
        ("latency_clocks", "GYROFX_COCOTB_LATENCY_CLOCKS"),
        ("min_clocks_per_sample", "GYROFX_COCOTB_MIN_CLOCKS_PER_SAMPLE"),
        ("samples", "GYROFX_COCOTB_SAMPLES"),
    ]:
        value = _option(config, option)
        if value is not None:
            environment[variable] = str(value)
    return environment


@pytest.mark.parametrize("block, test", CASES, ids=[f"{b['name']}-{t}" for b, t in CASES])
def test_cocotb(request, built, block, test):
    config = request.config
    runner, top = built(block)
    results = FOLDER / "sim_build" / "results" / f"{block['name']}-{test}.xml"
    results.parent.mkdir(parents=True, exist_ok=True)
    runner.test(
        test_module=block["module"],
        hdl_toplevel=top,
        testcase=test,
        seed=_option(config, "seed"),
        test_dir=PACKAGE / block["name"],
        results_xml=str(results),
        extra_env=_environment(config),
        waves=_option(config, "waves"),
    )
