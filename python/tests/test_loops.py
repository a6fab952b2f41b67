"""The resonator-level blocks (gyro loop, system, resonator) against the CLI's vectors.

Expected values come from the package `gyrofx generate` writes (its CSV and hex vectors), never
from numbers copied from the code under test.
"""

import json
import re

import numpy as np
import pytest

import gyrofx
from conftest import read_vectors

LOOP_PORTS = ["dac_x", "dac_y", "locked", "out_valid", "rate", "quadrature"]


def hex_rows(path):
    """A `$readmemh` vector file as (port names with formats, rows of signed codes)."""
    with open(path) as f:
        lines = [line.split() for line in f if line.strip()]
    header = [line for line in lines if line[0] == "//"]
    fields = [field.split(":") for field in header[-1][1:]]
    names = [name for name, _ in fields]
    widths = [int(fmt[1:].split(".")[0]) for _, fmt in fields]
    signed = [fmt[0] == "s" for _, fmt in fields]
    rows = []
    for line in lines:
        if line[0] == "//":
            continue
        row = {}
        for name, width, is_signed, text in zip(names, widths, signed, line):
            code = int(text, 16)
            if is_signed and code >= 1 << (width - 1):
                code -= 1 << width
            row[name] = code
        rows.append(row)
    return rows


def loop_record(package):
    rows = read_vectors(package / "gyro_loop" / "gyro_loop_vectors.csv")
    assert all(r["rst"] == "0" for r in rows), "the loop's record has no reset"
    return rows


def test_the_gyro_loop_reproduces_its_vectors_by_step_and_by_process(package):
    plan = gyrofx.Plan.from_package(package)
    rows = loop_record(package)
    expected = hex_rows(package / "gyro_loop" / "gyro_loop_expected.hex")
    assert len(expected) == len(rows)
    loop = plan.gyro_loop()
    for k, (row, want) in enumerate(zip(rows, expected)):
        got = loop.step(int(row["adc_x"]), int(row["adc_y"]), int(row["mode"]))
        assert got == {p: want[p] for p in LOOP_PORTS}, f"sample {k}"
    assert sum(w["out_valid"] for w in expected) >= 20
    assert {r["mode"] for r in rows} == {"0", "1"}, "the record switches modes"

    loop.reset()
    out = loop.process(
        np.array([int(r["adc_x"]) for r in rows], dtype=np.int64),
        np.array([int(r["adc_y"]) for r in rows], dtype=np.int64),
        np.array([int(r["mode"]) for r in rows], dtype=np.int64),
    )
    for port in LOOP_PORTS:
        assert list(out[port]) == [w[port] for w in expected], port


def test_a_loop_closed_around_the_resonator_retraces_the_vectors_run(package):
    """The resonator with generate's seed, driven by the loop's DAC codes, gives back every ADC
    code of the record: a testbench can close the loop around the DUT."""
    plan = gyrofx.Plan.from_package(package)
    stimulus = json.loads((package / "manifest.json").read_text())["gyro_loop"]["stimulus"]
    manifest_rate = float(re.search(r"at ([-0-9.e]+) °/s", stimulus).group(1))
    rows = loop_record(package)
    loop, resonator = plan.gyro_loop(), plan.resonator("a")
    resonator.set_rate_dps(manifest_rate)
    adc = (0, 0)
    mode = 1
    for k, row in enumerate(rows):
        if int(row["mode"]) != mode:
            mode = int(row["mode"])
            resonator.set_mode(mode)
        assert adc == (int(row["adc_x"]), int(row["adc_y"])), f"sample {k}"
        out = loop.step(adc[0], adc[1], mode)
        read = resonator.step(out["dac_x"], out["dac_y"])
        adc = (read["adc_x"], read["adc_y"])
    # Another seed gives another noise record.
    other = plan.resonator("a", seed=12345)
    other.set_rate_dps(manifest_rate)
    loop.reset()
    adc, differs = (0, 0), False
    for row in rows[:2000]:
        differs |= adc != (int(row["adc_x"]), int(row["adc_y"]))
        out = loop.step(adc[0], adc[1], 1)
        read = other.step(out["dac_x"], out["dac_y"])
        adc = (read["adc_x"], read["adc_y"])
    assert differs


def test_the_loops_float_twin_agrees_away_from_saturation(package):
    """Fed the same ADC record, the twin's rate and quadrature agree with the fixed loop's
    within 0.01 °/s (the settling criterion of the loop's closed-loop tests) plus 5e-5 of the
    output, wherever the fixed output is not saturated (right after a switch it is, by design).
    The relative part is for the samples just after a switch, where the outputs are hundreds
    of °/s: the NCOs' references differ from the twin's exact phase by up to a bin per sample
    (error feedback), and 1e-5 to 3e-5 of such an output is left after the CIC."""
    plan = gyrofx.Plan.from_package(package)
    rows = loop_record(package)
    loop, twin = plan.gyro_loop(), plan.gyro_loop_float()
    adc_lsb = 2.0 ** -int(loop.adc_format.split(".")[1])
    low, high = (-(1 << 23), (1 << 23) - 1)
    out_frac = int(loop.output_format.split(".")[1])
    compared = 0
    for row in rows:
        x, y, mode = int(row["adc_x"]), int(row["adc_y"]), int(row["mode"])
        fixed = loop.step(x, y, mode)
        real = twin.step(x * adc_lsb, y * adc_lsb, mode)
        assert real["out_valid"] == fixed["out_valid"]
        if fixed["out_valid"] and all(low < fixed[p] < high for p in ("rate", "quadrature")):
            for port in ("rate", "quadrature"):
                tolerance = 0.01 + 5e-5 * abs(real[port])
                assert abs(real[port] - fixed[port] * 2.0**-out_frac) < tolerance, (row["sample"], port)
            compared += 1
    assert compared >= 20


def test_the_system_reproduces_its_vectors(package):
    plan = gyrofx.Plan.from_package(package)
    stimulus = hex_rows(package / "system" / "system_stimulus.hex")
    expected = hex_rows(package / "system" / "system_expected.hex")
    assert len(stimulus) == len(expected) > 0
    system = plan.system()
    adc_ports = ["adc_a_x", "adc_a_y", "adc_b_x", "adc_b_y"]
    for k, (s, want) in enumerate(zip(stimulus, expected)):
        if s["rst"]:
            system.reset()
        got = system.step(*[s[p] for p in adc_ports], enable=s["enable"], bw_sel=s["bw_sel"])
        assert got == want, f"sample {k}"
    assert sum(w["out_valid"] for w in expected) >= 10
    assert any(w["estimated"] for w in expected)

    system.reset()
    body = stimulus
    assert not any(s["rst"] for s in body)
    out = system.process(
        *[np.array([s[p] for s in body], dtype=np.int64) for p in adc_ports],
        enable=np.array([s["enable"] for s in body], dtype=np.int64),
        bw_sel=np.array([s["bw_sel"] for s in body], dtype=np.int64),
    )
    for port in expected[0]:
        assert list(out[port]) == [w[port] for w in expected], port


def test_loop_and_system_inputs_are_checked():
    plan = gyrofx.Plan.default()
    loop, system = plan.gyro_loop(), plan.system()
    cases = [
        (lambda: loop.step(1 << 23, 0), "adc_x = 8388608 is not a code of s24.23"),
        (lambda: loop.step(0, 0, 2), "mode = 2: a mode is 1 (normal) or 0 (reverse)"),
        (lambda: loop.process(np.zeros(3, np.int64), np.zeros(2, np.int64)), "adc_y has 2 samples"),
        (lambda: loop.process(np.zeros(3, np.int64), np.zeros(3, np.int64), np.array([1, 0, 5])), "mode[2] = 5"),
        (lambda: system.step(0, 0, 0, 0, enable=2), "enable = 2: a flag is 0 or 1"),
        (lambda: system.step(0, 0, 0, -(1 << 23) - 1), "adc_b_y = -8388609"),
        (lambda: system.step(0, 0, 0, 0, bw_sel=9), "bw_sel = 9 does not address"),
        (lambda: plan.gyro_loop("c"), 'gyro = "c": allowed "a" or "b"'),
        (lambda: plan.resonator("a").step(1 << 17, 0), "dac_x = 131072 is not a code of s18.0"),
        (lambda: plan.resonator("b").set_mode(3), "mode = 3"),
    ]
    for call, message in cases:
        with pytest.raises(gyrofx.GyrofxError, match=re.escape(message)):
            call()
    # A refused step leaves the state unchanged: the same inputs after it give the same outputs.
    fresh = plan.gyro_loop()
    for k in range(50):
        with pytest.raises(gyrofx.GyrofxError):
            loop.step(0, 0, 7)
        assert loop.step(k, -k, 1) == fresh.step(k, -k, 1)


def test_the_rate_plant_has_no_system():
    plan = gyrofx.Plan.from_toml('[plant]\nmodel = "rate"\n')
    with pytest.raises(gyrofx.GyrofxError, match="no system block"):
        plan.system()
    assert plan.gyro_loop().decimation > 0


def test_the_systems_float_twin_takes_the_same_modes_and_chain_steps(package):
    """Fed the system record's ADC codes as full-scale values, the float twin commands the same
    modes and gives chain outputs at the same samples; its first output agrees with the fixed
    one within 0.01 °/s. (The model's Rust test bounds the rest, and says why saturated loop
    rates after a switch end the comparison: model/src/system/tests.rs.)"""
    plan = gyrofx.Plan.from_package(package)
    stimulus = hex_rows(package / "system" / "system_stimulus.hex")
    expected = hex_rows(package / "system" / "system_expected.hex")
    twin = plan.system_float()
    adc_lsb = 2.0 ** -int(plan.gyro_loop().adc_format.split(".")[1])
    out_frac = int(plan.formats()["kf.output"].split(".")[1])
    assert twin.next_modes() == plan.system().next_modes()
    outputs = []
    for k, (s, want) in enumerate(zip(stimulus, expected)):
        real = [s[p] * adc_lsb for p in ["adc_a_x", "adc_a_y", "adc_b_x", "adc_b_y"]]
        got = twin.step(*real, enable=s["enable"], bw_sel=s["bw_sel"])
        assert (got["mode_a"], got["mode_b"], got["out_valid"]) == (
            want["mode_a"], want["mode_b"], want["out_valid"]), f"sample {k}"
        if want["out_valid"]:
            outputs.append((want["rate_out"] * 2.0**-out_frac, got["rate_out"]))
    assert len(outputs) >= 10
    fixed, real = outputs[0]
    assert abs(fixed - real) < 0.01, outputs[0]
