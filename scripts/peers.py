#!/usr/bin/env python3
"""gyro-cli beside what a user would pick instead, on the same rest-to-rest spans of the shared
real recordings: rest-to-rest angle error, median (p90) per dataset.

Methods (each gives an angle series; a span's estimate is its angle at the middle of the rest
after less at the middle of the rest before):

- `gyro-cli run` (causal, default settings) and `gyro-cli run --offline`, on the single-axis
  files as they are (the tool puts them on its own grid): their 50 Hz `--out` series;
- plain per-rest mean: trapezoid on the logged stamps less the mean rate of the central part
  of the rest before (`rasteiro_turns.plain`);
- VQF 2.1.2 (`pip install vqf`), default parameters, on the three-axis source files:
  `6D` (`VQF.updateGyr`/`updateAcc`, `getQuat6D`), `gyro-only` (the same filter's gyroscope
  strapdown quaternion `getQuat3D`: gyro less VQF's bias estimate, no inclination
  correction), `offline 6D` (`offlineVQF`, acausal);
- Fusion 1.3.3 (`pip install imufusion`), `6D + bias`: `Bias` (gyroscope offset at rest,
  its default 3 deg/s, 3 s) then `Ahrs.update_no_magnetometer`, gain 0.5, acceleration
  rejection 10 deg, recovery after 5 s, gyroscope range 2000 deg/s.

A peer's angle about the file's axis is the sum over steps of the body-frame increment
`dq = conj(q[k-1]) * q[k]` about that axis, `2 atan2(dq_axis, dq_w)`: the integral of the body
rate about the axis, which is what the references are (BROAD's by construction, rasteiro's for
turns about one axis).

The regular grid the peers need: rasteiro's rows arrive in bursts (PC stamps, steps 2.5-17 ms),
so each gyro axis is integrated (trapezoid) on the stamps, that integral interpolated linearly
at a 100 Hz grid (the sensors' nominal rate) from the first stamp, and differenced: each grid
step's rate is the mean rate over it, so no rotation is lost or invented; the accelerometer is
interpolated linearly. BROAD is regular (285.714 Hz) and used as it is.

Spans: rasteiro as `rasteiro_turns.py` finds them (turns about the file's own axis, more than
20 deg, between rests); BROAD between rests of the optical reference (its rate magnitude,
each axis's rate smoothed over 0.5 s, its magnitude below 1 deg/s for at least 3 s, per the
data's README), every body axis
whose reference turns by more than 20 deg; truth: the reference's median over the central part
of the rest after less before (0.25 s trimmed each end).

Usage: python3 scripts/peers.py [--gyro target/release/gyro-cli] [--data ../shared/data/real]
"""
import glob
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rasteiro_turns as rt  # noqa: E402

GRID_HZ = 100.0
MIN_SPAN_DEG = 20.0
BROAD_REST_DPS = 1.0
BROAD_REST_SMOOTH_S = 0.5
BROAD_REST_MIN_S = 3.0
METHODS = [
    "gyro-cli",
    "gyro-cli --offline",
    "plain per-rest",
    "VQF 6D",
    "VQF gyro-only",
    "Fusion 6D + bias",
    "VQF offline 6D",
]


def option(name, default):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def gyro_series(gyro, path, offline):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "series.csv")
        args = [gyro, "run", path, "--out", out] + (["--offline"] if offline else [])
        subprocess.run(args, check=True, capture_output=True)
        s = pd.read_csv(out, comment="#")
    return s["time_s"].to_numpy(), s["angle_deg"].to_numpy()


def regular_grid(t, gyr, acc, rate_hz):
    """Grid times, the mean rate over each step (ending at that time) and the accelerometer
    there: the rate's integral on the stamps, interpolated and differenced."""
    grid = np.arange(t[0], t[-1], 1.0 / rate_hz)
    integral = np.concatenate(
        [np.zeros((1, 3)), np.cumsum(0.5 * (gyr[1:] + gyr[:-1]) * np.diff(t)[:, None], axis=0)]
    )
    at = np.stack([np.interp(grid, t, integral[:, i]) for i in range(3)], axis=1)
    rate = np.vstack([gyr[:1], np.diff(at, axis=0) * rate_hz])
    acc_grid = np.stack([np.interp(grid, t, acc[:, i]) for i in range(3)], axis=1)
    return grid, rate, acc_grid


def axis_angles(quats, axis):
    """Cumulative body-frame rotation about `axis` (0, 1, 2) of a quaternion series (w, x, y,
    z; sensor to earth), deg."""
    q = np.asarray(quats, dtype=float)
    w0, v0 = q[:-1, 0], -q[:-1, 1:]
    w1, v1 = q[1:, 0], q[1:, 1:]
    # dq = conj(q0) * q1
    dw = w0 * w1 - np.sum(v0 * v1, axis=1)
    dv = w0[:, None] * v1 + w1[:, None] * v0 + np.cross(v0, v1)
    sign = np.where(dw < 0, -1.0, 1.0)
    inc = 2.0 * np.degrees(np.arctan2(sign * dv[:, axis], sign * dw))
    return np.concatenate([[0.0], np.cumsum(inc)])


def peer_quats(gyr_dps, acc_mps2, rate_hz):
    """Quaternion series per peer, on the grid."""
    import imufusion
    import vqf

    ts = 1.0 / rate_hz
    gyr = np.ascontiguousarray(np.radians(gyr_dps))
    acc = np.ascontiguousarray(acc_mps2)
    v = vqf.VQF(ts)
    q6, q3 = np.empty((len(gyr), 4)), np.empty((len(gyr), 4))
    for k in range(len(gyr)):
        v.updateGyr(gyr[k])
        v.updateAcc(acc[k])
        q6[k] = v.getQuat6D()
        q3[k] = v.getQuat3D()
    offline = vqf.offlineVQF(gyr, acc, None, ts)["quat6D"]
    settings = imufusion.AhrsSettings()
    settings.sample_rate = int(round(rate_hz))
    settings.gain = 0.5
    settings.gyroscope_range = 2000.0
    settings.acceleration_rejection = 10.0
    settings.rejection_timeout = int(5 * rate_hz)
    ahrs = imufusion.Ahrs()
    ahrs.set_settings(settings)
    bias_settings = imufusion.BiasSettings()
    bias_settings.sample_rate = rate_hz
    bias = imufusion.Bias()
    bias.set_settings(bias_settings)
    qf = np.empty((len(gyr), 4))
    acc_g = acc_mps2 / 9.80665
    for k in range(len(gyr)):
        g = bias.update(np.ascontiguousarray(gyr_dps[k], dtype=float))
        ahrs.update_no_magnetometer(np.asarray(g, dtype=float), np.ascontiguousarray(acc_g[k], dtype=float))
        qf[k] = ahrs.get_quaternion()
    return {"VQF 6D": q6, "VQF gyro-only": q3, "Fusion 6D + bias": qf, "VQF offline 6D": offline}


def estimates(series, t0, t1):
    return {name: np.interp(t1, st, sa) - np.interp(t0, st, sa) for name, (st, sa) in series.items()}


def rasteiro(data, gyro):
    errors = {m: [] for m in METHODS}
    files = sorted(glob.glob(os.path.join(data, "rasteiro", "3axis", "*.csv")))
    for three in files:
        name = os.path.basename(three)[: -len(".csv")]
        d3 = pd.read_csv(three, comment="#")
        t3 = d3["time_s"].to_numpy()
        gyr = d3[["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"]].to_numpy()
        acc = d3[["acc_x_g", "acc_y_g", "acc_z_g"]].to_numpy() * 9.80665
        grid, rate, acc_grid = regular_grid(t3, gyr, acc, GRID_HZ)
        quats = peer_quats(rate, acc_grid, GRID_HZ)
        for axis, letter in enumerate("xyz"):
            path = os.path.join(data, "rasteiro", f"rasteiro_{name}_{letter}.csv")
            d = pd.read_csv(path, comment="#")
            t, w, ref = (d[c].to_numpy() for c in ("time_s", "rate_dps", "reference_deg"))
            series = {
                "gyro-cli": gyro_series(gyro, path, False),
                "gyro-cli --offline": gyro_series(gyro, path, True),
            }
            for peer, q in quats.items():
                series[peer] = (grid, axis_angles(q, axis))
            found = rt.rests(t, w, ref)
            cells = []
            for before, after in zip(found, found[1:]):
                lo, hi = rt.central(t, *before)
                lo2, hi2 = rt.central(t, *after)
                r0, r1 = rt.rest_angle(ref, lo, hi), rt.rest_angle(ref, lo2, hi2)
                if r0 is None or r1 is None:
                    continue
                t0 = 0.5 * (t[before[0]] + t[before[1]])
                t1 = 0.5 * (t[after[0]] + t[after[1]])
                p = rt.plain(t, w, before, t0, t1)
                truth = r1 - r0
                truth += 360.0 * np.round((p - truth) / 360.0)
                if abs(truth) < rt.MIN_TURN_DEG or abs(p) < rt.MIN_TURN_DEG:
                    continue
                est = estimates(series, t0, t1)
                est["plain per-rest"] = p
                for m in METHODS:
                    errors[m].append(est[m] - truth)
                cells.append(f"{truth:+.0f}")
            print(f"  rasteiro {name}_{letter}: {len(cells)} turns {' '.join(cells)}", file=sys.stderr)
    return errors


def broad_rests(t, refs):
    """(start, end) index pairs where the reference's rate magnitude, smoothed over 0.5 s, stays
    below 1 deg/s for at least 3 s."""
    dt = np.median(np.diff(t))
    n = max(1, int(round(BROAD_REST_SMOOTH_S / dt)))
    # Each axis's rate smoothed (a moving mean of the gradient), then the magnitude.
    rates = np.stack(
        [np.convolve(np.gradient(r, t), np.ones(n) / n, mode="same") for r in refs], axis=1
    )
    still = np.sqrt(np.sum(rates**2, axis=1)) < BROAD_REST_DPS
    out, i = [], 0
    while i < len(t):
        if not still[i]:
            i += 1
            continue
        k = i
        while k < len(t) and still[k]:
            k += 1
        if t[k - 1] - t[i] >= BROAD_REST_MIN_S:
            out.append((i, k - 1))
        i = k
    return out


def broad(data, gyro):
    errors = {m: [] for m in METHODS}
    for three in sorted(glob.glob(os.path.join(data, "broad", "broad_*_3axis.csv"))):
        trial = os.path.basename(three)[: -len("_3axis.csv")]
        d3 = pd.read_csv(three, comment="#")
        t3 = d3["time_s"].to_numpy()
        rate_hz = 1.0 / np.median(np.diff(t3))
        gyr = np.degrees(d3[["gyro_x_rps", "gyro_y_rps", "gyro_z_rps"]].to_numpy())
        acc = d3[["acc_x_mps2", "acc_y_mps2", "acc_z_mps2"]].to_numpy()
        quats = peer_quats(gyr, acc, rate_hz)
        axes = []
        for letter in "xyz":
            path = os.path.join(data, "broad", f"{trial}_{letter}.csv")
            d = pd.read_csv(path, comment="#")
            axes.append((path, d["time_s"].to_numpy(), d["rate_dps"].to_numpy(), d["reference_deg"].to_numpy()))
        t = axes[0][1]
        found = broad_rests(t, [a[3] for a in axes])
        cells = []
        for axis, (path, _, w, ref) in enumerate(axes):
            series = {
                "gyro-cli": gyro_series(gyro, path, False),
                "gyro-cli --offline": gyro_series(gyro, path, True),
            }
            for peer, q in quats.items():
                series[peer] = (t3, axis_angles(q, axis))
            for before, after in zip(found, found[1:]):
                lo, hi = rt.central(t, *before)
                lo2, hi2 = rt.central(t, *after)
                truth = np.median(ref[lo2:hi2]) - np.median(ref[lo:hi])
                if abs(truth) < MIN_SPAN_DEG:
                    continue
                t0 = 0.5 * (t[before[0]] + t[before[1]])
                t1 = 0.5 * (t[after[0]] + t[after[1]])
                est = estimates(series, t0, t1)
                est["plain per-rest"] = rt.plain(t, w, before, t0, t1)
                for m in METHODS:
                    errors[m].append(est[m] - truth)
                cells.append(f"{'xyz'[axis]}{truth:+.0f}")
        print(f"  BROAD {trial}: {len(found)} rests, spans {' '.join(cells)}", file=sys.stderr)
    return errors


def cell(e):
    a = np.abs(e)
    return f"{np.median(a):.2f}° ({np.percentile(a, 90):.2f})"


def main():
    gyro = option("--gyro", "target/release/gyro-cli")
    data = option("--data", os.path.join(os.path.dirname(__file__), "../../shared/data/real"))
    results = [("rasteiro", rasteiro(data, gyro)), ("BROAD", broad(data, gyro))]
    print("rest-to-rest angle error, median (p90), deg\n")
    print("| | spans | " + " | ".join(METHODS) + " |")
    print("|---|---|" + "---|" * len(METHODS))
    for name, errors in results:
        n = len(errors[METHODS[0]])
        print(f"| {name} | {n} | " + " | ".join(cell(errors[m]) for m in METHODS) + " |")
    print()
    for name, errors in results:
        med = {m: np.median(np.abs(errors[m])) for m in METHODS}
        causal_peers = ["plain per-rest", "VQF 6D", "VQF gyro-only", "Fusion 6D + bias"]
        best = min(causal_peers, key=lambda m: med[m])
        print(
            f"{name}: --offline / best causal peer ({best}) {med['gyro-cli --offline'] / med[best]:.2f}, "
            f"/ VQF offline {med['gyro-cli --offline'] / med['VQF offline 6D']:.2f}; "
            f"causal gyro-cli / best causal peer {med['gyro-cli'] / med[best]:.2f}"
        )


if __name__ == "__main__":
    main()
