#!/usr/bin/env python3
"""Per-turn angle on the rasteiro recordings with a model calibrated on other recordings.

`scripts/rasteiro_turns.py` shows `gyro-cli run` and the plain per-rest estimator sharing
one error: proportional to the turn, a scale error no rest removes. Here the scale is
calibrated and judged on recordings it was not fitted on, two ways:

- by speed: for each sensor and axis, `gyro-cli calibrate --objective movement-rms` on the
  two other speeds' recordings, then `gyro-cli run --model` on the held-out speed;
- by sensor: calibrated on every speed of one sensor, run on the other sensor's recordings
  of the same axis (the two boards differ: this asks whether a calibration carries over).

Beside it, the plainest honest alternative with the same information: the plain per-rest
estimator with a scale from a least-squares line (through the origin) of its own turn
errors on the truth over the same training recordings, applied to the held-out turns.
Turns and truth are those of `rasteiro_turns.py` (rest to rest against the robot's pose).

Prints the median and 90th percentile of |error| per held-out group, and the ratio of the
calibrated `run` to the scaled plain estimator. Then, held out by speed, what a wrench's
controller would be told: how often the 95% interval of each turn's angle covers the
truth (the movement's `angle_std_deg`; with the model, also the scale uncertainty that
`calibrate` measured held out and wrote as the model's `scale_sigma`, added as the
tightening decision adds it: sqrt(sigma^2 + (u * angle)^2); the model's compensation is
overridden to the Kalman form, the one whose movements carry a sigma), and the tightening
decisions of `gyro-cli run`
(k = 2) against windows of half-width 0.5, 1 and 2 degrees whose target lies from 1.2
half-widths below the truth to 1.2 above: how many `ok` were wrong (truth outside the
window), `nok` wrong (truth inside), and `recheck`.

Usage: python3 scripts/rasteiro_calibrated.py [DATA_DIR] [--gyro target/release/gyro-cli]
"""
import glob
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rasteiro_turns import positional_args, turns  # noqa: E402

SPEEDS = ("V_300", "V_800", "V1500")
SENSORS = ("MPU6050", "MPU6500")


def path_of(data, sensor, speed, axis):
    return os.path.join(data, f"rasteiro_{sensor}RM3100_{speed}_{axis}.csv")


def calibrate(gyro, train, model):
    """Calibrate on `train`; the JSON's scale and delay (the scale with its held-out
    residual)."""
    out = subprocess.run(
        [gyro, "calibrate", "--objective", "movement-rms", "--format", "json", "-o", model, *train],
        check=True,
        capture_output=True,
        text=True,
    )
    j = json.loads(out.stdout)
    return j["scale"], j["reference_delay"]


def plain_scale(found):
    """Least-squares scale of the plain estimator's turn errors on the truth."""
    truth = np.array([f[0] for f in found])
    err = np.array([f[1] for f in found])
    return float(np.sum(err * truth) / np.sum(truth * truth))


def held_out(gyro, train, test, cache):
    """Errors on `test` (list of (truth, plain, plain scaled, run, run calibrated))."""
    with tempfile.TemporaryDirectory() as tmp:
        model = os.path.join(tmp, "model.json")
        scale, delay = calibrate(gyro, train, model)
        k_plain = plain_scale([f for p in train for f in cache[p]])
        rows = []
        for path in test:
            calibrated = turns(path, gyro, ("--model", model))
            for (truth, pe, re), (truth2, _, ce) in zip(cache[path], calibrated):
                assert truth == truth2
                p = truth + pe
                rows.append((truth, pe, p / (1.0 + k_plain) - truth, re, ce))
    return rows, scale, delay, k_plain


def line(label, rows):
    a = np.abs(np.array(rows))
    med = np.median(a, axis=0)
    p90 = np.percentile(a, 90, axis=0)
    cells = "  ".join(f"{m:5.2f} ({q:5.2f})" for m, q in zip(med[1:], p90[1:]))
    print(f"{label:<22} {len(rows):>5}  {cells}  {med[4] / med[2]:6.2f}")


def header(title):
    print(title)
    print(f"{'held out':<22} {'turns':>5}  {'plain':>13}  {'plain+scale':>13}  {'run':>13}  {'run --model':>13}  ratio")


HALF_WIDTHS = (0.5, 1.0, 2.0)
OFFSETS = (-1.2, -0.9, -0.6, -0.3, 0.0, 0.3, 0.6, 0.9, 1.2)


def movements(gyro, path, extra=()):
    out = subprocess.run(
        [gyro, "run", path, "--format", "json", *extra], check=True, capture_output=True, text=True
    )
    return json.loads(out.stdout)["movements"]


def matched(moves, truth):
    """The movement that is this turn: the nearest angle, within 20 degrees."""
    m = min(moves, key=lambda m: abs(m["angle_deg"] - truth), default=None)
    return m if m is not None and abs(m["angle_deg"] - truth) < 20.0 else None


def decisions(gyro, path, truth, extra):
    """(wrong ok, wrong nok, recheck, decided, invalid) over the windows around `truth`."""
    sign = 1.0 if truth > 0 else -1.0
    wrong_ok = wrong_nok = recheck = decided = invalid = 0
    for d in HALF_WIDTHS:
        for o in OFFSETS:
            target = abs(truth) + o * d
            args = [
                "--target-deg", f"{target:.6f}", "--tolerance-deg", f"{d}",
                "--tightening-direction", "positive" if sign > 0 else "negative", *extra,
            ]
            m = matched(movements(gyro, path, args), truth)
            if m is None or m.get("verdict") is None:
                continue
            inside = abs(abs(truth) - target) <= d
            v = m["verdict"]
            decided += 1
            wrong_ok += v == "ok" and not inside
            if v == "ok" and not inside and extra:
                print(
                    f"wrong ok with the model: {os.path.basename(path)} turn {truth:+.2f}, "
                    f"window {target:.2f} ± {d}, measured {m['angle_deg']:+.2f} (σ {m['angle_std_deg']:.3f})",
                    file=sys.stderr,
                )
            wrong_nok += v == "nok" and inside
            recheck += v == "recheck"
            invalid += v == "invalid"
    return wrong_ok, wrong_nok, recheck, decided, invalid


def trust(gyro, data, cache):
    """Coverage and decisions on each speed held out, default and calibrated."""
    rows = {"default": [0] * 7, "calibrated": [0] * 7}
    residuals = []
    for sensor in SENSORS:
        for axis in "xyz":
            for speed in SPEEDS:
                test = path_of(data, sensor, speed, axis)
                train = [path_of(data, sensor, s, axis) for s in SPEEDS if s != speed]
                with tempfile.TemporaryDirectory() as tmp:
                    model = os.path.join(tmp, "model.json")
                    scale, _ = calibrate(gyro, train, model)
                    u = scale.get("residual_relative_upper") or 0.0
                    if scale.get("residual_relative") is not None:
                        residuals.append((scale["residual_relative"], u))
                    configs = {
                        "default": ((), 0.0),
                        "calibrated": (("--model", model, "--compensation", "kalman"), u),
                    }
                    for name, (extra, u) in configs.items():
                        moves = movements(gyro, test, extra)
                        for truth, _, _ in cache[test]:
                            m = matched(moves, truth)
                            if m is None or m["angle_std_deg"] is None:
                                continue
                            sigma = (m["angle_std_deg"] ** 2 + (u * m["angle_deg"]) ** 2) ** 0.5
                            r = rows[name]
                            r[0] += 1
                            r[1] += abs(m["angle_deg"] - truth) <= 1.96 * sigma
                            for i, v in enumerate(decisions(gyro, test, truth, extra)):
                                r[2 + i] += v
    if residuals:
        low, high = min(r for r, _ in residuals), max(r for r, _ in residuals)
        low_u, high_u = min(u for _, u in residuals), max(u for _, u in residuals)
        print(
            f"scale_sigma: left-out relative RMS {100 * low:.2f}-{100 * high:.2f}%, "
            f"95% upper bound {100 * low_u:.2f}-{100 * high_u:.2f}% ({len(residuals)} folds)"
        )
    print(f"{'held out by speed':<20} {'turns':>5} {'95% covers':>10} {'decisions':>9} {'wrong ok':>8} {'wrong nok':>9} {'recheck':>8} {'invalid':>8}")
    for name, r in rows.items():
        print(
            f"{name:<20} {r[0]:>5} {100 * r[1] / max(r[0], 1):>9.0f}% {r[5]:>9} {r[2]:>8} {r[3]:>9}"
            f" {100 * r[4] / max(r[5], 1):>7.1f}% {100 * r[6] / max(r[5], 1):>7.1f}%"
        )


def main():
    args = positional_args()
    data = args[0] if args else os.path.join(os.path.dirname(__file__), "../../shared/data/real/rasteiro")
    gyro = sys.argv[sys.argv.index("--gyro") + 1] if "--gyro" in sys.argv else "target/release/gyro-cli"
    paths = sorted(glob.glob(os.path.join(data, "rasteiro_*.csv")))
    cache = {p: turns(p, gyro) for p in paths}
    by_speed = {}
    print("calibrated on the other two speeds (scale written? k; reference delay; plain k):")
    for sensor in SENSORS:
        for axis in "xyz":
            for speed in SPEEDS:
                test = path_of(data, sensor, speed, axis)
                train = [path_of(data, sensor, s, axis) for s in SPEEDS if s != speed]
                rows, scale, delay, k_plain = held_out(gyro, train, [test], cache)
                by_speed.setdefault((sensor, speed), []).extend(rows)
                print(
                    f"  {sensor} {axis} held out {speed}: scale {'written' if scale['written'] else 'not written'}"
                    f" {100 * (scale['k'] or 0):+.2f}%, delay {1e3 * delay['delay_s']:.0f} ms, plain {100 * k_plain:+.2f}%"
                )
    print()
    header("median |error| (90th percentile), deg; ratio: run --model / plain+scale")
    for sensor in SENSORS:
        for speed in SPEEDS:
            line(f"{sensor} {speed}", by_speed[(sensor, speed)])
        line(f"{sensor} all", [r for (s, _), v in by_speed.items() if s == sensor for r in v])
    print()
    header("calibrated on the other sensor (every speed, same axis)")
    for sensor in SENSORS:
        other = [s for s in SENSORS if s != sensor][0]
        rows = []
        for axis in "xyz":
            train = [path_of(data, other, s, axis) for s in SPEEDS]
            test = [path_of(data, sensor, s, axis) for s in SPEEDS]
            rows.extend(held_out(gyro, train, test, cache)[0])
        line(f"{sensor} from {other}", rows)
    print()
    trust(gyro, data, cache)


if __name__ == "__main__":
    main()
