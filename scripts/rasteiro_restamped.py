#!/usr/bin/env python3
"""The rasteiro recordings as other loggers would stamp them: `gyro-cli run` beside the plain
estimator, per turn, rest to rest (the method of scripts/rasteiro_turns.py).

Each recording's rows are kept (rates and reference as logged) and only their time stamps
changed, as loggers the team has not seen do:

- `as logged`: the recordings' own stamps (PC arrival, bursts);
- `1 ms`: rounded to the millisecond;
- `10 ms`: rounded to 10 ms (steps of 0, 10 and 20 ms; stamps coarser than the rows);
- `15.6 ms floor`: truncated to the 64 Hz tick of a PC timer;
- `packets of 4`: four rows stamped with the last one's arrival (a link that sends packets);
- `packets of 4, 50 us`: the same, 50 microseconds apart within a packet;
- `jitter 3 ms`: each stamp moved by up to 3 ms (uniform, seed 7), rows re-sorted;
- `5% rows lost`: one row in twenty dropped (seed 7);
- `epoch`: 1.7e9 s added (Unix time).

The truth and the rests come from the recording as logged; the plain estimator runs on the
re-stamped rows (trapezoid on the stamps minus the mean rate of the central rest before),
`gyro-cli run` (default settings) on the re-stamped file. Prints, per stamping, the median,
90th percentile and largest |error| over the 42 turns, and run / plain of the medians.

Usage: python3 scripts/rasteiro_restamped.py [DATA_DIR] [--gyro target/release/gyro-cli]
"""
import glob
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rasteiro_turns as rt  # noqa: E402


def packets(t, spacing_s):
    out = t.copy()
    n = len(t)
    for i in range(0, n, 4):
        arrival = t[min(i + 3, n - 1)]
        for k in range(i, min(i + 4, n)):
            out[k] = arrival + (k - i) * spacing_s
    return out


def stampings(t, seed=7):
    """name -> (stamps, rows kept or None)."""
    rng = np.random.default_rng(seed)
    n = len(t)
    keep = rng.random(n) > 0.05
    keep[0] = keep[-1] = True
    return {
        "as logged": (t, None),
        "1 ms": (np.round(t / 1e-3) * 1e-3, None),
        "10 ms": (np.round(t / 1e-2) * 1e-2, None),
        "15.6 ms floor": (np.floor(t / 0.015625) * 0.015625, None),
        "packets of 4": (packets(t, 0.0), None),
        "packets of 4, 50 us": (packets(t, 50e-6), None),
        "jitter 3 ms": (np.sort(t + rng.uniform(-3e-3, 3e-3, n)), None),
        "5% rows lost": (t, keep),
        "epoch": (t + 1.7e9, None),
    }


def plain_on(tt, ww, t_rest0, t_rest1, t0, t1):
    """The plain estimator on (possibly re-stamped) rows: bias from [t_rest0, t_rest1]."""
    b0, b1 = np.searchsorted(tt, t_rest0), np.searchsorted(tt, t_rest1)
    bias = ww[b0 : max(b1, b0 + 1)].mean()
    k0, k1 = np.searchsorted(tt, t0), np.searchsorted(tt, t1)
    sw, st = ww[k0 : k1 + 1], tt[k0 : k1 + 1]
    return np.sum(0.5 * (sw[1:] + sw[:-1]) * np.diff(st)) - bias * (st[-1] - st[0])


def main():
    args = rt.positional_args()
    data = args[0] if args else os.path.join(os.path.dirname(__file__), "../../shared/data/real/rasteiro")
    gyro = sys.argv[sys.argv.index("--gyro") + 1] if "--gyro" in sys.argv else "target/release/gyro-cli"
    errors = {}
    for path in sorted(glob.glob(os.path.join(data, "rasteiro_*.csv"))):
        d = pd.read_csv(path, comment="#")
        t, w, ref = (d[c].to_numpy() for c in ("time_s", "rate_dps", "reference_deg"))
        found = rt.rests(t, w, ref)
        for name, (tv, keep) in stampings(t).items():
            offset = tv[0] - t[0] if name == "epoch" else 0.0
            dv = pd.DataFrame({"time_s": tv, "rate_dps": w, "reference_deg": ref})
            if keep is not None:
                dv = dv[keep]
            with tempfile.TemporaryDirectory() as tmp:
                p = os.path.join(tmp, "restamped.csv")
                dv.to_csv(p, index=False, float_format="%.6f")
                try:
                    st, sa = rt.run_series(gyro, p)
                except subprocess.CalledProcessError as e:
                    print(f"{name}: {os.path.basename(path)}: run failed: {e.stderr.decode().strip()}")
                    continue
            tt, ww = dv["time_s"].to_numpy(), dv["rate_dps"].to_numpy()
            for before, after in zip(found, found[1:]):
                lo, hi = rt.central(t, *before)
                lo2, hi2 = rt.central(t, *after)
                r0, r1 = rt.rest_angle(ref, lo, hi), rt.rest_angle(ref, lo2, hi2)
                if r0 is None or r1 is None:
                    continue
                truth = r1 - r0
                t0, t1 = 0.5 * (t[before[0]] + t[before[1]]), 0.5 * (t[after[0]] + t[after[1]])
                p = rt.plain(t, w, before, t0, t1)
                truth += 360.0 * np.round((p - truth) / 360.0)
                if abs(truth) < rt.MIN_TURN_DEG or abs(p) < rt.MIN_TURN_DEG:
                    continue
                rest0 = t[before[0]] + rt.TRIM_S + offset
                rest1 = t[before[1]] - rt.TRIM_S + offset
                pv = plain_on(tt, ww, rest0, rest1, t0 + offset, t1 + offset)
                r = np.interp(t1 + offset, st, sa) - np.interp(t0 + offset, st, sa)
                errors.setdefault(name, []).append((pv - truth, r - truth))
    print(f"{'stamps':<20} {'turns':>5}  {'plain med':>9} {'p90':>6} {'max':>6}  {'run med':>8} {'p90':>6} {'max':>6}  run/plain")
    for name, found in errors.items():
        e = np.abs(np.array(found))
        pe, re = e[:, 0], e[:, 1]
        print(
            f"{name:<20} {len(e):>5}  {np.median(pe):>9.2f} {np.percentile(pe, 90):>6.2f} {pe.max():>6.1f}"
            f"  {np.median(re):>8.2f} {np.percentile(re, 90):>6.2f} {re.max():>6.1f}  {np.median(re) / np.median(pe):>9.2f}"
        )


if __name__ == "__main__":
    main()
