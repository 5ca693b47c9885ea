"""gyro.run_arrays and gyro.run against gyro-cli run on the same samples: one hour at 1 kHz.

    python crates/gyro-py/bench/overhead.py --cli target/release/gyro-cli [--log /tmp/hour.csv]

Makes the log with `gyro-cli simulate --duration-s 3600` unless it exists, reads it into
numpy arrays, then times, `--repeat` times each, interleaved: `gyro-cli run LOG --format
json` (a process: reading the CSV, the replay, the JSON), `gyro.run(LOG)` (the same in
this process), and `gyro.run_arrays` on the arrays (the replay and the JSON, the CSV already
parsed). Prints the medians and their ratios to the CLI's, and checks the three agree.
A benchmark, not a test: the figures depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import time

import numpy as np

import gyro


def read_columns(path: pathlib.Path):
    """The log's columns as float64 arrays and its nominal rate (a CSV without gaps)."""
    header_lines, nominal = 0, None
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                names = line.strip().split(",")
                break
            header_lines += 1
            key, _, value = line[1:].partition(":")
            if key.strip() == "sample_rate_hz":
                nominal = float(value)
    data = np.loadtxt(path, delimiter=",", skiprows=header_lines + 1, dtype=np.float64)
    cols = {n: np.ascontiguousarray(data[:, i]) for i, n in enumerate(names)}
    return cols, nominal, header_lines + 2


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cli", default=os.environ.get("GYRO_CLI", "target/release/gyro-cli"))
    p.add_argument("--log", type=pathlib.Path, default=pathlib.Path("/tmp/gyro_hour_1khz.csv"))
    p.add_argument("--repeat", type=int, default=5)
    a = p.parse_args()
    if not a.log.exists():
        subprocess.run([a.cli, "simulate", "-o", str(a.log), "--duration-s", "3600", "--seed", "1"],
                       check=True, capture_output=True)
    cols, nominal, first_line = read_columns(a.log)
    n = len(cols["time_s"])

    def cli():
        out = subprocess.run([a.cli, "run", str(a.log), "--format", "json"],
                             check=True, capture_output=True, text=True)
        return json.loads(out.stdout)

    def from_file():
        return gyro.run(str(a.log))

    def from_arrays():
        return gyro.run_arrays(cols["time_s"], cols["rate_dps"], cols.get("reference_deg"),
                               cols.get("temperature_c"), nominal_rate_hz=nominal,
                               name=str(a.log), first_line=first_line)

    times = {"gyro-cli run": [], "gyro.run": [], "gyro.run_arrays": []}
    results = {}
    for _ in range(a.repeat):
        for name, call in zip(times, (cli, from_file, from_arrays)):
            start = time.perf_counter()
            results[name] = call()
            times[name].append(time.perf_counter() - start)
    expected = results["gyro-cli run"]
    for name in ("gyro.run", "gyro.run_arrays"):
        got = {k: v for k, v in results[name].items() if k != "series"}
        assert got == expected, f"{name} differs from gyro-cli run"
    base = statistics.median(times["gyro-cli run"])
    print(f"{n} samples ({n / 1000 / 3600:.2f} h at 1 kHz), {a.repeat} runs each, median (min-max):")
    for name, t in times.items():
        print(f"  {name:16s} {statistics.median(t):6.3f} s ({min(t):.3f}-{max(t):.3f})"
              f"  {statistics.median(t) / base:.2f}x the CLI")
    print("results: equal to the CLI's JSON")


if __name__ == "__main__":
    main()
