"""``gyrofx.population`` against ``gyrofx population``: the same files byte for byte, run here,
on a dask ``LocalCluster`` and on a scheduler and two workers started with dask's own commands.

The expected files are the CLI's; nothing is compared with numbers copied from the code under
test. The run is tiny (4 members, a short schedule, 1 s of chain each: about 3 s of one core)
but spread so that the members differ, and seed 13 draws gyro a of member 3 off the PLL's pull
range: an unlocked member, whose message has a comma (a quoted CSV cell).
"""

import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest
from distributed import Client, LocalCluster

import gyrofx
from conftest import run_cli

# Windows of 0.4 s (as the job's own population tests), three parameters spread per gyro.
CONFIG = """\
[sequencer]
interval_length = 40
intervals = 2
blank = 30

[population.resonator]
q_drive = { distribution = "normal", std = 0.05, relative = true }
phase_error_deg = { distribution = "uniform", low = 0.5, high = 1.5 }
drive_frequency_hz = { distribution = "values", values = [8195.0, 8195.0, 8195.0, 8600.0] }
"""
GYROS = 4
SECONDS = 1.0
SEED = 13
TARGETS = ("residual_dps<=0.05", "settling_ms<=400")


@pytest.fixture(scope="module")
def config_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("population") / "spread.toml"
    path.write_text(CONFIG)
    return path


@pytest.fixture(scope="module")
def cli_files(config_file):
    """``population.csv`` and ``summary.json`` of ``gyrofx population`` for the tiny run."""
    out = config_file.parent / "cli"
    arguments = ["population", "--config", str(config_file), "--gyros", str(GYROS)]
    arguments += ["--seconds", str(SECONDS), "--seed", str(SEED), "--out", str(out), "--quiet"]
    for target in TARGETS:
        arguments += ["--target", target]
    run_cli(*arguments)
    return {name: (out / name).read_bytes() for name in ("population.csv", "summary.json")}


def study(config_file, **options):
    return gyrofx.population(
        config_file, gyros=GYROS, seconds=SECONDS, seed=SEED, targets=TARGETS, **options
    )


def assert_same_files(result, cli_files, folder):
    """The result's files, written and as text, are the CLI's byte for byte."""
    written = result.write(folder)
    assert [p.name for p in written] == ["population.csv", "summary.json"]
    for path in written:
        assert path.read_bytes() == cli_files[path.name], path.name
    assert result.csv.encode() == cli_files["population.csv"]
    assert result.summary_json.encode() == cli_files["summary.json"]


def test_the_local_run_is_the_clis_byte_for_byte(config_file, cli_files, tmp_path):
    result = study(config_file, jobs=2)
    assert_same_files(result, cli_files, tmp_path / "threads")
    rows = result.rows()
    assert [r["member"] for r in rows] == [str(i) for i in range(GYROS)]
    assert len({r["a.q_drive"] for r in rows}) == GYROS, "the members differ"
    assert result.summary["report"]["counts"]["members"] == GYROS
    assert [r["status"] for r in rows] == ["ok", "ok", "ok", "unlocked"]
    assert '"gyro a: drive resonance 8600.000 Hz' in result.lines[3]
    assert result.columns == result.header.rstrip("\n").split(",")


def test_a_local_cluster_gives_the_clis_files(config_file, cli_files, tmp_path):
    with LocalCluster(
        n_workers=2,
        processes=True,
        threads_per_worker=1,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        local_directory=str(tmp_path / "dask"),
    ) as cluster, Client(cluster) as client:
        result = study(config_file, client=client, batch=1, in_flight=3)
        assert_same_files(result, cli_files, tmp_path / "local-cluster")
        assert_both_workers_studied(client)


def assert_both_workers_studied(client):
    """Both workers imported the compiled module: the batches ran there (the client ships a
    function of the pure-Python module and plain arguments, nothing compiled)."""
    loaded = client.run(lambda: "gyrofx._gyrofx" in sys.modules)
    assert list(loaded.values()) == [True, True], loaded


def dask_command():
    """dask's own command, the one of the Python running the tests."""
    path = pathlib.Path(sys.executable).parent / "dask"
    return [str(path)] if path.exists() else [sys.executable, "-m", "dask"]


@pytest.fixture
def scheduler_and_workers(tmp_path):
    """A scheduler and two single-threaded workers on 127.0.0.1, started as processes with
    ``dask scheduler`` and ``dask worker``, and a client on them; each process group is ended
    by its id when the test ends, also when it fails."""
    scheduler_file = tmp_path / "scheduler.json"
    processes = []
    logs = []

    def start(arguments, name):
        log = open(tmp_path / f"{name}.log", "wb")
        logs.append(log)
        processes.append(
            subprocess.Popen(
                dask_command() + arguments,
                stdout=log,
                stderr=subprocess.STDOUT,
                cwd=tmp_path,
                start_new_session=True,
            )
        )

    client = None
    try:
        start(
            ["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(scheduler_file)],
            "scheduler",
        )
        deadline = time.monotonic() + 60
        while not scheduler_file.exists():
            assert processes[0].poll() is None, (tmp_path / "scheduler.log").read_text()
            assert time.monotonic() < deadline, "the scheduler wrote no scheduler file in 60 s"
            time.sleep(0.1)
        for k in range(2):
            start(
                ["worker", "--scheduler-file", str(scheduler_file), "--nthreads", "1",
                 "--host", "127.0.0.1", "--no-dashboard",
                 "--local-directory", str(tmp_path / f"worker{k}")],
                f"worker{k}",
            )
        client = Client(scheduler_file=str(scheduler_file), timeout=60)
        client.wait_for_workers(2, timeout=120)
        yield client
    finally:
        if client is not None:
            client.close()
        for process in reversed(processes):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in reversed(processes):
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()
        for log in logs:
            log.close()


def test_a_scheduler_and_workers_started_by_dask_give_the_clis_files(
    config_file, cli_files, scheduler_and_workers, tmp_path
):
    client = scheduler_and_workers
    result = study(config_file, client=client, batch=1)
    assert_same_files(result, cli_files, tmp_path / "cluster")
    assert_both_workers_studied(client)


def test_a_bad_config_raises_the_clis_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[population.resonator]\nq_drive = { distribution = "gauss", std = 0.1 }\n')
    cli = run_cli("population", "--config", str(bad), "--gyros", "1", "--out",
                  str(tmp_path / "out"), "--quiet", check=False)
    assert cli.returncode != 0
    with pytest.raises(gyrofx.GyrofxError) as refused:
        gyrofx.population(bad, gyros=1, seconds=0.1)
    message = str(refused.value)
    assert 'q_drive.distribution = "gauss" is not allowed' in message
    assert message in cli.stderr, (message, cli.stderr)
    with pytest.raises(gyrofx.GyrofxError, match="is not a figure"):
        gyrofx.population(toml="", gyros=1, seconds=0.1, targets=["residual<=1"])
    with pytest.raises(gyrofx.GyrofxError, match="gyros 0 is not allowed"):
        gyrofx.population(gyros=0)
