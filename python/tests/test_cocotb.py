"""The package's cocotb tests: they pass on the reference RTL in Icarus, `gyrofx verify --sim
cocotb` runs them, and they fail on one flipped expected bit and on a mutated RTL line."""

import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

from conftest import cli, run_cli

# The longest runs first: pytest-xdist hands the tests out in this order (scripts/test.sh runs a
# worker per core), and a long one handed out last would run alone at the end.
BLOCKS = ["system", "gyro_loop", "estimator", "kf", "top", "mean_filter", "sequencer"]


def environment(**extra):
    """PATH with this interpreter's bin/ first: cocotb-config and the python3 that imports
    gyrofx and cocotb."""
    env = dict(os.environ)
    env["PATH"] = str(pathlib.Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env.update(extra)
    return env


def make(package, target, **extra):
    return subprocess.run(
        ["make", "--no-print-directory", "-C", str(package), target],
        capture_output=True,
        text=True,
        env=environment(**extra),
    )


def summary(result):
    return [line for line in result.stdout.splitlines() if line.startswith(("PASS", "FAIL"))]


def assert_passes(result):
    """Every scoreboard passed, having checked at least one value."""
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    lines = summary(result)
    assert lines and all(line.startswith("PASS n=") for line in lines), lines
    assert all(int(line.split("n=")[1].split()[0]) > 0 for line in lines)


def assert_fails(result, scoreboards):
    """The run failed with one mismatch on each of `scoreboards` scoreboards."""
    assert result.returncode != 0
    assert any(line.startswith(f"FAIL mismatches={scoreboards} ") for line in summary(result)), summary(result)


def test_the_serial_blocks_pass_it_and_a_flipped_bit_fails_it(tmp_path):
    # architecture = "serial": gyrofx_top_serial and gyrofx_mean_filter_serial, their latency
    # written into the tests by gyrofx.
    config = tmp_path / "serial.toml"
    config.write_text('architecture = "serial"\n[sequencer]\ninterval_length = 60\nblank = 30\n')
    folder = tmp_path / "out"
    run_cli("generate", "--config", str(config), "--out", str(folder), "--samples", "800", "--quiet")
    manifest = json.loads((folder / "manifest.json").read_text())
    # gyrofx writes the serial chain's pipeline into the test.
    latency = manifest["chain"]["latency_clocks"]
    assert latency > 1000
    timing = f"TIMING = tb.Timing(latency_clocks={latency}, min_clocks_per_sample={latency})\n"
    assert timing in (folder / "cocotb" / "test_top.py").read_text()
    assert_passes(make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="400"))
    # Two scoreboards: rate_out and the registered bias ports. The flip comes at the 40th value
    # of each; 150 samples reach it on both (rate_out is valid outside the blanking only). Each
    # sample takes over 1000 clocks of cocotb's Python clock: 400 here would add 35 s.
    assert_fails(make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="150", GYROFX_COCOTB_FLIP_EXPECTED="40"), 2)
    # The sequential mean filter beside it: the next sample after its latency.
    assert (folder / "cocotb" / "cocotb_gyrofx_mean_filter_serial.v").exists()
    spacing = manifest["mean_filter"]["min_clocks_per_sample"]
    assert spacing > 1
    assert f", min_clocks_per_sample={spacing})\n" in (folder / "cocotb" / "test_mean_filter.py").read_text()
    assert_passes(make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000"))
    assert_fails(make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000", GYROFX_COCOTB_FLIP_EXPECTED="40"), 1)
    # The folded gyro loop: the next sample after its schedule's clocks.
    loop = manifest["gyro_loop"]
    assert loop["architecture"] == "serial"
    spacing = loop["min_clocks_per_sample"]
    assert 4 < spacing <= 120
    assert f", min_clocks_per_sample={spacing})\n" in (folder / "cocotb" / "test_gyro_loop.py").read_text()
    assert_passes(make(folder, "cocotb-gyro_loop", GYROFX_COCOTB_SAMPLES="300"))
    assert_fails(make(folder, "cocotb-gyro_loop", GYROFX_COCOTB_SAMPLES="300", GYROFX_COCOTB_FLIP_EXPECTED="40"), 1)
    # The folded system: both gyros' loops on one folded datapath, every output the clock after
    # its longest sample (within 120 clocks: a 200 kHz ADC at 24 MHz), the chain's
    # chain_delay_samples later, as the Python System (the test's model) has them. Its run is
    # an estimator window whatever GYROFX_COCOTB_SAMPLES (14 300 samples of 120 clocks, about
    # 100 s of CPU): run only with GYROFX_SLOW_TESTS=1 (offline; CI's budget), and no
    # flipped-bit run, the scoreboards are those test_one_flipped_expected_bit_fails_it proves on
    # the parallel system.
    system = manifest["system"]
    assert system["module"] == "gyrofx_system_serial"
    pair = system["folded_loops"]
    assert pair["module"] == "gyrofx_gyro_pair_serial"
    spacing = system["min_clocks_per_sample"]
    assert system["latency_clocks"] == spacing == pair["longest_sample_words"] + 3 <= 120
    assert f"TIMING = tb.Timing(latency_clocks={spacing}, min_clocks_per_sample={spacing})\n" in (
        folder / "cocotb" / "test_system.py"
    ).read_text()
    if os.environ.get("GYROFX_SLOW_TESTS") == "1":
        assert_passes(make(folder, "cocotb-system", GYROFX_COCOTB_SAMPLES="300"))


@pytest.mark.parametrize("block", BLOCKS)
def test_the_cocotb_test_passes_on_the_reference_rtl(package, block):
    assert_passes(make(package, f"cocotb-{block}"))


@pytest.mark.parametrize("block", BLOCKS)
def test_one_flipped_expected_bit_fails_it(package, block):
    # The flip hits the 40th expected value of each scoreboard: top has two (rate_out and the
    # registered bias ports), the others one.
    scoreboards = 2 if block == "top" else 1
    # The resonator-level blocks' tests run shorter here (the flip comes early).
    shorter = {"GYROFX_COCOTB_SAMPLES": "1500"} if block in ("gyro_loop", "system") else {}
    assert_fails(make(package, f"cocotb-{block}", GYROFX_COCOTB_FLIP_EXPECTED="40", **shorter), scoreboards)


def test_a_mutated_rtl_line_fails_it(package, tmp_path):
    mutant = tmp_path / "mutant"
    shutil.copytree(package, mutant)
    rtl = mutant / "hdl" / "gyrofx_kf.v"
    text = rtl.read_text()
    assert "x2_reg <= x2_next;" in text
    rtl.write_text(text.replace("x2_reg <= x2_next;", "x2_reg <= x2_reg;", 1))
    result = make(mutant, "cocotb-kf")
    assert result.returncode != 0
    assert any(line.startswith("FAIL mismatches=") for line in summary(result)), result.stdout[-2000:]


def test_gyrofx_verify_runs_them(package, tmp_path):
    result = subprocess.run(
        [*cli(), "verify", "--out", str(package), "--sim", "cocotb", "--blocks", "kf,sequencer",
         "--junit", str(tmp_path / "junit.xml"), "--quiet"],
        capture_output=True, text=True, env=environment(),
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "cocotb: passed" in result.stdout
    junit = (tmp_path / "junit.xml").read_text()
    assert 'name="cocotb"' in junit and "kf" in junit and "<failure" not in junit
    # What the cocotb runs left behind are build outputs the package's marker allows: the
    # package can be regenerated in place.
    assert (package / "kf" / "sim_build").is_dir()
    again = run_cli("generate", "--out", str(package), "--samples", "3000", "--seed", "5", "--quiet", check=False)
    assert again.returncode == 0, again.stderr


def one_stage_longer(wrapper_text, name):
    """A top of the same ports as a package's cocotb wrapper whose every output comes one clock
    later: the reference block with one more register stage, as your own RTL might be."""
    lines = wrapper_text.splitlines()
    registers = []
    out = []
    for line in lines:
        stripped = line.strip()
        if stripped.startswith("module cocotb_"):
            line = f"module {name} ("
        elif stripped.startswith("output wire "):
            declaration = stripped[len("output wire "):].rstrip(",")
            port = declaration.split()[-1]
            registers.append((declaration[: -len(port)], port))
            line = line.replace("output wire ", "output reg ", 1)
        elif stripped.startswith(".") and any(stripped.startswith(f".{p}({p})") for _, p in registers):
            port = stripped[1:].split("(")[0]
            line = line.replace(f".{port}({port})", f".{port}({port}_early)")
        elif stripped == "endmodule":
            out.extend(f"wire {kind}{port}_early;" for kind, port in registers)
            out.append("always @(posedge clk) begin")
            out.extend(f"    {port} <= {port}_early;" for _, port in registers)
            out.append("end")
        out.append(line)
    return "\n".join(out) + "\n"


def pytest_package(package, *arguments, **extra):
    """The package's own pytest file (cocotb/test_package.py on cocotb's Python runner)."""
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-s", "-p", "no:cacheprovider", str(package / "cocotb"), *arguments],
        capture_output=True, text=True, cwd=package, env=environment(**extra),
    )


def junit_cases(path):
    import xml.etree.ElementTree as ElementTree

    root = ElementTree.parse(path).getroot()
    return {case.get("name"): case.find("failure") is None for case in root.iter("testcase")}


def test_the_package_pytest_file_runs_one_test_per_cocotb_test(package, tmp_path):
    copy = tmp_path / "package"
    shutil.copytree(package, copy)
    junit = tmp_path / "junit.xml"
    result = pytest_package(copy, "-k", "kf or sequencer", f"--junitxml={junit}", "--samples", "400")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    # JUnit per cocotb test: the KF's two and the sequencer's one, by block and test name.
    assert junit_cases(junit) == {
        "test_cocotb[kf-random_stimulus]": True,
        "test_cocotb[kf-directed_full_scale]": True,
        "test_cocotb[sequencer-cycles_with_idle_clocks_and_resets]": True,
    }
    # One flipped expected bit fails the one test that holds it.
    result = pytest_package(copy, "-k", "kf-random", f"--junitxml={junit}", "--samples", "400",
                            GYROFX_COCOTB_FLIP_EXPECTED="40")
    assert result.returncode != 0
    assert junit_cases(junit) == {"test_cocotb[kf-random_stimulus]": False}


def test_your_own_rtl_one_stage_longer(package, tmp_path):
    copy = tmp_path / "package"
    shutil.copytree(package, copy)
    rtl = sorted(str(p) for p in (copy / "hdl").glob("*.v"))
    for block, module in [("estimator", "gyrofx_bias_estimator"), ("kf", "gyrofx_kf")]:
        wrapper = (copy / "cocotb" / f"cocotb_{module}.v").read_text()
        (tmp_path / f"longer_{block}.v").write_text(one_stage_longer(wrapper, f"longer_{block}"))
    manifest = json.loads((copy / "manifest.json").read_text())
    latency = manifest["estimator"]["latency_clocks"]

    def run(block, *options):
        return pytest_package(copy, "-k", block, "--samples", "600", "--rtl", *rtl,
                              str(tmp_path / f"longer_{block}.v"), "--toplevel", f"longer_{block}", *options)

    # The estimator's outputs have no valid flag: checked at the reference's latency, the longer
    # pipeline fails; told its latency, it passes.
    failed = run("estimator")
    assert failed.returncode != 0 and "FAIL mismatches=" in failed.stdout, failed.stdout[-3000:]
    passed = run("estimator", "--latency-clocks", str(latency + 1))
    assert passed.returncode == 0, passed.stdout[-3000:] + passed.stderr[-3000:]
    assert passed.stdout.count("PASS n=") == 2, passed.stdout[-3000:]
    # The KF's output is a valid-qualified stream: any latency passes as it is.
    passed = run("kf")
    assert passed.returncode == 0, passed.stdout[-3000:] + passed.stderr[-3000:]
    assert passed.stdout.count("PASS n=") == 2, passed.stdout[-3000:]


def test_the_cocotb_example_of_the_guide_passes_and_catches_a_flipped_bit(tmp_path):
    # examples/cocotb_kf: a user's own cocotb test with the model as its scoreboard, on the
    # KF of a package, through cocotb's Python runner.
    folder = tmp_path / "pkg"
    run_cli("generate", "--out", str(folder), "--samples", "500", "--blocks", "kf", "--quiet")
    example = pathlib.Path(__file__).resolve().parents[2] / "examples" / "cocotb_kf"

    def run(**extra):
        return subprocess.run(
            [sys.executable, "-m", "pytest", "-s", "-p", "no:cacheprovider", str(example)],
            capture_output=True, text=True, env=environment(GYROFX_PACKAGE=str(folder), **extra),
        )

    passed = run()
    assert passed.returncode == 0, passed.stdout[-3000:] + passed.stderr[-3000:]
    assert "PASS n=600" in passed.stdout
    failed = run(GYROFX_COCOTB_FLIP_EXPECTED="10")
    assert failed.returncode != 0 and "FAIL mismatches=1 n=600" in failed.stdout, failed.stdout[-3000:]
