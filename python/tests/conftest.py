"""Shared fixtures: the repository, the gyrofx CLI, and a package it generates once per run."""

import csv
import os
import pathlib
import subprocess

import pytest

REPOSITORY = pathlib.Path(__file__).resolve().parents[2]


def cli():
    """The gyrofx CLI: $GYROFX_CLI (scripts/test.sh sets it), else `cargo run` in the repo."""
    path = os.environ.get("GYROFX_CLI")
    if path:
        return [path]
    return ["cargo", "run", "--quiet", "--release", "--manifest-path", str(REPOSITORY / "Cargo.toml"), "--"]


def run_cli(*arguments, check=True):
    return subprocess.run(cli() + list(arguments), capture_output=True, text=True, check=check)


def read_vectors(path):
    """The rows of a gyrofx vector CSV as dicts of strings (`#` lines skipped)."""
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(lines))


@pytest.fixture(scope="session")
def package(tmp_path_factory):
    """A package of the default config, 3000 samples, seed 5: every block's vectors."""
    folder = tmp_path_factory.mktemp("package") / "out"
    run_cli("generate", "--out", str(folder), "--samples", "3000", "--seed", "5", "--quiet")
    return folder
