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
    # gyrofx writes the latency into the tests: outputs show latency - 1 clocks after the edge.
    settle = manifest["chain"]["latency_clocks"] - 1
    assert settle > 1000
    assert f"OUTPUT_CLOCKS = {settle}\n" in (folder / "cocotb" / "test_top.py").read_text()
    assert_passes(make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="400"))
    # Two scoreboards: rate_out and the registered bias ports. The flip comes at the 40th value
    # of each; 150 samples reach it on both (rate_out is valid outside the blanking only). Each
    # sample takes over 1000 clocks of cocotb's Python clock: 400 here would add 35 s.
    assert_fails(make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="150", GYROFX_COCOTB_FLIP_EXPECTED="40"), 2)
    # The sequential mean filter beside it: the next sample after its latency.
    assert (folder / "cocotb" / "cocotb_gyrofx_mean_filter_serial.v").exists()
    idle = manifest["mean_filter"]["min_clocks_per_sample"] - 1
    assert idle > 0
    assert f"PIPELINE_CLOCKS = {idle}\n" in (folder / "cocotb" / "test_mean_filter.py").read_text()
    assert_passes(make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000"))
    assert_fails(make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000", GYROFX_COCOTB_FLIP_EXPECTED="40"), 1)


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
