#!/usr/bin/env python3
"""Runs `gyrofx allan` on public real records and prints the tables of the guide's
"Real records" section (docs/guide/src/how-to/noise-analysis.md). Offline: the records are not
in this repository (their licences do not allow it); the guide says where to get them.

  scripts/real-records.py adis DIR        # DIR/adis16405_imu{1..6}_gyro.csv, 100 Hz
  scripts/real-records.py stable32 CSV TABLE [--rate HZ] [--kind overlapping|nonoverlapping]

`adis` prints, per record and axis, the fitted N and B with their intervals beside the IEEE-952
readings (N = sigma(1 s) * sqrt(1 s), log-log interpolated; B = min ADEV / 0.6643), what is identified, the model's
error and the leading tau left out. `stable32` compares gyrofx's deviation with a Stable32
table ("AF Tau # Alpha MinSigma Sigma MaxSigma" rows) at every averaging factor both have and
prints the largest relative difference. GYROFX (default target/release/gyrofx) names the binary.
Standard library only.
"""

import json
import os
import subprocess
import sys

GYROFX = os.environ.get("GYROFX", "target/release/gyrofx")


def allan(path, columns, rate, taus="octave", kind="overlapping"):
    """`gyrofx allan --json` on `columns` of `path`: one dict per column."""
    command = [GYROFX, "allan", "--input", path, "--rate", str(rate), "--taus", taus,
               "--kind", kind, "--json", "--quiet"]
    for column in columns:
        command += ["--column", column]
    result = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
    return result if isinstance(result, list) else [result]


def at_one_second(series):
    """sigma(1 s) by log-log interpolation between the curve's points around 1 s."""
    import math
    points = list(zip(series["tau_s"], series["adev"]))
    for (t0, d0), (t1, d1) in zip(points, points[1:]):
        if t0 <= 1.0 <= t1:
            f = math.log(1.0 / t0) / math.log(t1 / t0)
            return math.exp(math.log(d0) + f * (math.log(d1) - math.log(d0)))
    return float("nan")


def interval(estimate):
    return f"{estimate['value']:.2f} [{estimate['lo']:.2f}, {estimate['hi']:.2f}]"


def adis(folder):
    print("| record | axis | N °/√h (fit) | N (σ(1 s) reading) | B °/h (fit) | B (min/0.6643) "
          "| K °/h/√h | model error | left out below τ (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for unit in range(1, 7):
        path = os.path.join(folder, f"adis16405_imu{unit}_gyro.csv")
        series = allan(path, ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"], 100)
        for axis, s in zip("xyz", series):
            noise, shown = s["noise"], s["identified"]
            k = noise["rrw_deg_per_h_per_sqrt_h"]
            k_text = (interval(k) if shown["rrw_deg_per_h_per_sqrt_h"]
                      else f"< {s['upper_bound']['rrw_deg_per_h_per_sqrt_h']:.0f}")
            b = noise["bias_instability_deg_per_h"]
            b_text = interval(b) if shown["bias_instability_deg_per_h"] else (
                f"< {s['upper_bound']['bias_instability_deg_per_h']:.1f}")
            white_reading = at_one_second(s) * 60.0
            print(f"| imu{unit} | {axis} | {interval(noise['arw_deg_per_sqrt_h'])} | "
                  f"{white_reading:.2f} | {b_text} | {noise['slope_bias_instability_deg_per_h']:.1f} | "
                  f"{k_text} | {100 * s['fit']['model_error']:.1f} % | "
                  f"{s['filtered_below_tau_s'] or '-'} |")


def stable32(csv, table, rate=1.0, kind="overlapping"):
    rows = [line.split() for line in open(table)
            if line.strip() and not line.lstrip().startswith("#")]
    reference = {int(r[0]): float(r[5]) for r in rows}
    with open(csv) as f:
        column = f.readline().strip().split(",")[0]
    samples = sum(1 for _ in open(csv)) - 1
    taus = "all" if samples <= 100_000 else "decade"
    series = allan(csv, [column], rate, taus=taus, kind=kind)[0]
    worst, compared = 0.0, 0
    for tau, dev in zip(series["tau_s"], series["adev"]):
        m = round(tau * rate)
        if m in reference:
            compared += 1
            worst = max(worst, abs(dev / reference[m] - 1))
    print(f"{table}: {compared} factors compared ({taus} grid), "
          f"largest relative difference {worst:.2e}")


def main(argv):
    if len(argv) >= 2 and argv[0] == "adis":
        adis(argv[1])
    elif len(argv) >= 3 and argv[0] == "stable32":
        options = dict(zip(argv[3::2], argv[4::2]))
        stable32(argv[1], argv[2], float(options.get("--rate", 1.0)),
                 options.get("--kind", "overlapping"))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
