#!/usr/bin/env python3
"""`gyro-cli run` beside the plain estimator on the rasteiro sensors and speeds that are not
bundled in ../shared/data/real: the same robot path (path 1, `Sequencia1`) recorded by
four IMUs (MPU6050, MPU6500, MPU9150, LSM9DS0) at six speeds (V_300, V_500, V_800, V1000,
V1500, eV50p), read from a clone of the public dataset
(https://github.com/miguelrasteiro/IMU_dataset, MIT licence; nothing of it is copied here).

These .mat files are read as the bundled CSVs were made: `MATLABtime` (s) less the first,
rows with a non-increasing stamp dropped, `SENSgyro` per axis (°/s; the LSM9DS0's is in
rad/s and is given to `gyro-cli run --rate-unit rads`). Their reference is not used: the
robot's pose has to be mapped onto each board's axes, and the path's turns are known
instead. On the bundled recordings the pose measures every turn of path 1, rest to rest,
at 135°, −270° and 135° (x), −150° and 150° (y), 180° and −180° (z) to within 0.02°
(scripts/rasteiro_turns.py), so the truth of a turn here is the one of those magnitudes
nearest the plain estimate, with its sign (a board whose axes are permuted, as the
LSM9DS0's are, still gets its own axis's turns).

Rests are found from the gyro alone: at least 0.6 s over which, in every 0.2 s, the rate
spans less than 2 °/s and its median is within 5 °/s of zero (the robot turns at a steady
rate, which would otherwise pass for a rest). A turn is a change of more than 100° between
two rests (the other axes' turns leak 5–18° into each axis). Both estimators go from the
middle of the rest before to the middle of the rest after: the plain one integrates the
rate on the stamps (trapezoid) less the mean rate of the central rest before (0.25 s
trimmed at each end), `run` (default settings) reads its 50 Hz angle series there.

A rest-to-rest span also holds what the other axes' turns leak into this axis, which the
nominal truth leaves out: where a slow leak (under 1 °/s) sits next to a rest, the two
estimators differ by up to 1° for that reason alone.

Then, calibrated on the bundled recordings and held out on the speeds they do not have:
per sensor that is bundled (MPU6050, MPU6500) and axis, `gyro-cli calibrate --objective
movement-rms` on its three bundled speeds, and `gyro-cli run --model` on V_500, V1000 and
eV50p; beside it the plain estimator with the scale of a least-squares line of its own turn
errors on the same bundled recordings (scripts/rasteiro_calibrated.py's plain line).

Usage: python3 scripts/rasteiro_more.py DATASET_DIR [BUNDLED_DIR] [--gyro target/release/gyro-cli]
(DATASET_DIR: the clone's root, holding DataSets/; BUNDLED_DIR: default
../shared/data/real/rasteiro). Needs numpy, pandas and scipy.
"""
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np
import pandas as pd
import scipy.io as sio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rasteiro_calibrated import calibrate, plain_scale  # noqa: E402
from rasteiro_turns import positional_args, turns  # noqa: E402

SENSORS = ["MPU6050RM3100", "MPU6500RM3100", "MPU9150", "LSM9DS0"]
SPEEDS = ["V_300", "V_500", "V_800", "V1000", "V1500", "eV50p"]
BUNDLED_SPEEDS = ["V_300", "V_800", "V1500"]
IN_RADIANS = {"LSM9DS0"}
MAGNITUDES_DEG = np.array([135.0, 150.0, 180.0, 270.0])
MIN_TURN_DEG = 100.0
REST_MIN_S, REST_WINDOW_S, REST_SPREAD_DPS, REST_LEVEL_DPS, TRIM_S = 0.6, 0.2, 2.0, 5.0, 0.25


def load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = sio.loadmat(path)
    t = m["MATLABtime"][0].astype(float)
    g = m["SENSgyro"].astype(float)
    keep = np.concatenate([[True], np.diff(t) > 0])
    return t[keep] - t[keep][0], g[:, keep]


def rests(t, w):
    still = np.zeros(len(t), dtype=bool)
    j = 0
    for i in range(len(t)):
        while t[j] < t[i] - REST_WINDOW_S:
            j += 1
        seg = w[j : i + 1]
        seg = seg[np.isfinite(seg)]
        still[i] = (
            len(seg) > 2
            and seg.max() - seg.min() < REST_SPREAD_DPS
            and abs(np.median(seg)) < REST_LEVEL_DPS
        )
    out, i = [], 0
    while i < len(t):
        if not still[i]:
            i += 1
            continue
        start, k = np.searchsorted(t, t[i] - REST_WINDOW_S), i
        while k < len(t) and still[k]:
            k += 1
        if t[k - 1] - t[start] >= REST_MIN_S:
            out.append((start, k - 1))
        i = k
    return out


def plain(t, w, rest, t0, t1):
    lo = np.searchsorted(t, t[rest[0]] + TRIM_S)
    hi = max(np.searchsorted(t, t[rest[1]] - TRIM_S), lo + 1)
    bias = np.nanmean(w[lo:hi])
    k0, k1 = np.searchsorted(t, t0), np.searchsorted(t, t1)
    st, sw = t[k0 : k1 + 1], w[k0 : k1 + 1]
    ok = np.isfinite(sw)
    st, sw = st[ok], sw[ok]
    return np.sum(0.5 * (sw[1:] + sw[:-1]) * np.diff(st)) - bias * (st[-1] - st[0])


def run_series(gyro, t, w_logged, radians, model=None):
    with tempfile.TemporaryDirectory() as tmp:
        path, out = os.path.join(tmp, "axis.csv"), os.path.join(tmp, "series.csv")
        pd.DataFrame({"time_s": t, "rate_dps": w_logged}).to_csv(path, index=False, float_format="%.9g")
        args = [gyro, "run", path, "--out", out] + (["--rate-unit", "rads"] if radians else [])
        args += ["--model", model] if model else []
        subprocess.run(args, check=True, capture_output=True)
        s = pd.read_csv(out, comment="#")
    return s["time_s"].to_numpy(), s["angle_deg"].to_numpy()


def main():
    args = positional_args()
    if not args:
        sys.exit(__doc__)
    root = os.path.join(args[0], "DataSets")
    bundled = args[1] if len(args) > 1 else os.path.join(os.path.dirname(__file__), "../../shared/data/real/rasteiro")
    gyro = sys.argv[sys.argv.index("--gyro") + 1] if "--gyro" in sys.argv else "target/release/gyro-cli"
    tmp = tempfile.TemporaryDirectory()
    # Per bundled sensor and axis: the model calibrated on its bundled speeds, and the
    # plain line's scale from the same recordings.
    models = {}
    for sensor in SENSORS:
        for axis in "xyz":
            train = [os.path.join(bundled, f"rasteiro_{sensor}_{speed}_{axis}.csv") for speed in BUNDLED_SPEEDS]
            if not all(os.path.exists(p) for p in train):
                continue
            model = os.path.join(tmp.name, f"{sensor}_{axis}.json")
            calibrate(gyro, train, model)
            k_plain = plain_scale([f for p in train for f in turns(p, gyro)])
            models[(sensor, axis)] = (model, k_plain)
    rows, held = [], []
    for sensor in SENSORS:
        for speed in SPEEDS:
            path = os.path.join(root, speed, "Sequencia1", sensor + ".mat")
            if not os.path.exists(path):
                continue
            t, g = load(path)
            radians = sensor in IN_RADIANS
            for axis in range(3):
                logged = g[axis]
                w = np.degrees(logged) if radians else logged
                st, sa = run_series(gyro, t, logged, radians)
                calibrated = models.get((sensor, "xyz"[axis])) if speed not in BUNDLED_SPEEDS else None
                if calibrated:
                    mt, ma = run_series(gyro, t, logged, radians, calibrated[0])
                found = rests(t, w)
                for before, after in zip(found, found[1:]):
                    t0 = 0.5 * (t[before[0]] + t[before[1]])
                    t1 = 0.5 * (t[after[0]] + t[after[1]])
                    p = plain(t, w, before, t0, t1)
                    if abs(p) < MIN_TURN_DEG:
                        continue
                    truth = np.sign(p) * MAGNITUDES_DEG[np.argmin(np.abs(MAGNITUDES_DEG - abs(p)))]
                    r = np.interp(t1, st, sa) - np.interp(t0, st, sa)
                    rows.append((sensor, speed, "xyz"[axis], truth, p - truth, r - truth))
                    if calibrated:
                        m = np.interp(t1, mt, ma) - np.interp(t0, mt, ma)
                        held.append((sensor, speed, p - truth, p / (1.0 + calibrated[1]) - truth, r - truth, m - truth))
    df = pd.DataFrame(rows, columns=["sensor", "speed", "axis", "truth", "plain", "run"])
    print(f"{'sensor':<14} {'speed':<6} {'turns':>5}  {'plain med':>9} {'p90':>6}  {'run med':>8} {'p90':>6}  run/plain")

    def line(sensor, speed, g):
        pe, re = g["plain"].abs(), g["run"].abs()
        print(
            f"{sensor:<14} {speed:<6} {len(g):>5}  {pe.median():>9.2f} {pe.quantile(0.9):>6.2f}"
            f"  {re.median():>8.2f} {re.quantile(0.9):>6.2f}  {re.median() / pe.median():>9.2f}"
        )

    for sensor in SENSORS:
        for speed in SPEEDS:
            g = df[(df.sensor == sensor) & (df.speed == speed)]
            if len(g):
                line(sensor, speed, g)
    for sensor in SENSORS:
        g = df[df.sensor == sensor]
        if len(g):
            line(sensor, "all", g)
    if not held:
        return
    print()
    print("calibrated on the bundled speeds (V_300, V_800, V1500), held out on the others")
    h = pd.DataFrame(held, columns=["sensor", "speed", "plain", "plain_scaled", "run", "model"])
    cols = ["plain", "plain_scaled", "run", "model"]
    print(f"{'sensor':<14} {'speed':<6} {'turns':>5}  {'plain':>13}  {'plain+scale':>13}  {'run':>13}  {'run --model':>13}  model / plain+scale")

    def held_line(sensor, speed, g):
        a = g[cols].abs()
        cells = "  ".join(f"{a[c].median():5.2f} ({a[c].quantile(0.9):5.2f})" for c in cols)
        print(f"{sensor:<14} {speed:<6} {len(g):>5}  {cells}  {a['model'].median() / a['plain_scaled'].median():>9.2f}")

    for sensor in SENSORS:
        for speed in SPEEDS:
            g = h[(h.sensor == sensor) & (h.speed == speed)]
            if len(g):
                held_line(sensor, speed, g)
        g = h[h.sensor == sensor]
        if len(g):
            held_line(sensor, "all", g)


if __name__ == "__main__":
    main()
