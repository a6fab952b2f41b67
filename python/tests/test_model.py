"""The Python model against the Rust CLI's vectors, the derived error bound and exact arithmetic.

Nothing here is compared with numbers copied from the code under test: the expected values come
from the vectors `gyrofx generate` writes (and the repository's golden vectors), from Python's
own exact rational arithmetic, or from the CLI's own error messages.
"""

import fractions
import json
import math
import pathlib

import numpy as np
import pytest

import gyrofx
from conftest import REPOSITORY, read_vectors, run_cli


def replay_kf(kf, rows):
    """Steps `kf` through KF vector rows; returns how many outputs were compared."""
    compared = 0
    for row in rows:
        if row["rst"] == "1":
            kf.reset()
            continue
        got = kf.step(int(row["z"]), int(row["bw_sel"]))
        assert row["out_valid"] == "1" and got["out_valid"] == 1, row
        got = got["rate_out"]
        assert got == int(row["rate_out"]), f"sample {row['sample']}: {got} != {row['rate_out']}"
        compared += 1
    return compared


def leading_run(rows):
    """The rows before the first reset (the record `process` replays without one)."""
    run = []
    for row in rows:
        if row["rst"] == "1":
            break
        run.append(row)
    return run


def test_the_kf_reproduces_the_repositorys_golden_vectors():
    rows = read_vectors(REPOSITORY / "vectors" / "kf" / "kf_vectors.csv")
    plan = gyrofx.Plan.from_package(REPOSITORY / "vectors")
    assert replay_kf(plan.kf(), rows) > 1000


def test_the_kf_reproduces_a_fresh_package(package):
    rows = read_vectors(package / "kf" / "kf_vectors.csv")
    assert replay_kf(gyrofx.Plan.from_package(package).kf(), rows) > 1000


def test_a_flipped_expected_bit_is_caught(package):
    rows = read_vectors(package / "kf" / "kf_vectors.csv")
    victim = next(i for i, r in enumerate(rows) if r["rst"] == "0" and int(r["rate_out"]) != 0)
    rows[victim] = dict(rows[victim], rate_out=str(int(rows[victim]["rate_out"]) ^ 1))
    with pytest.raises(AssertionError):
        replay_kf(gyrofx.Plan.default().kf(), rows)


def test_the_sequencer_reproduces_its_vectors(package):
    sequencer = gyrofx.Plan.from_package(package).sequencer()
    ports = ["mode_a", "mode_b", "blank_a", "blank_b", "interval_a", "interval_b", "done_a", "done_b", "window_done"]
    compared = 0
    for row in read_vectors(package / "sequencer" / "sequencer_vectors.csv"):
        if row["rst"] == "1":
            sequencer.reset()
            continue
        got = sequencer.step()
        assert [got[p] for p in ports] == [int(row[p]) for p in ports], row
        compared += 1
    assert compared > 1000


def test_the_estimator_reproduces_its_vectors(package):
    estimator = gyrofx.Plan.from_package(package).estimator()
    inputs = ["y_a", "y_b", "blank_a", "blank_b", "done_a", "done_b", "interval_a", "interval_b", "window_done"]
    rows = read_vectors(package / "estimator" / "estimator_vectors.csv")
    estimated = 0
    for row in rows:
        if row["rst"] == "1":
            estimator.reset()
            continue
        got = estimator.step(*(int(row[p]) for p in inputs))
        bias_a, bias_b, done = got["bias_a"], got["bias_b"], got["estimated"]
        assert (bias_a, bias_b, done) == (int(row["bias_a"]), int(row["bias_b"]), int(row["estimated"])), row
        estimated += done
    assert estimated > 0, "the record reaches an estimate"
    # process() on the same record gives the same outputs.
    body = leading_run(rows)
    assert any(r["estimated"] == "1" for r in body), "the replayed run reaches an estimate"
    fresh = gyrofx.Plan.from_package(package).estimator()
    out = fresh.process(*(np.array([int(r[p]) for r in body], dtype=np.int64) for p in inputs))
    assert list(out["bias_a"]) == [int(r["bias_a"]) for r in body]
    assert list(out["estimated"]) == [int(r["estimated"]) for r in body]


def test_the_mean_filter_reproduces_its_vectors(package):
    mean_filter = gyrofx.Plan.from_package(package).mean_filter()
    blocks = 0
    for row in read_vectors(package / "mean_filter" / "mean_filter_vectors.csv"):
        if row["rst"] == "1":
            mean_filter.reset()
            continue
        got = mean_filter.step(int(row["x"]))
        if row["y_valid"] == "1":
            assert got == {"y_valid": 1, "y": int(row["y"]), "kept": int(row["kept"])}, row
            blocks += 1
        else:
            assert got == {"y_valid": 0, "y": 0, "kept": 0}, row
    assert blocks > 10


def test_the_chain_and_its_float_twin_reproduce_the_top_vectors(package):
    plan = gyrofx.Plan.from_package(package)
    chain, twin = plan.chain(), plan.chain_float()
    input_format = plan.formats()["estimator.input"]
    ports = ["mode_a", "mode_b", "out_valid", "rate_out", "bias_a", "bias_b", "estimated"]
    rows = read_vectors(package / "top" / "top_vectors.csv")
    valid = 0
    for row in rows:
        if row["rst"] == "1":
            chain.reset()
            twin.reset()
            continue
        y = [int(row["y_a"]), int(row["y_b"])]
        got = chain.step(y[0], y[1], int(row["bw_sel"]))
        want = {p: int(row[p]) if row[p] != "" else 0 for p in ports}
        assert got == want, row
        y_real = gyrofx.to_real(np.array(y, dtype=np.int64), input_format)
        float_sample = twin.step(float(y_real[0]), float(y_real[1]), int(row["bw_sel"]))
        if row["float_rate_dps"]:
            # The CSV prints the shortest round-trip text: equal as doubles.
            assert float_sample["rate_out"] == float(row["float_rate_dps"]), row
            valid += 1
        else:
            assert float_sample["rate_out"] is None
    assert valid > 100
    # process() over the same stimulus: the same port streams.
    body = leading_run(rows)
    assert sum(r["out_valid"] == "1" for r in body) > 100
    fresh = plan.chain()
    out = fresh.process(
        np.array([int(r["y_a"]) for r in body], dtype=np.int64),
        np.array([int(r["y_b"]) for r in body], dtype=np.int64),
        np.array([int(r["bw_sel"]) for r in body], dtype=np.int64),
    )
    assert list(out["rate_out"]) == [int(r["rate_out"]) if r["rate_out"] else 0 for r in body]


def test_the_kf_stays_within_its_derived_bound_of_the_float_twin():
    plan = gyrofx.Plan.default()
    kf, twin = plan.kf(), plan.kf_float()
    fmt_in, fmt_out = kf.input_format, kf.output_format
    rng = np.random.default_rng(7)
    samples = 20_000
    z = gyrofx.quantize(rng.normal(5.0, 30.0, samples), fmt_in)
    fixed = gyrofx.to_real(kf.process(z, 2)["rate_out"], fmt_out)
    real = twin.process(gyrofx.to_real(z, fmt_in), 2)["rate_out"]
    lsb = 2.0 ** -int(fmt_out.split(".")[1])
    worst = np.max(np.abs(fixed - real)) / lsb
    bound = kf.error_bound_lsb(samples)
    assert 0 < worst <= bound, (worst, bound)


def test_process_equals_step_for_the_kf_and_mean_filter():
    plan = gyrofx.Plan.default()
    rng = np.random.default_rng(3)
    z = gyrofx.quantize(rng.normal(0.0, 50.0, 3000), plan.kf().input_format)
    select = rng.integers(0, len(plan.bandwidths_hz), z.size)
    stepped = plan.kf()
    out = plan.kf().process(z, select)
    steps = [stepped.step(int(a), int(b)) for a, b in zip(z, select)]
    assert set(out) == set(steps[0]) == {"out_valid", "rate_out"}
    for port in out:
        assert list(out[port]) == [s[port] for s in steps], port
    mean = plan.mean_filter()
    x = gyrofx.quantize(rng.normal(0.0, 50.0, 3000), mean.input_format)
    out = plan.mean_filter().process(x)
    for i, code in enumerate(x):
        got = mean.step(int(code))
        assert got == {port: out[port][i] for port in ("y_valid", "y", "kept")}, i


def exact_quantize(value, frac, width, rounding, overflow):
    """Python's own rational arithmetic: the reference for `quantize`."""
    scaled = fractions.Fraction(value) * fractions.Fraction(2) ** frac
    floor = math.floor(scaled)
    rest = scaled - floor
    half = fractions.Fraction(1, 2)
    if rounding == "floor":
        code = floor
    elif rounding == "ceil":
        code = math.ceil(scaled)
    elif rounding == "zero":
        code = math.trunc(scaled)
    elif rounding == "nearest":
        code = floor + (1 if rest >= half else 0)
    elif rounding == "round":
        code = floor + (1 if rest > half or (rest == half and scaled > 0) else 0)
    else:  # convergent
        code = floor + (1 if rest > half or (rest == half and floor % 2 == 1) else 0)
    low, high = -(1 << (width - 1)), (1 << (width - 1)) - 1
    if overflow == "saturate":
        return min(max(code, low), high)
    return ((code - low) % (1 << width)) + low


@pytest.mark.parametrize("rounding", ["floor", "ceil", "zero", "nearest", "round", "convergent"])
@pytest.mark.parametrize("overflow", ["saturate", "wrap"])
def test_quantize_matches_exact_arithmetic(rounding, overflow):
    rng = np.random.default_rng(11)
    width, frac = 10, 3
    ties = (np.arange(-700, 700) + 0.5) / 8.0  # every tie, including past the range
    values = np.concatenate([ties, rng.uniform(-100.0, 100.0, 2000), [0.0, -0.0, 63.9375, -64.0]])
    got = gyrofx.quantize(values, f"s{width}.{frac}", rounding, overflow)
    want = [exact_quantize(v, frac, width, rounding, overflow) for v in values]
    assert got.dtype == np.int64
    assert list(got) == want
    back = gyrofx.to_real(got, f"s{width}.{frac}")
    assert list(back) == [c / 8.0 for c in want]


def test_errors_are_gyrofx_errors_with_the_clis_messages(tmp_path):
    bad = "[kf]\nbandwidths_hz = [10.0, 500.0]\n"
    config = tmp_path / "bad.toml"
    config.write_text(bad)
    cli = run_cli("generate", "--config", str(config), "--out", str(tmp_path / "o"), check=False)
    assert cli.returncode != 0
    with pytest.raises(gyrofx.GyrofxError) as python:
        gyrofx.Plan.from_file(config)
    assert str(python.value) in cli.stderr, (str(python.value), cli.stderr)
    with pytest.raises(gyrofx.GyrofxError, match="one of gu2019, xue2015, mpu6050"):
        gyrofx.Plan.preset("nope")
    kf = gyrofx.Plan.default().kf()
    with pytest.raises(gyrofx.GyrofxError, match=r"z = 8388608 is not a code of s24\.14"):
        kf.step(8388608)
    with pytest.raises(gyrofx.GyrofxError, match=r"bw_sel = 3 does not address"):
        kf.step(0, 3)
    with pytest.raises(gyrofx.GyrofxError, match=r"values\[1\] = NaN"):
        gyrofx.quantize(np.array([1.0, np.nan]), "s8.2")
    with pytest.raises(gyrofx.GyrofxError, match="format \"q8\""):
        gyrofx.quantize(np.array([1.0]), "q8")
    with pytest.raises(gyrofx.GyrofxError, match="y_b has 2 samples but y_a has 3"):
        gyrofx.Plan.default().chain().process(np.zeros(3, dtype=np.int64), np.zeros(2, dtype=np.int64))
    with pytest.raises(gyrofx.GyrofxError, match="not a gyrofx package manifest"):
        (tmp_path / "manifest.json").write_text('{"tool": "other"}')
        gyrofx.Plan.from_package(tmp_path)


def test_plans_and_formats():
    default = gyrofx.Plan.default()
    formats = default.formats()
    assert formats["kf.input"] == default.kf().input_format
    assert formats["kf.output"] == default.kf().output_format
    assert formats["mean_filter.input"] == default.mean_filter().input_format
    assert all(f[0] in "su" and "." in f for f in formats.values())
    assert gyrofx.Plan.preset("mpu6050").toml() != default.toml()
    assert gyrofx.Plan.from_toml("[kf]\nbandwidths_hz = [5.0]\n").bandwidths_hz == [5.0]
    # The resolved config round-trips.
    assert gyrofx.Plan.from_toml(default.toml()).formats() == formats


def test_the_stubs_name_every_public_class():
    stubs = (pathlib.Path(gyrofx.__file__).parent / "__init__.pyi").read_text()
    for name in gyrofx.__all__:
        if name != "__version__":
            assert name in stubs, name


@pytest.mark.parametrize("architecture", ["parallel", "serial"])
def test_every_block_class_has_the_manifests_latency_and_spacing(tmp_path, architecture):
    # The manifest's figures are the testbenches' (both read gyrofx_job::pipeline): a
    # scoreboard built on the Python values waits as long as the RTL takes.
    config = tmp_path / "config.toml"
    config.write_text(f'architecture = "{architecture}"\n')
    folder = tmp_path / "out"
    run_cli("generate", "--config", str(config), "--out", str(folder), "--samples", "400",
            "--blocks", "kf", "--no-csv", "--quiet")
    manifest = json.loads((folder / "manifest.json").read_text())
    plan = gyrofx.Plan.from_package(str(folder))
    classes = {
        "kf": plan.kf(),
        "estimator": plan.estimator(),
        "chain": plan.chain(),
        "mean_filter": plan.mean_filter(),
        "gyro_loop": plan.gyro_loop(),
        "system": plan.system(),
    }
    for section, block in classes.items():
        expected = (manifest[section]["latency_clocks"], manifest[section]["min_clocks_per_sample"])
        assert (block.latency_clocks, block.min_clocks_per_sample) == expected, section
    assert (plan.kf().latency_clocks, plan.kf().min_clocks_per_sample) == (4, 3)
    serial = architecture == "serial"
    assert (plan.chain().latency_clocks > 1000) == serial
    assert (plan.mean_filter().latency_clocks > 1) == serial
    assert (plan.sequencer().latency_clocks, plan.sequencer().min_clocks_per_sample) == (1, 1)
    # The folded system's chain outputs come the manifest's chain_delay_samples later.
    assert plan.system().chain_delay_samples == manifest["system"]["chain_delay_samples"]
    assert (plan.system().chain_delay_samples > 1) == serial


def test_every_block_class_lists_the_manifests_ports(package):
    # The ports a testbench of one's own drives and reads: names, formats and directions as
    # the package's vector files declare them (the manifest's fields, after rst).
    manifest = json.loads((package / "manifest.json").read_text())
    plan = gyrofx.Plan.from_package(str(package))
    classes = {
        "sequencer": plan.sequencer(),
        "estimator": plan.estimator(),
        "kf": plan.kf(),
        "top": plan.chain(),
        "mean_filter": plan.mean_filter(),
        "gyro_loop": plan.gyro_loop(),
        "system": plan.system(),
    }
    for block, model in classes.items():
        fields = manifest["blocks"][block]
        expected = [(f["name"], f["format"], "in") for f in fields["stimulus"]["fields"] if f["name"] != "rst"]
        expected += [(f["name"], f["format"], "out") for f in fields["expected"]["fields"]]
        assert model.ports() == expected, block


def test_records_of_any_integer_dtype_and_lists_are_accepted_and_others_refused_by_name():
    kf = gyrofx.Plan.default().kf()
    codes = np.array([5, -7, 1200, 0, -3000, 42], dtype=np.int64)
    want = kf.process(codes)["rate_out"]
    kf.reset()
    for record in (codes.tolist(), codes.astype(np.int32), codes.astype(">i8"), codes[::-1][::-1].copy()):
        kf.reset()
        assert np.array_equal(kf.process(record)["rate_out"], want), type(record)
    small = np.array([0, 1, 200, 255], dtype=np.uint8)
    kf.reset()
    via_uint8 = kf.process(small)["rate_out"]
    kf.reset()
    assert np.array_equal(via_uint8, kf.process(small.astype(np.int64))["rate_out"])
    assert len(kf.process([])["rate_out"]) == 0
    for record, message in (
        (codes.astype(np.float64), "z: an array of float64; allowed: a one-dimensional record of integer codes"),
        (codes.reshape(2, 3), "z: 2 dimensions; allowed"),
        (np.array([2**63], dtype=np.uint64), "z[0] = 9223372036854775808: not a code of any port"),
    ):
        with pytest.raises(gyrofx.GyrofxError, match=message.replace("[", r"\[").replace("]", r"\]")):
            kf.process(record)
    # bw_sel per sample takes the same records.
    kf.reset()
    both = kf.process(codes, bw_sel=[0, 1, 2, 0, 1, 2])["rate_out"]
    kf.reset()
    assert np.array_equal(both, kf.process(codes, bw_sel=np.array([0, 1, 2, 0, 1, 2], dtype=np.uint8))["rate_out"])
    assert np.array_equal(gyrofx.to_real([1, -2], "s4.1"), gyrofx.to_real(np.array([1, -2]), "s4.1"))


def test_the_package_docstring_runs_and_signatures_read_plainly():
    import doctest
    import inspect

    failures, tried = doctest.testmod(gyrofx, raise_on_error=False, verbose=False)
    assert tried > 0 and failures == 0
    assert str(inspect.signature(gyrofx.Kf.process)) == "(self, /, z, bw_sel=0)"
    assert "Ellipsis" not in str(inspect.signature(gyrofx.System.process))
    assert np.array_equal(gyrofx.quantize([0.5, -1], "s8.4"), gyrofx.quantize(np.array([0.5, -1.0]), "s8.4"))


def test_the_wheel_installs_into_a_clean_virtualenv_without_rust(tmp_path):
    # The path the guide gives a user with no Rust toolchain: the abi3 wheel the build makes,
    # installed with pip into a new virtualenv whose PATH has no cargo; numpy comes from PyPI.
    import glob
    import os
    import subprocess
    import sys

    wheels = [os.environ["GYROFX_WHEEL"]] if os.environ.get("GYROFX_WHEEL") else sorted(
        glob.glob(str(REPOSITORY / "python" / "target" / "wheels" / "gyrofx-*.whl")))
    assert wheels, "no wheel: scripts/test.sh builds it (maturin build), or set GYROFX_WHEEL"
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    environment = {"PATH": f"{venv / 'bin'}:/usr/bin:/bin", "HOME": str(tmp_path)}
    for name in ("PIP_INDEX_URL", "PIP_EXTRA_INDEX_URL", "PIP_TRUSTED_HOST", "PIP_CERT",
                 "HTTPS_PROXY", "HTTP_PROXY", "https_proxy", "http_proxy", "NO_PROXY", "no_proxy",
                 "SSL_CERT_FILE", "REQUESTS_CA_BUNDLE"):
        if name in os.environ:
            environment[name] = os.environ[name]
    subprocess.run([str(venv / "bin" / "pip"), "install", "-q", wheels[-1]], check=True, env=environment)
    script = ("import shutil, gyrofx; assert shutil.which('cargo') is None; "
              "kf = gyrofx.Plan.default().kf(); print(kf.latency_clocks, kf.process([0, 1000, -1000])['rate_out'].tolist())")
    shown = subprocess.run([str(venv / "bin" / "python"), "-c", script], check=True, env=environment,
                           capture_output=True, text=True).stdout.split(" ", 1)
    kf = gyrofx.Plan.default().kf()
    assert shown == ["4", f"{kf.process([0, 1000, -1000])['rate_out'].tolist()}\n"]


def test_every_step_returns_its_output_ports_and_process_the_same_keys():
    # One return shape per kind of method: step a dict keyed by the block's output ports,
    # process the same keys (arrays), a float twin a subset of them.
    plan = gyrofx.Plan.default()
    slot_ports = ["blank_a", "blank_b", "done_a", "done_b", "interval_a", "interval_b", "window_done"]
    slot = plan.sequencer().step()
    estimator_inputs = [0, 0] + [slot[p] for p in slot_ports]
    cases = [
        (plan.kf(), (0,), ([0, 1],), (plan.kf_float(), (0.0,))),
        (plan.sequencer(), (), (2,), None),
        (plan.estimator(), estimator_inputs, [[v] for v in estimator_inputs],
         (plan.estimator_float(), [0.0, 0.0] + estimator_inputs[2:])),
        (plan.mean_filter(), (0,), ([0, 1],), (plan.mean_filter_float(), (0.0,))),
        (plan.chain(), (0, 0), ([0], [0]), (plan.chain_float(), (0.0, 0.0))),
        (plan.gyro_loop(), (0, 0, 1), ([0], [0]), (plan.gyro_loop_float(), (0.0, 0.0, 1))),
        (plan.system(), (0, 0, 0, 0), ([0], [0], [0], [0]), (plan.system_float(), (0.0, 0.0, 0.0, 0.0))),
    ]
    for block, step_inputs, process_inputs, twin in cases:
        outputs = {name for name, _, direction in block.ports() if direction == "out"}
        name = type(block).__name__
        assert set(block.step(*step_inputs)) == outputs, name
        processed = block.process(*process_inputs)
        assert set(processed) == outputs, name
        assert all(isinstance(v, np.ndarray) for v in processed.values()), name
        if twin is not None:
            model, inputs = twin
            assert set(model.step(*inputs)) <= outputs, type(model).__name__
    loop_inputs = {name for name, _, direction in plan.gyro_loop().ports() if direction == "in"}
    assert set(plan.resonator("a").step(0, 0)) == {"adc_x", "adc_y"} <= loop_inputs


def test_mypy_refuses_what_fails_at_run_time(tmp_path):
    # The stubs type each step's dict: a misspelt port or a tuple unpacking of a dict is a type
    # error before it is a KeyError or a ValueError at run time.
    import mypy.api

    good = tmp_path / "good.py"
    good.write_text(
        "import gyrofx\n"
        "plan = gyrofx.Plan.default()\n"
        "rate: int = plan.kf().step(0)['rate_out']\n"
        "adc = plan.resonator('a').step(0, 0)\n"
        "x: int = adc['adc_x']\n"
    )
    out, _, status = mypy.api.run(["--strict", "--no-incremental", str(good)])
    assert status == 0, out
    for bad, message in (
        ("rate = gyrofx.Plan.default().kf().step(0)['rate']\n", 'has no key "rate"'),
        ("a, b, c = gyrofx.Plan.default().estimator().step(0, 0, 0, 0, 0, 0, 0, 0, 0)['bias_a']\n", "int"),
        ("gyrofx.quantize([0.5], 's24.14', rounding='nearset')\n", 'No overload variant of "quantize"'),
    ):
        path = tmp_path / "bad.py"
        path.write_text("import gyrofx\n" + bad)
        out, _, status = mypy.api.run(["--no-incremental", str(path)])
        assert status != 0 and message in out, (bad, out)


def test_format_rounding_and_overflow_objects_and_overflow_counts():
    fmt = gyrofx.Format("s8.4")
    assert (fmt.width, fmt.fraction, fmt.signed, fmt.min_code, fmt.max_code, fmt.lsb) == (8, 4, True, -128, 127, 1 / 16)
    assert fmt == "s8.4" and fmt == gyrofx.Format(width=8, fraction=4) and fmt != "s8.3"
    assert hash(fmt) == hash("s8.4") and repr(fmt) == "Format('s8.4')" and str(fmt) == "s8.4"
    unsigned = gyrofx.Format(width=4, fraction=0, signed=False)
    assert (str(unsigned), unsigned.min_code, unsigned.max_code) == ("u4.0", 0, 15)
    values = [0.03125, -0.03125, 100.0, -100.0, 1.5]
    # Enums and the config's strings are the same modes, for quantize and Format.quantize.
    for rounding in ("floor", "ceil", "zero", "nearest", "round", "convergent"):
        enum = getattr(gyrofx.Rounding, rounding.upper())
        assert enum.config_name == rounding
        for overflow in ("saturate", "wrap"):
            by_name = gyrofx.quantize(values, "s8.4", rounding, overflow)
            by_enum = gyrofx.quantize(values, fmt, enum, getattr(gyrofx.Overflow, overflow.upper()))
            assert np.array_equal(by_name, by_enum) and np.array_equal(by_name, fmt.quantize(values, enum, overflow))
    # Two of the five values do not fit s8.4 (±100): counted, saturated or wrapped.
    codes, overflowed = gyrofx.quantize(values, fmt, counts=True)
    assert overflowed == 2 and list(codes) == [1, 0, 127, -128, 24]
    codes, overflowed = gyrofx.quantize(values, fmt, overflow=gyrofx.Overflow.WRAP, counts=True)
    assert overflowed == 2 and list(codes[2:4]) == [(1600 + 128) % 256 - 128, (-1600 + 128) % 256 - 128]
    assert gyrofx.quantize([0.5], fmt, counts=True)[1] == 0
    assert np.array_equal(fmt.to_real([16, -8]), gyrofx.to_real([16, -8], "s8.4"))
    for call, message in (
        (lambda: gyrofx.Format("q8.4"), 'format "q8.4"'),
        (lambda: gyrofx.Format(width=0, fraction=0), "width=0"),
        (lambda: gyrofx.Format(), "give a string"),
        (lambda: gyrofx.quantize([0.5], fmt, "nearset"), 'rounding = "nearset"'),
        (lambda: gyrofx.quantize([0.5], fmt, overflow="clip"), 'overflow = "clip"'),
    ):
        with pytest.raises(gyrofx.GyrofxError, match=message):
            call()


def test_blocks_count_their_overflows_and_show_their_ports():
    plan = gyrofx.Plan.default()
    kf = plan.kf()
    assert kf.overflow_counts() == {"x1": 0, "x2": 0, "rate_out": 0}
    assert repr(kf) == "Kf(" + ", ".join(f"{n}: {f}" for n, f, d in kf.ports() if d == "in") + " -> " + \
        ", ".join(f"{n}: {f}" for n, f, d in kf.ports() if d == "out") + ")"
    # A KF fed full scale long enough to saturate: the state or output quantizers count it, a
    # reset keeps the counts, and the step's outputs are the saturated codes.
    small = gyrofx.Plan.from_toml('[kf]\noutput_format = "s16.12"\n').kf()
    full_scale = gyrofx.Format(small.input_format).max_code
    for _ in range(4000):
        out = small.step(full_scale)
    assert out["rate_out"] == gyrofx.Format(small.output_format).max_code
    counts = small.overflow_counts()
    assert sum(counts.values()) > 0, counts
    small.reset()
    assert small.overflow_counts() == counts
    # Every block names its points; the chain and the system by their parts.
    assert set(plan.estimator().overflow_counts()) == {
        "mean_a", "mean_b", "bias_a", "bias_b", "calibrated_a", "calibrated_b", "combined"}
    chain = plan.chain().overflow_counts()
    assert {"kf.x1", "kf.rate_out", "estimator.combined"} <= set(chain)
    system = plan.system().overflow_counts()
    assert set(chain) <= set(system) and any(k.startswith("a.") for k in system) and any(k.startswith("b.") for k in system)
    assert set(plan.gyro_loop().overflow_counts()) == {k[2:] for k in system if k.startswith("a.")}
    assert plan.sequencer().overflow_counts() == {} and plan.mean_filter().overflow_counts() == {}
