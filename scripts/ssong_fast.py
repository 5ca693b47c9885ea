#!/usr/bin/env python3
"""`gyro-cli diagnose` trained on the bundled ssong slow and medium trials and held out on
the fast trials, which are not bundled: motion up to 450 °/s, faster than anything the
model was fitted on. Beside it the plain analyst's alternative with the same information.

The fast trials are read from a clone of the public repository
(https://github.com/ssong47/get_joint_angles_using_imus, MIT licence; nothing of it is
copied here), `MatlabCode/Data/raw_{roll,yaw}_fast.mat`, and converted exactly as the
bundled CSVs were made (../shared/data/real/README.md): rows from `data_line`, time less
the first row's, IMU2's raw gyro on the axis (yaw: z, sign flipped; roll: x), the encoder
angle; printed with the bundled files' decimals. The script first converts the slow
trials the same way and checks they equal the bundled files byte for byte. The pitch
trial's fast file is not in the clone (its blob is absent), so pitch is not checked.

Per axis:
- `gyro-cli diagnose --split-s 100 --train slow medium --holdout fast -o model.json`:
  the named effects, and the held-out windows' max |angle error| with the default
  configuration and with the written model (`compensation.runs` of the JSON);
- the plain alternative: per recording, both signals on a 1 ms grid, low-passed alike
  (zero-phase 4th-order 5 Hz Butterworth), the lag, scale and bias of the least-squares
  fit gyro = (1 + k) encoder_rate + b (scripts/ssong_plain.py), averaged over the two
  training recordings; then on each 100 s window of the fast trial the gyro, less b,
  divided by 1 + k, integrated on the stamps (trapezoid, duplicate stamps dropped) and read
  lag later, against the encoder's change since the window's start. "plain, raw" is the
  same integral with nothing corrected. Its ratio to `run --model` is reported.

Usage: python3 scripts/ssong_fast.py CLONE_DIR [BUNDLED_DIR] [--gyro target/release/gyro-cli]
(CLONE_DIR: the clone's root, holding MatlabCode/; BUNDLED_DIR: default ../shared/data/real).
Needs numpy, pandas and scipy.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import pandas as pd
import scipy.io as sio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ssong_plain  # noqa: E402

AXES = [("x", "roll", False), ("z", "yaw", True)]
WINDOW_S = 100.0


def convert(clone, rotation, axis, flip, speed, path):
    """The trial `raw_{rotation}_{speed}.mat` as the bundled CSV format, written to `path`."""
    m = sio.loadmat(os.path.join(clone, "MatlabCode", "Data", f"raw_{rotation}_{speed}.mat"))
    start = int(m["data_line"][0, 0])
    t = m["all_time"][start:, 0]
    t = t - t[0]
    g = m[f"all_gyro_2_{axis}"][start:, 0] * (-1.0 if flip else 1.0)
    e = m["all_encoder"][start:, 0]
    with open(path, "w") as f:
        f.write(
            f"# source: ssong47/get_joint_angles_using_imus MatlabCode/Data/raw_{rotation}_{speed}.mat (MIT licence)\n"
            f"# sensor: MPU6050 (IMU2 on the motor shaft), axis {axis}, sign flipped: {'yes' if flip else 'no'}\n"
            "# sample_rate_hz: 100\ntime_s,rate_dps,reference_deg\n"
        )
        for a, b, c in zip(t, g, e):
            f.write(f"{a:.6f},{b + 0.0:.2f},{c + 0.0:.3f}\n")


def read(path):
    d = pd.read_csv(path, comment="#").drop_duplicates("time_s")
    return d.time_s.values, d.rate_dps.values, d.reference_deg.values


def plain_fit(path):
    """(lag_s, k, bias_dps) of the least-squares fit of scripts/ssong_plain.py."""
    lag_ms, k, bias = ssong_plain.plain_fit(path)
    return lag_ms / 1000.0, k, bias


def window_errors(path, lag_s=0.0, k=0.0, bias_dps=0.0):
    """Max |angle error| (deg) of each whole 100 s window of `path`."""
    t, g, ref = read(path)
    rate = (g - bias_dps) / (1.0 + k)
    angle = np.r_[0.0, np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))]
    out = []
    w = 0
    while (w + 1) * WINDOW_S <= t[-1] - t[0]:
        sel = (t >= t[0] + w * WINDOW_S) & (t < t[0] + (w + 1) * WINDOW_S)
        ts = t[sel]
        gyro = np.interp(ts + lag_s, t, angle)
        gyro -= gyro[0]
        out.append(np.max(np.abs(gyro - (ref[sel] - ref[sel][0]))))
        w += 1
    return np.array(out)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--gyro")]
    gyro = "target/release/gyro-cli"
    if "--gyro" in sys.argv:
        gyro = sys.argv[sys.argv.index("--gyro") + 1]
        args = [a for a in args if a != gyro]
    if not args:
        sys.exit(__doc__)
    clone = args[0]
    bundled = args[1] if len(args) > 1 else "../shared/data/real"
    tmp = tempfile.mkdtemp(prefix="ssong_fast_")
    rows = []
    for axis, rotation, flip in AXES:
        check = os.path.join(tmp, f"check_{axis}_slow.csv")
        convert(clone, rotation, axis, flip, "slow", check)
        with open(check, "rb") as a, open(os.path.join(bundled, f"ssong_{axis}_slow.csv"), "rb") as b:
            if a.read() != b.read():
                sys.exit(f"{check}: the conversion does not reproduce the bundled ssong_{axis}_slow.csv")
        fast = os.path.join(tmp, f"ssong_{axis}_fast.csv")
        convert(clone, rotation, axis, flip, "fast", fast)
        train = [os.path.join(bundled, f"ssong_{axis}_{s}.csv") for s in ("slow", "medium")]
        model = os.path.join(tmp, f"{axis}.model.json")
        out = subprocess.run(
            [gyro, "diagnose", "--split-s", str(int(WINDOW_S)), "--train", *train, "--holdout", fast,
             "--format", "json", "-o", model],
            check=True, capture_output=True, text=True,
        ).stdout
        d = json.loads(out)
        runs = d["compensation"]["runs"]
        before = np.array([r["max_abs_error_before_deg"] for r in runs])
        after = np.array([r["max_abs_error_after_deg"] for r in runs])
        fits = [plain_fit(p) for p in train]
        lag_s, k, bias = (float(np.mean([f[i] for f in fits])) for i in range(3))
        own_lag, own_k, own_bias = plain_fit(fast)
        raw = window_errors(fast)
        plain = window_errors(fast, lag_s, k, bias)
        plain_no_bias = window_errors(fast, lag_s, k, 0.0)
        named = ", ".join(d["verdict"]["unmodelled"]) or "nothing"
        rows.append((axis, rotation, named, d["compensation"]["corrected"], before, after, raw, plain,
                     plain_no_bias, (lag_s, k, bias), (own_lag, own_k, own_bias)))

    print("held-out max |angle error| per 100 s window of the fast trial, median (worst), deg\n")
    print("| axis | windows | named | written | `run` | `run --model` | better | plain, raw | plain + training lag, scale, bias | plain + training lag, scale | `run --model` / best plain |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for axis, rotation, named, corrected, before, after, raw, plain, plain_nb, _, _ in rows:
        f = lambda a: f"{np.median(a):.2f} ({np.max(a):.2f})"  # noqa: E731
        best = min(np.median(plain), np.median(plain_nb))
        print(f"| {rotation} ({axis}) | {len(after)} | {named} | {', '.join(corrected) or 'nothing'} | {f(before)} | {f(after)} | "
              f"{int(np.sum(after < before))}/{len(after)} | {f(raw)} | {f(plain)} | {f(plain_nb)} | {np.median(after) / best:.2f} |")
    print("\nthe plain fit (lag ms, scale %, bias deg/s): training mean -> the fast trial's own")
    for axis, rotation, *_, tr, own in rows:
        print(f"  {rotation} ({axis}): {1000 * tr[0]:.0f} ms, {100 * tr[1]:+.2f}%, {tr[2]:+.3f} -> "
              f"{1000 * own[0]:.0f} ms, {100 * own[1]:+.2f}%, {own[2]:+.3f}")


if __name__ == "__main__":
    main()
