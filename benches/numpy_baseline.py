#!/usr/bin/env python3
"""The numpy/scipy equivalent of `gyro-cli run`'s numeric core, for the throughput comparison.

Reads a log CSV (pandas' C parser), decimates by block means, low-passes with scipy's
Butterworth (order 2 at 12.5 Hz, as the pipeline's default) and integrates (trapezoidal).
No motion detection, no compensation, no error report: a lower bound of the work
`gyro-cli run` does. Prints the wall time and MB/s.

Usage: python3 benches/numpy_baseline.py LOG.csv [--factor 20]
"""
import os
import sys
import time

import numpy as np
import pandas as pd
from scipy import signal


def main():
    path = sys.argv[1]
    factor = int(sys.argv[sys.argv.index("--factor") + 1]) if "--factor" in sys.argv else 20
    start = time.perf_counter()
    data = pd.read_csv(path, comment="#", usecols=["time_s", "rate_dps"])
    rate = data["rate_dps"].to_numpy()
    n = len(rate) // factor * factor
    decimated = rate[:n].reshape(-1, factor).mean(axis=1)
    fs_out = 1000.0 / factor
    sos = signal.butter(2, 12.5, fs=fs_out, output="sos")
    filtered = signal.sosfilt(sos, decimated)
    angle = np.concatenate([[0.0], np.cumsum((filtered[1:] + filtered[:-1]) / 2) / fs_out])
    elapsed = time.perf_counter() - start
    size_mb = os.path.getsize(path) / 1e6
    print(
        f"{path}: {len(rate)} samples, {size_mb:.1f} MB in {elapsed:.3f} s: "
        f"{size_mb / elapsed:.1f} MB/s, {len(rate) / elapsed / 1e6:.2f} M samples/s "
        f"(final angle {angle[-1]:.3f} deg)"
    )


if __name__ == "__main__":
    main()
