#!/usr/bin/env python3
"""Per-turn angle error on the rasteiro recordings: `gyro-cli run` beside the plain estimator.

The recordings (../shared/data/real/rasteiro, see its README) are rest, turn, rest: a robot
turns a board of IMUs, and its pose (the reference) is exact at rest. For every turn about
the file's own axis (the reference changes by more than 20 degrees between two rests):

- truth: the reference's median over the rest after minus over the rest before;
- plain estimator (ten lines of numpy): trapezoid integration of `rate_dps` on the logged
  stamps from the middle of the rest before to the middle of the rest after, minus the mean
  rate of the rest before (its central part) times the time integrated;
- `gyro-cli run` (default settings): its 50 Hz angle series (`--out`), the angle at the
  middle of the rest after minus at the middle of the rest before.

The pose wraps by whole turns in places, even within a rest (at 180 degrees it flips to
-180, and the recordings' cumulative angle then jumps by 360): rests compare angles modulo
360 degrees, and the truth is taken modulo 360 degrees, as the multiple nearest the plain
estimate. A turn counts when both the reference and the plain estimate change by more than
20 degrees (the pose of one axis also changes when the board turns about another: the
Euler angles couple; the gyro of that axis then sees only leakage). Rests are stretches of at least 0.6 s where, over any 0.2 s, the rate spans less than
2 deg/s (a turn about another axis leaves this axis's pose still but not its gyro) and at
least 60% of the pose samples agree to 0.05 degrees modulo 360 (at 180 degrees the pose
flips to -180 and the recordings' resampling interpolates across the flip, so some rest
samples hold neither value); the pose over a rest is the value most of its samples hold. The gyro lags the pose by 80-105 ms (cross-correlation), so rest means use only
the central part of each rest (0.25 s trimmed at each end).

Prints one line per file, then the median and 90th percentile of |error| per sensor and
speed for both estimators and their ratio (run / plain).

Usage: python3 scripts/rasteiro_turns.py [DATA_DIR] [--gyro target/release/gyro-cli]
"""
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

MIN_TURN_DEG = 20.0
REST_MIN_S = 0.6
REST_WINDOW_S = 0.2
REST_TOLERANCE_DEG = 0.05
REST_RATE_SPREAD_DPS = 2.0
TRIM_S = 0.25


def wrapped(deg):
    """Angles folded into [-180, 180)."""
    return (np.asarray(deg) + 180.0) % 360.0 - 180.0


def rest_angle(ref, lo, hi):
    """The pose over a rest, or None: the value (modulo 360 degrees) that most samples hold,
    when at least half of them do. At 180 degrees the pose flips to -180 and the recordings'
    resampling interpolates across the flip, so some rest samples hold neither value."""
    values = ref[lo:hi]
    held = [np.sum(np.abs(wrapped(values - v)) < REST_TOLERANCE_DEG) for v in values]
    best = int(np.argmax(held))
    if held[best] < 0.5 * len(values):
        return None
    v = values[best]
    return v + np.median(wrapped(values - v)[np.abs(wrapped(values - v)) < REST_TOLERANCE_DEG])


def held(values):
    """True if at least 60% of `values` agree to REST_TOLERANCE_DEG modulo 360 degrees."""
    diff = np.abs(wrapped(values[:, None] - values[None, :])) < REST_TOLERANCE_DEG
    return diff.sum(axis=1).max() >= 0.6 * len(values)


def rests(t, w, ref):
    """(start, end) index pairs of the rests: for at least REST_MIN_S, the gyro still (its
    rate spans less than REST_RATE_SPREAD_DPS over every REST_WINDOW_S) and the pose held."""
    still = np.zeros(len(t), dtype=bool)
    j = 0
    for i in range(len(t)):
        while t[j] < t[i] - REST_WINDOW_S:
            j += 1
        rates = w[j : i + 1]
        still[i] = rates.max() - rates.min() < REST_RATE_SPREAD_DPS and held(ref[j : i + 1])
    out, i = [], 0
    while i < len(t):
        if not still[i]:
            i += 1
            continue
        # A still window ending at i means the rest began REST_WINDOW_S earlier.
        start = np.searchsorted(t, t[i] - REST_WINDOW_S)
        k = i
        while k < len(t) and still[k]:
            k += 1
        if t[k - 1] - t[start] >= REST_MIN_S:
            out.append((start, k - 1))
        i = k
    return out


def central(t, a, b):
    """Indices of the central part of rest [a, b]."""
    lo = np.searchsorted(t, t[a] + TRIM_S)
    hi = np.searchsorted(t, t[b] - TRIM_S)
    return (lo, max(hi, lo + 1))


def plain(t, w, rest_before, t0, t1):
    lo, hi = central(t, *rest_before)
    bias = w[lo:hi].mean()
    k0, k1 = np.searchsorted(t, t0), np.searchsorted(t, t1)
    seg_t, seg_w = t[k0 : k1 + 1], w[k0 : k1 + 1]
    return np.sum(0.5 * (seg_w[1:] + seg_w[:-1]) * np.diff(seg_t)) - bias * (seg_t[-1] - seg_t[0])


def run_series(gyro, path, run_args=()):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "series.csv")
        subprocess.run([gyro, "run", path, "--out", out, *run_args], check=True, capture_output=True)
        s = pd.read_csv(out, comment="#")
    return s["time_s"].to_numpy(), s["angle_deg"].to_numpy()


def turns(path, gyro, run_args=()):
    """(truth, plain error, run error) per turn; `run_args` go to `gyro-cli run`."""
    d = pd.read_csv(path, comment="#")
    t, w, ref = (d[c].to_numpy() for c in ("time_s", "rate_dps", "reference_deg"))
    found = rests(t, w, ref)
    st, sa = run_series(gyro, path, run_args)
    out = []
    for before, after in zip(found, found[1:]):
        lo, hi = central(t, *before)
        lo2, hi2 = central(t, *after)
        r0, r1 = rest_angle(ref, lo, hi), rest_angle(ref, lo2, hi2)
        if r0 is None or r1 is None:
            continue
        truth = r1 - r0
        t0, t1 = 0.5 * (t[before[0]] + t[before[1]]), 0.5 * (t[after[0]] + t[after[1]])
        p = plain(t, w, before, t0, t1)
        # The pose wraps by whole turns in places: take the multiple of 360 degrees the
        # gyro agrees with (any estimator here is off by far less than 180 degrees).
        truth += 360.0 * np.round((p - truth) / 360.0)
        if abs(truth) < MIN_TURN_DEG or abs(p) < MIN_TURN_DEG:
            continue
        r = np.interp(t1, st, sa) - np.interp(t0, st, sa)
        out.append((truth, p - truth, r - truth))
    return out


def positional_args():
    """The command line's positional arguments: neither an option (`--gyro`) nor the value
    after one."""
    return [a for i, a in enumerate(sys.argv[1:], 1)
            if not a.startswith("--") and not sys.argv[i - 1].startswith("--")]


def main():
    args = positional_args()
    data = args[0] if args else os.path.join(os.path.dirname(__file__), "../../shared/data/real/rasteiro")
    gyro = sys.argv[sys.argv.index("--gyro") + 1] if "--gyro" in sys.argv else "target/release/gyro-cli"
    groups = {}
    for path in sorted(glob.glob(os.path.join(data, "rasteiro_*.csv"))):
        name = os.path.basename(path)[len("rasteiro_") : -len(".csv")]
        sensor, speed = name.split("RM3100_")[0], name.split("RM3100_")[1].rsplit("_", 1)[0]
        found = turns(path, gyro)
        groups.setdefault((sensor, speed), []).extend(found)
        cells = " ".join(f"{tr:+7.1f}:{pe:+6.2f}/{re:+6.2f}" for tr, pe, re in found)
        print(f"{name:<28} turns (truth: plain/run error, deg) {cells}")
    print()
    print(f"{'sensor':<10} {'speed':<6} {'turns':>5}  {'plain med':>9} {'p90':>6}  {'run med':>8} {'p90':>6}  run/plain")
    for (sensor, speed), found in sorted(groups.items()):
        pe = np.abs([f[1] for f in found])
        re = np.abs([f[2] for f in found])
        print(
            f"{sensor:<10} {speed:<6} {len(found):>5}  {np.median(pe):>9.2f} {np.percentile(pe, 90):>6.2f}"
            f"  {np.median(re):>8.2f} {np.percentile(re, 90):>6.2f}  {np.median(re) / np.median(pe):>9.2f}"
        )
    for sensor in sorted({k[0] for k in groups}):
        found = [f for k, v in groups.items() if k[0] == sensor for f in v]
        pe = np.abs([f[1] for f in found])
        re = np.abs([f[2] for f in found])
        print(
            f"{sensor:<10} {'all':<6} {len(found):>5}  {np.median(pe):>9.2f} {np.percentile(pe, 90):>6.2f}"
            f"  {np.median(re):>8.2f} {np.percentile(re, 90):>6.2f}  {np.median(re) / np.median(pe):>9.2f}"
        )


if __name__ == "__main__":
    main()
