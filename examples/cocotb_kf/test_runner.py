"""Runs test_my_kf.py on a package's KF RTL with cocotb's Python runner (Icarus by default):

    gyrofx generate --out pkg --blocks kf
    GYROFX_PACKAGE=pkg python -m pytest examples/cocotb_kf -s

The package's own wrapper `cocotb/cocotb_gyrofx_kf.v` sets the KF's parameters from
`kf/kf_params.vh`; its ROM file is read from the kf/ folder, where the test runs.
"""

import json
import os
import pathlib
import sys

from cocotb_tools.runner import get_runner

HERE = pathlib.Path(__file__).resolve().parent
# The runner hands the simulator this interpreter's sys.path: test_my_kf is found here.
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))


def test_my_kf():
    package = pathlib.Path(os.environ["GYROFX_PACKAGE"]).resolve()
    tests = json.loads((package / "cocotb" / "tests.json").read_text())
    kf = next(block for block in tests["blocks"] if block["name"] == "kf")
    runner = get_runner(os.environ.get("SIM", "icarus"))
    # Inside the package's build outputs (its marker allows cocotb/sim_build/).
    build = package / "cocotb" / "sim_build" / "my_kf"
    runner.build(
        sources=[package / path for path in tests["sources"]] + [package / kf["wrapper"]],
        includes=[package / "kf"],
        hdl_toplevel=kf["toplevel"],
        build_dir=build,
        always=True,
    )
    runner.test(
        test_module="test_my_kf",
        hdl_toplevel=kf["toplevel"],
        test_dir=package / "kf",
        build_dir=build,
        results_xml=str(build / "results.xml"),
        extra_env={"GYROFX_PACKAGE": str(package)},
    )
