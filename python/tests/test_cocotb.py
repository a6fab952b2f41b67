"""The package's cocotb tests: they pass on the reference RTL in Icarus, `gyrofx verify --sim
cocotb` runs them, and they fail on one flipped expected bit and on a mutated RTL line."""

import os
import pathlib
import shutil
import subprocess
import sys

import pytest

from conftest import cli, run_cli

BLOCKS = ["sequencer", "estimator", "kf", "top", "mean_filter", "gyro_loop", "system"]


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


@pytest.mark.parametrize("block", BLOCKS)
def test_the_cocotb_test_passes_on_the_reference_rtl(package, block):
    result = make(package, f"cocotb-{block}")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    lines = summary(result)
    assert lines and all(line.startswith("PASS n=") for line in lines), lines
    assert all(int(line.split("n=")[1].split()[0]) > 0 for line in lines)


@pytest.mark.parametrize("block", BLOCKS)
def test_one_flipped_expected_bit_fails_it(package, block):
    # The flip hits the 40th expected value of each scoreboard: top has two (rate_out and the
    # registered bias ports), the others one.
    scoreboards = 2 if block == "top" else 1
    # The resonator-level blocks' tests run shorter here (the flip comes early).
    shorter = {"GYROFX_COCOTB_SAMPLES": "1500"} if block in ("gyro_loop", "system") else {}
    result = make(package, f"cocotb-{block}", GYROFX_COCOTB_FLIP_EXPECTED="40", **shorter)
    assert result.returncode != 0
    assert any(line.startswith(f"FAIL mismatches={scoreboards} ") for line in summary(result)), summary(result)


def test_the_serial_blocks_pass_it_and_a_flipped_bit_fails_it(tmp_path):
    # architecture = "serial": gyrofx_top_serial and gyrofx_mean_filter_serial, their latency
    # written into the tests by gyrofx.
    config = tmp_path / "serial.toml"
    config.write_text('architecture = "serial"\n[sequencer]\ninterval_length = 60\nblank = 30\n')
    folder = tmp_path / "out"
    run_cli("generate", "--config", str(config), "--out", str(folder), "--samples", "800", "--quiet")
    assert "OUTPUT_CLOCKS = 5\n" not in (folder / "cocotb" / "test_top.py").read_text()
    result = make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="400")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert all(line.startswith("PASS n=") for line in summary(result)), summary(result)
    result = make(folder, "cocotb-top", GYROFX_COCOTB_SAMPLES="400", GYROFX_COCOTB_FLIP_EXPECTED="40")
    assert result.returncode != 0
    assert any(line.startswith("FAIL mismatches=2 ") for line in summary(result)), summary(result)
    # The sequential mean filter beside it: the next sample after its latency.
    assert (folder / "cocotb" / "cocotb_gyrofx_mean_filter_serial.v").exists()
    assert "PIPELINE_CLOCKS = 0\n" not in (folder / "cocotb" / "test_mean_filter.py").read_text()
    result = make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert all(line.startswith("PASS n=") for line in summary(result)), summary(result)
    result = make(folder, "cocotb-mean_filter", GYROFX_COCOTB_SAMPLES="1000", GYROFX_COCOTB_FLIP_EXPECTED="40")
    assert result.returncode != 0
    assert any(line.startswith("FAIL mismatches=1 ") for line in summary(result)), summary(result)


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
