#!/usr/bin/env python3
"""The plain analyst's estimate on the ssong recordings, to set beside `gyro-cli diagnose`.

For each recording: drop duplicate stamps, interpolate gyro and encoder onto a 1 ms grid,
low-pass both with the same zero-phase 4th-order 5 Hz Butterworth (so no lag is added),
differentiate the encoder angle, then
- lag: the shift of the gyro (1 ms steps, refined by a parabola) that minimises the
  residual of the least-squares fit gyro = (1 + k) * encoder_rate + b;
- k: the gyro's scale against the encoder at that lag (the encoder itself reads
  351/360 of the shaft angle, see the data README);
- b: the bias (deg/s);
- N: the effective noise on moving data, on the 100 Hz samples as logged: per 100 s
  window, the residual of gyro - encoder rate (centred difference) regressed on
  [1, rate, acceleration, jerk]; the largest white noise its Allan deviation allows from
  tau = 1 s to 10 s (deg/sqrt(h)).
Usage: scripts/ssong_plain.py [DATA_DIR]   (needs numpy, pandas, scipy)
"""
import sys
import numpy as np
import pandas as pd
from scipy.signal import butter, sosfiltfilt

root = sys.argv[1] if len(sys.argv) > 1 and __name__ == "__main__" else "../shared/data/real"
sos = butter(4, 5.0, fs=1000.0, output="sos")


def effective_arw(g, ref, fs=100.0, window_s=100.0):
    """N (deg/sqrt(h)): the largest white noise the Allan deviation of the regression
    residual allows from tau = 1 s to 10 s, min over tau of adev(tau) * sqrt(tau) * 60. The
    residual: per window, gyro (averaged over the same 3 samples as the centred difference)
    minus the encoder rate, regressed on [1, rate, acceleration, jerk]."""
    w = np.gradient(ref) * fs
    gs = np.convolve(g, [0.25, 0.5, 0.25], "same")
    n, residuals = int(window_s * fs), []
    for k in range(0, len(g) - n + 1, n):
        rate = w[k:k + n]
        acc = np.gradient(rate) * fs
        design = np.c_[np.ones(n), rate, acc, np.gradient(acc) * fs][2:-2]
        y = (gs[k:k + n] - rate)[2:-2]
        residuals.append(y - design @ np.linalg.lstsq(design, y, rcond=None)[0])
    best = np.inf
    for m in np.unique(np.round(10 ** np.arange(0, 1.01, 0.1) * fs).astype(int)):
        d2 = [(lambda c: c[2 * m:] - 2 * c[m:-m] + c[:-2 * m])(np.cumsum(np.r_[0.0, r]) / fs) for r in residuals]
        avar = np.mean(np.concatenate(d2) ** 2) / (2 * (m / fs) ** 2)
        best = min(best, np.sqrt(avar * m / fs))
    return 60.0 * best


def plain_fit(path):
    """(lag in ms, refined by a parabola through the minimum; k; bias in deg/s) of one
    recording: the shift and the least-squares fit gyro = (1 + k) * encoder_rate + b."""
    d = pd.read_csv(path, comment="#").drop_duplicates("time_s")
    t, g, ref = d.time_s.values, d.rate_dps.values, d.reference_deg.values
    grid = np.arange(t[0], t[-1], 0.001)
    gyro = sosfiltfilt(sos, np.interp(grid, t, g))
    enc = sosfiltfilt(sos, np.gradient(np.interp(grid, t, ref), 0.001))
    n, m = len(grid), 2000

    def fit(lag):
        a, b = gyro[m + lag:n - m + lag], enc[m:n - m]
        design = np.c_[b, np.ones_like(b)]
        c = np.linalg.lstsq(design, a, rcond=None)[0]
        return np.sum((a - design @ c) ** 2), c

    lags = range(-10, 40)
    res = [fit(lag)[0] for lag in lags]
    i = int(np.argmin(res))
    best = lags[i]
    if 0 < i < len(res) - 1:  # parabola through the minimum and its neighbours
        y0, y1, y2 = res[i - 1], res[i], res[i + 1]
        best = lags[i] + 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    _, (scale, bias) = fit(lags[i])
    return best, scale - 1.0, bias


def main():
    print("recording            lag_ms   k_vs_encoder   bias_dps   N_deg_per_rt_h")
    for axis in "xyz":
        for speed in ("slow", "medium"):
            path = f"{root}/ssong_{axis}_{speed}.csv"
            best, k, bias = plain_fit(path)
            d = pd.read_csv(path, comment="#").drop_duplicates("time_s")
            arw = effective_arw(d.rate_dps.values, d.reference_deg.values)
            print(f"ssong_{axis}_{speed:<8} {best:8.2f}   {100 * k:+8.2f} %   {bias:+8.3f}   {arw:8.1f}")


if __name__ == "__main__":
    main()
